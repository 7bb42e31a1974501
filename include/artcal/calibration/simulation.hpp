#pragma once
// Simulating one calibration run (docs/method.md section 6): the readings a machine with the true
// parameters p_true would report for a plan's planned readings.
//
// For placement j the artifact sits where the plan puts it: r_j fitted (Umeyama) to the planned
// readings at the nominal parameters. One draw of each physical artifact's systematic errors
// c ~ N(0, Sigma_c) moves its features (the same draw in every placement of that artifact). For
// each planned reading of feature i:
//   x*    = r_j^-1 W*_i(c)                       the feature's true machine-frame position
//   x_hit = x* + delta_probe,  delta_probe ~ N(0, s_p^2 I_d)   (every coordinate drawn)
//   q     = IK(p_true, x_hit) from the planned reading (solveInverseKinematics)
//   q_read = q + delta_q,      delta_q ~ N(0, diag(s_q^2))
// Noise may be scaled by SimulationOptions::noise_scale (confirmation's negative control).
//
// Random numbers: std::mt19937_64 (fully specified by the standard) through NormalSource's own
// Box-Muller transform, since std::normal_distribution is implementation-defined. Draw order:
// c (artifacts in plan order, errors in artifact order), then per placement, per reading, the d
// probe deviates then the joint deviates. The same seed gives the same readings on any platform.

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <vector>

#include "artcal/artifact/rigid_transform.hpp"
#include "artcal/model/inverse_kinematics.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// Standard normal deviates from std::mt19937_64 by the Box-Muller transform (portable).
class NormalSource {
 public:
  explicit NormalSource(std::uint64_t seed) : engine_(seed) {}
  double operator()();
  /// Uniform in (0, 1], 53 random bits.
  double uniform();

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

/// The seed of trial `trial` of a run seeded with `seed` (SplitMix64 of both): independent
/// streams, the same whatever the thread that runs the trial.
std::uint64_t trialSeed(std::uint64_t seed, std::uint64_t trial);

struct SimulationOptions {
  double noise_scale = 1.0;     ///< multiplies s_p, s_q (and the artifacts' s_c)
  bool artifact_errors = true;  ///< draw c ~ N(0, Sigma_c); false: c = 0
  IkOptions ik;
  bool isValid(std::string* error) const;
};

/// What one simulated run drew besides the readings.
struct SimulatedRun {
  std::vector<Placement> placements;  ///< the plan's placements with simulated readings
  Eigen::VectorXd systematic;         ///< the drawn c, GlobalLayout order, mm
};

/// Prepared simulation of one plan: the nominal r_j are fitted once. Thread-safe (const).
class Simulator {
 public:
  explicit Simulator(const Plan& plan, const SimulationOptions& options = {});

  /// The readings of a machine with full parameter vector `p_true`. RunError (pointing at the
  /// reading in the plan, naming the joint whose limit is in the way) when inverse kinematics
  /// finds no joint values within the limits for a point.
  SimulatedRun simulate(const Eigen::VectorXd& p_true, NormalSource& normal) const;

  const std::vector<RigidTransform>& nominalPoses() const { return poses_; }

 private:
  const Plan* plan_;
  SimulationOptions options_;
  std::vector<RigidTransform> poses_;  ///< machine -> artifact, fitted at nominal
  std::vector<RigidTransform> inverse_poses_;
};

}  // namespace artcal
