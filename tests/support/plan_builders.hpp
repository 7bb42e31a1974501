#pragma once
// Plans built in code for tests and benchmarks: the seed's planar 2R arm with random reachable
// ball-bar placements, and the 6-axis arm of tests/data/ref-aacmm-3bars-3postures.json with ball
// bars whose balls are each read in several postures (readings by inverse kinematics at nominal).

#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <string>

#include "artcal/internal.hpp"
#include "artcal/model/rotation_vector.hpp"
#include "test_paths.hpp"

namespace artcal::testing {

inline Plan loadTestPlan(const std::string& name) {
  return loadPlan(test_support::testDataFile(name + ".json"));
}

inline double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

/// The seed's arm (l1 = 150, l2 = 100, dt2 = 0), an 80 mm bar (u_length given), s_p = 0.005 mm,
/// s_q = 0.001 deg, limits [-180, 180] and [-170, 170], no placements yet.
inline Plan seedPlanar2RPlan(double u_length = 0.0) {
  const nlohmann::json doc = {
      {"format", "artcal-plan/1"},
      {"name", "seed-2r"},
      {"machine",
       {{"model", "planar2r"},
        {"parameters", {{"l1", 150.0}, {"l2", 100.0}, {"dt2", 0.0}}},
        {"joint_limits", {{-180, 180}, {-170, 170}}}}},
      {"noise", {{"probe", 0.005}, {"encoder", 0.001}}},
      {"artifacts", {{"bar80", {{"type", "ball_bar"}, {"length", 80.0}, {"u_length", u_length}}}}},
      {"workspace", {{"samples", 120}, {"seed", 7}}}};
  return parsePlan(doc, "seed-2r", false);
}

/// A placement of a planar ball bar (artifact `artifact` of the plan) at a random reachable pose:
/// both balls between reach 60 and 240 mm, a random elbow branch for each reading.
inline Placement randomPlanarBar(const Plan& plan, std::mt19937_64& rng, int artifact = 0) {
  const Machine& machine = plan.machine;
  const double length = plan.artifacts[static_cast<std::size_t>(artifact)].features(0, 1);
  for (;;) {
    const double radius = uniform(rng, 60.0, 240.0);
    const double bearing = uniform(rng, -std::numbers::pi, std::numbers::pi);
    const double angle = uniform(rng, -std::numbers::pi, std::numbers::pi);
    const Eigen::Vector2d center(radius * std::cos(bearing), radius * std::sin(bearing));
    const Eigen::Vector2d other =
        center + length * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    if (other.norm() < 60.0 || other.norm() > 240.0) continue;
    Placement placement;
    placement.artifact = artifact;
    placement.pose = Pose{center, angle};
    bool reachable = true;
    for (int feature = 0; feature < 2 && reachable; ++feature) {
      const auto branches = planar2rInverse(machine.nominal, feature == 0 ? center : other);
      const Eigen::VectorXd q =
          branches[std::uniform_int_distribution<std::size_t>(0, branches.size() - 1)(rng)];
      reachable = machine.withinLimits(q);
      placement.measurements.push_back({feature, q});
    }
    if (reachable) return placement;
  }
}

inline std::vector<Placement> randomPlanarBars(const Plan& plan, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Placement> placements;
  for (int j = 0; j < count; ++j) placements.push_back(randomPlanarBar(plan, rng));
  return placements;
}

/// The 6-axis arm of the reference case (21 calibrated parameters, 300 mm bar, s_p = 0.01 mm,
/// s_q = 0.0005 deg), placements removed, joint limits [-180, 180].
inline Plan aacmmPlan() {
  Plan plan = loadTestPlan("ref-aacmm-3bars-3postures");
  plan.placements.clear();
  return plan;
}

/// A 3-D ball bar at a random pose 450 to 900 mm from the shoulder, each ball read in `postures`
/// different postures (diversePostures). Artifact 0 of the plan.
inline Placement randomSpatialBar(const Plan& plan, int postures, std::mt19937_64& rng) {
  const Machine& machine = plan.machine;
  const Artifact& bar = plan.artifacts[0];
  const Eigen::Vector3d shoulder(0.0, 0.0, machine.nominal[1]);
  for (;;) {
    Eigen::Vector3d direction(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    Eigen::Vector3d offset(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    if (direction.norm() < 0.1 || offset.norm() < 0.1) continue;
    const Eigen::Vector3d center = shoulder + offset.normalized() * uniform(rng, 450.0, 900.0);
    const RigidTransform toMachine = placeSpatial(center, direction, 0.0).inverse();
    Placement placement;
    placement.artifact = 0;
    placement.pose.emplace();
    placement.pose->center = center;
    placement.pose->direction = direction.normalized();
    bool reachable = true;
    for (int feature = 0; feature < bar.featureCount() && reachable; ++feature) {
      const Eigen::VectorXd target = toMachine.apply(bar.features.col(feature));
      const auto qs = diversePostures(machine, machine.nominal, target, postures, rng);
      reachable = static_cast<int>(qs.size()) == postures;
      for (const Eigen::VectorXd& q : qs) placement.measurements.push_back({feature, q});
    }
    if (reachable) return placement;
  }
}

inline std::vector<Placement> randomSpatialBars(const Plan& plan, int count, int postures,
                                                std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Placement> placements;
  for (int j = 0; j < count; ++j) placements.push_back(randomSpatialBar(plan, postures, rng));
  return placements;
}

/// A simulated truth: p_true = nominal + 3 u (alternating signs) of the calibrated parameters,
/// u the plan's predicted uncertainty: well outside the noise.
inline Eigen::VectorXd shiftedTruth(const Plan& plan, const Eigen::VectorXd& u) {
  Eigen::VectorXd shift(u.size());
  for (int k = 0; k < u.size(); ++k) shift[k] = (k % 2 == 0 ? 3.0 : -3.0) * u[k];
  const Machine& machine = plan.machine;
  return machine.withCalibrated(machine.nominal, machine.calibratedValues(machine.nominal) + shift);
}

/// The tracker plan of tests/data/ref-instrument-arm6-2stations.json made a pose instrument
/// (`"measures": "pose"`, `noise_angle` 0.005 deg): each reading's `point` extended by the nominal
/// tip frame's orientation seen from its station (the rigid fit of the nominal tips onto the
/// plan's points), a rotation vector in deg, so that the readings are the nominal machine's.
inline nlohmann::json poseTrackerDocument() {
  std::ifstream in(test_support::testDataFile("ref-instrument-arm6-2stations.json"));
  nlohmann::json document = nlohmann::json::parse(in);
  const Plan points = parsePlan(document, "tracker.json");
  document["artifacts"]["tracker"]["measures"] = "pose";
  document["artifacts"]["tracker"]["noise_angle"] = 0.005;
  const Mechanism& mechanism = *points.machine.mechanism;
  for (std::size_t j = 0; j < points.placements.size(); ++j) {
    const std::vector<Measurement>& readings = points.placements[j].measurements;
    Eigen::MatrixXd tips(3, static_cast<int>(readings.size())), measured = tips;
    std::vector<Eigen::Matrix3d> turns;
    for (std::size_t i = 0; i < readings.size(); ++i) {
      Eigen::VectorXd x;
      Eigen::Matrix3d R;
      forwardPoseOrThrow(mechanism, points.machine.nominal, readings[i].joints, x, R);
      tips.col(static_cast<int>(i)) = x;
      measured.col(static_cast<int>(i)) = readings[i].point;
      turns.push_back(R);
    }
    const RigidTransform station = fitRigid(tips, measured);
    for (std::size_t i = 0; i < readings.size(); ++i) {
      const Eigen::Vector3d w = rotationVector(Eigen::Matrix3d(station.R * turns[i]));
      for (int k = 0; k < 3; ++k)
        document["placements"][j]["measurements"][i]["point"].push_back(radToDeg(w[k]));
    }
  }
  return document;
}

/// The plan `document` with its readings simulated by the machine `truth` (full parameter vector,
/// noise seed `seed`), parsed again as a plan of measured readings would be.
inline Plan simulatedDocumentPlan(nlohmann::json document, const Eigen::VectorXd& truth,
                                  std::uint64_t seed) {
  const Plan planned = parsePlan(document, "planned.json");
  NormalSource normal(seed);
  Plan simulated = planned;
  simulated.placements = Simulator(planned, {}).simulate(truth, normal).placements;
  document["placements"] = placementsToJson(simulated);
  return parsePlan(document, "simulated.json");
}

}  // namespace artcal::testing
