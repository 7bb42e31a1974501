#pragma once
// The ISO 9283 pose accuracy test of an arm or robot predicted from the calibration (docs/method.md
// section 9, "Acceptance tests predicted"):
//
// - the cube: edge e, centre c, axes R (columns; the spec's cube: R = I, along the base frame),
//   h = e/2; the measuring plane through Q1 = c + R (-h,-h,-h), Q2 = c + R (h,h,-h),
//   Q3 = c + R (h,h,h), Q4 = c + R (-h,-h,h); the points P1 = c, P2 = Q1 + 0.1 (Q3 - Q1),
//   P3 = Q2 + 0.1 (Q4 - Q2), P4 = Q3 + 0.1 (Q1 - Q3), P5 = Q4 + 0.1 (Q2 - Q4);
// - each point's joints by inverse kinematics (model/inverse_kinematics.hpp) from the workspace
//   configuration whose probe is nearest it; with a seed posture (the arm's configuration as the
//   user sets it up): P1 from the seed, each following point from the previous solution, every
//   angle the equivalent nearest the seed within the limits;
// - AP_P = |J_p(q_P) dp + u_P + mean of `cycles` J_q(q_P) eq|: dp ~ N(0, V_p) ONE draw shared by
//   the five points, u_P ~ N(0, s_u^2 I) the error the model does not explain at P (the same in
//   every cycle, independent between points), the encoder noise averaged over the cycles
//   (covariance J_q Sigma_q J_q^T / cycles); E[AP_P] exactly (expectedGaussianNorm), its mean,
//   50 % and 95 % quantiles, those of max_P AP_P and, with an MPE, P(every AP_P <= MPE), by
//   Monte-Carlo (acceptance/monte_carlo.hpp);
// - RP_P = mean l + 3 S_l, l = |x_c - mean x| over the cycles: only the per-cycle noise
//   (covariance C = J_q Sigma_q J_q^T) enters; predicted as its value for many cycles,
//   E|y| + 3 sqrt(trace C - E|y|^2), y ~ N(0, C).

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "artcal/acceptance/acceptance.hpp"
#include "artcal/acceptance/monte_carlo.hpp"

namespace artcal {

struct PoseTestOptions {
  double cube = 0.0;  ///< edge, mm
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  /// The cube's orientation, roll, pitch, yaw (rad; R = Rz(yaw) Ry(pitch) Rx(roll), the columns
  /// of R its axes in the base frame); zero: the spec's cube, axes along the base frame.
  Eigen::Vector3d orientation = Eigen::Vector3d::Zero();
  /// The arm's configuration for the test (internal units), within the joint limits.
  std::optional<Eigen::VectorXd> seed_posture;
  /// The error the model does not explain: standard deviation per coordinate, mm (0: unknown).
  double unmodelled = 0.0;
  std::optional<double> mpe;  ///< mm
  int cycles = 30;
  MonteCarloOptions monte_carlo;
};

struct PosePoint {
  Eigen::Vector3d commanded = Eigen::Vector3d::Zero();              ///< mm
  Eigen::VectorXd joints;                                           ///< internal units
  Eigen::MatrixXd J_p;                                              ///< 3 x calibrated parameters
  Eigen::Matrix3d systematic_covariance = Eigen::Matrix3d::Zero();  ///< mm^2
  Eigen::Matrix3d noise_covariance = Eigen::Matrix3d::Zero();       ///< of the mean, mm^2
  Eigen::Matrix3d cycle_covariance = Eigen::Matrix3d::Zero();       ///< of one cycle, mm^2
  double sigma_sys = 0.0;                                           ///< sqrt(trace), mm
  double sigma_noise = 0.0;                                         ///< sqrt(trace), mm
  double sigma_unmodelled = 0.0;  ///< sqrt(trace of s_u^2 I) = sqrt(3) s_u, mm
  double ap_expected = 0.0;       ///< E[AP_P], mm (expectedGaussianNorm)
  double rp = 0.0;                ///< RP_P predicted, mm (predictedRepeatability)
  Quantiles ap;                   ///< AP_P, mm
};

struct PoseTestPrediction {
  std::vector<PosePoint> points;
  std::optional<double> mpe;
  Quantiles max_ap;               ///< max_P AP_P, mm
  MonteCarloSummary monte_carlo;  ///< its statistic is max AP_P / MPE (mm when no MPE)
};

/// The five points of the cube (P1 .. P5); `axes` its axes in the base frame (columns).
std::vector<Eigen::Vector3d> poseTestPoints(
    double cube, const Eigen::Vector3d& center,
    const Eigen::Matrix3d& axes = Eigen::Matrix3d::Identity());

/// ISO 9283's RP = mean l + 3 S_l (l = |x_c - mean x|) of positions x_c ~ N(x, C) in the limit
/// of many cycles: m + 3 sqrt(trace C - m^2), m = E|y|, y ~ N(0, C) (E|y|^2 = trace C). With n
/// cycles, x_c - mean x has covariance C (n - 1)/n: the mean l is sqrt((n - 1)/n) m.
double predictedRepeatability(const Eigen::Matrix3d& cycle_covariance);

/// The points, their joints and their linear statistics (no Monte-Carlo). InputError when the
/// mechanism's probe is not 3-D, or an option is out of range (the seed posture's size or limits,
/// a negative unmodelled error); RunError naming the point when inverse kinematics finds no
/// joints within the limits.
PoseTestPrediction predictPoseTestLinear(const AcceptanceInput& input,
                                         const PoseTestOptions& options);

/// The Monte-Carlo model: result P is AP_P (3 rows), scaled by 1 / MPE when there is one.
LinearGaussianTest poseTestModel(const PoseTestPrediction& prediction,
                                 const AcceptanceInput& input);

/// predictPoseTestLinear, then the Monte-Carlo.
PoseTestPrediction predictPoseTest(const AcceptanceInput& input, const PoseTestOptions& options);

}  // namespace artcal
