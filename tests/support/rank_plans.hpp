#pragma once
// The plans of the rank policy (method.md section 5, "Rank policy"), built in code: placements
// whose measurements leave rigid directions unseen, beside well-spread ball bars, and a dense
// oracle of their information written independently of src/estimation: the full Jacobian A with
// every rigid column of every placement (translations and rotations about the placement's
// centroid, in the machine frame), the whole nuisance block eliminated by a pseudo-inverse whose
// tolerance is relative to its largest eigenvalue.

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "artcal/internal.hpp"
#include "plan_builders.hpp"

namespace artcal::testing {

inline constexpr double kDeg = std::numbers::pi / 180.0;

/// The machine->artifact transform of a pose (2-D: center, angle; 3-D: center, direction, roll).
inline RigidTransform poseTransform(const Pose& pose) {
  if (pose.center.size() == 2) return placePlanar(pose.center.head<2>(), pose.angle);
  return placeSpatial(pose.center.head<3>(), pose.direction, pose.roll);
}

/// A placement of artifact `artifact` of `plan` at `pose`, each listed feature read in `postures`
/// postures (inverse kinematics at nominal).
inline Placement placeFeatures(const Plan& plan, int artifact, const Pose& pose,
                               const std::vector<int>& features, int postures,
                               std::mt19937_64& rng) {
  const Machine& machine = plan.machine;
  const Artifact& a = plan.artifacts[static_cast<std::size_t>(artifact)];
  const RigidTransform to_machine = poseTransform(pose).inverse();
  Placement placement;
  placement.artifact = artifact;
  placement.pose = pose;
  for (int feature : features) {
    const Eigen::VectorXd target = to_machine.apply(a.features.col(feature));
    const auto qs = posturesFor(machine, machine.nominal, target, postures, rng);
    if (static_cast<int>(qs.size()) < postures) {
      throw std::runtime_error("test plan: feature " + std::to_string(feature) + " unreachable");
    }
    for (int k = 0; k < postures; ++k) {
      placement.measurements.push_back({feature, qs[static_cast<std::size_t>(k)]});
    }
  }
  return placement;
}

/// The seed's planar arm with 4 random bars and a 2-D step gauge (faces 0..120 mm on its axis).
inline Plan stepGauge2DPlan() {
  nlohmann::json doc = {
      {"format", "artcal-plan/1"},
      {"name", "rank-step2d"},
      {"machine",
       {{"model", "planar2r"},
        {"parameters", {{"l1", 150.0}, {"l2", 100.0}, {"dt2", 0.0}}},
        {"joint_limits", {{-180, 180}, {-170, 170}}}}},
      {"noise", {{"probe", 0.005}, {"encoder", 0.001}}},
      {"artifacts",
       {{"bar80", {{"type", "ball_bar"}, {"length", 80.0}}},
        {"gauge", {{"type", "step_gauge"}, {"positions", {0.0, 40.0, 80.0, 120.0}}}}}},
      {"workspace", {{"samples", 64}, {"seed", 3}}}};
  Plan plan = parsePlan(doc, "rank-step2d", false);
  plan.placements = randomPlanarBars(plan, 4, 11);
  std::mt19937_64 rng(5);
  Pose pose;
  pose.center = Eigen::Vector2d(60.0, 90.0);
  pose.angle = 20.0 * kDeg;
  plan.placements.push_back(placeFeatures(plan, 1, pose, {0, 1, 2, 3}, 1, rng));
  return plan;
}

/// The 6-axis arm (21 parameters) with 3 bars (each ball in 3 postures) and `extra`.
inline Plan spatialPlanWith(const std::string& name, const nlohmann::json& artifact,
                            const std::vector<int>& features, int postures) {
  Plan plan = aacmmPlan();
  plan.name = name;
  plan.placements = randomSpatialBars(plan, 3, 3, 21);
  if (artifact.is_null()) return plan;
  // The artifact parsed in 3-D, through a plan of a one-joint arm.
  const nlohmann::json doc = {{"format", "artcal-plan/1"},
                              {"machine",
                               {{"model", "serial-dh"},
                                {"joints", {{{"theta", 0}, {"d", 0}, {"a", 0}, {"alpha", 0}}}},
                                {"probe", {1, 0, 0}}}},
                              {"noise", {{"probe", 0.01}, {"encoder", 0.001}}},
                              {"artifacts", {{"extra", artifact}}}};
  plan.artifacts.push_back(parsePlan(doc, name, false).artifacts.front());
  const int index = static_cast<int>(plan.artifacts.size()) - 1;
  std::mt19937_64 rng(17);
  Pose pose;
  pose.center = Eigen::Vector3d(520.0, -180.0, 380.0);
  pose.direction = Eigen::Vector3d(0.3, 0.8, -0.25).normalized();
  pose.roll = 25.0 * kDeg;
  plan.placements.push_back(placeFeatures(plan, index, pose, features, postures, rng));
  return plan;
}

inline Plan stepGauge3DPlan() {
  return spatialPlanWith("rank-step3d",
                         {{"type", "step_gauge"}, {"positions", {0.0, 100.0, 200.0, 300.0}}},
                         {0, 1, 2, 3}, 2);
}
inline Plan oneBallPlan() {
  return spatialPlanWith("rank-oneball", {{"type", "ball_bar"}, {"length", 300.0}}, {1}, 3);
}
inline const nlohmann::json& plateDefinition() {
  static const nlohmann::json plate = {
      {"type", "ball_plate"},
      {"centers", {{0, 0, 0}, {100, 0, 0}, {200, 0, 0}, {0, 150, 0}, {200, 150, 0}}}};
  return plate;
}
inline Plan plateOriginPlan() {
  return spatialPlanWith("rank-plate-origin", plateDefinition(), {0}, 3);
}
inline Plan plateXAxisPlan() {
  return spatialPlanWith("rank-plate-xaxis", plateDefinition(), {0, 1, 2}, 2);
}

/// A 3-axis arm (RRR: base column, shoulder, elbow) calibrating 8 parameters plus j1.theta
/// (absorbed by the placements' rigid motions: deficiency 1), 6 bars whose balls are each read in
/// 2 postures. probe.z is left out: the shoulder and elbow axes are parallel, so it trades with
/// j2.d.
inline Plan arm3ThetaPlan() {
  const nlohmann::json doc = nlohmann::json::parse(R"({
    "format": "artcal-plan/1", "name": "rank-arm3-theta",
    "machine": {"model": "serial-dh",
      "joints": [{"theta": 0, "d": 300, "a": 0, "alpha": 90},
                 {"theta": 0, "d": 0, "a": 400, "alpha": 0},
                 {"theta": 0, "d": 0, "a": 350, "alpha": 0}],
      "probe": [0, 0, 0],
      "calibrate": ["j1.theta", "j1.a", "j1.alpha", "j2.theta", "j2.d", "j2.a", "j2.alpha",
                    "probe.x", "probe.y"],
      "joint_limits": [[-180, 180], [-180, 180], [-170, 170]]},
    "noise": {"probe": 0.005, "encoder": 0.001},
    "artifacts": {"bar": {"type": "ball_bar", "length": 250}},
    "workspace": {"samples": 64, "seed": 2}})");
  Plan plan = parsePlan(doc, "rank-arm3-theta", false);
  std::mt19937_64 rng(9);
  for (int j = 0; j < 6; ++j) {
    const double bearing = uniform(rng, -std::numbers::pi, std::numbers::pi);
    const Eigen::Vector3d center(450.0 * std::cos(bearing), 450.0 * std::sin(bearing),
                                 uniform(rng, 150.0, 450.0));
    Pose pose;
    pose.center = center;
    pose.direction =
        Eigen::Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)).normalized();
    plan.placements.push_back(placeFeatures(plan, 0, pose, {0, 1}, 2, rng));
  }
  return plan;
}

// ---------------------------------------------------------------------------------------------
// The dense oracle

struct DenseInformation {
  Eigen::MatrixXd N_red;      ///< information of the calibrated parameters, internal units
  Eigen::VectorXd unreduced;  ///< diag(A_p^T W A_p)
  int rank = 0;               ///< of D^-1/2 N_red D^-1/2, tolerance 1e-10 of its largest
  Eigen::VectorXd u;          ///< sqrt(diag N_red^-1) when full rank
  int nuisance_rank = 0;      ///< rank of the whole nuisance block
};

/// Every placement carries the pose it was built with (its valued rows: the first k of R).
inline DenseInformation denseOracle(const Plan& plan) {
  const Machine& machine = plan.machine;
  const Mechanism& mech = *machine.mechanism;
  const int d = machine.dimension();
  const int n_p = machine.calibratedCount();
  const int rigid = d == 2 ? 3 : 6;
  const int m = static_cast<int>(plan.placements.size());
  int rows = 0;
  for (const Placement& pl : plan.placements) {
    rows += plan.artifacts[static_cast<std::size_t>(pl.artifact)].valuedPerFeature() *
            static_cast<int>(pl.measurements.size());
  }
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(rows, n_p + rigid * m);
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(rows, rows);
  Eigen::VectorXd encoder(machine.jointCount());
  for (int i = 0; i < encoder.size(); ++i) {
    encoder[i] = plan.noise.encoder.size() == 1 ? plan.noise.encoder[0] : plan.noise.encoder[i];
  }
  int row = 0;
  for (int j = 0; j < m; ++j) {
    const Placement& pl = plan.placements[static_cast<std::size_t>(j)];
    const int k = plan.artifacts[static_cast<std::size_t>(pl.artifact)].valuedPerFeature();
    const Eigen::MatrixXd Rk = poseTransform(*pl.pose).R.topRows(k);
    std::vector<Eigen::VectorXd> x(pl.measurements.size());
    std::vector<Eigen::MatrixXd> Jp(pl.measurements.size()), Jq(pl.measurements.size());
    Eigen::VectorXd centroid = Eigen::VectorXd::Zero(d);
    for (std::size_t i = 0; i < pl.measurements.size(); ++i) {
      x[i].resize(d);
      forwardOrThrow(mech, machine.nominal, pl.measurements[i].joints, x[i], &Jp[i], &Jq[i]);
      centroid += x[i] / static_cast<double>(pl.measurements.size());
    }
    for (std::size_t i = 0; i < pl.measurements.size(); ++i) {
      for (int c = 0; c < n_p; ++c) {
        A.block(row, c, k, 1) = Rk * Jp[i].col(machine.calibrated[static_cast<std::size_t>(c)]);
      }
      // Rigid motion of the artifact in the machine frame: x -> x + t + w x (x - centroid).
      Eigen::MatrixXd G(d, rigid);
      const Eigen::VectorXd lever = x[i] - centroid;
      if (d == 2) {
        G << 1, 0, -lever[1], 0, 1, lever[0];
      } else {
        G.leftCols(3).setIdentity();
        const Eigen::Vector3d l = lever.head<3>();
        for (int a = 0; a < 3; ++a) G.col(3 + a) = Eigen::Vector3d::Unit(a).cross(l);
      }
      A.block(row, n_p + rigid * j, k, rigid) = Rk * G;
      const Eigen::MatrixXd Jqk = Rk * Jq[i];
      const Eigen::MatrixXd sigma =
          plan.noise.probe * plan.noise.probe * Eigen::MatrixXd::Identity(k, k) +
          Jqk * encoder.cwiseAbs2().asDiagonal() * Jqk.transpose();
      W.block(row, row, k, k) = sigma.inverse();
      row += k;
    }
  }
  const Eigen::MatrixXd N = A.transpose() * W * A;
  const int n_r = rigid * m;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(N.bottomRightCorner(n_r, n_r));
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(n_r);
  DenseInformation out;
  for (int i = 0; i < n_r; ++i) {
    if (lambda[i] > 1e-10 * lambda[n_r - 1]) {
      inverse[i] = 1.0 / lambda[i];
      ++out.nuisance_rank;
    }
  }
  const Eigen::MatrixXd pinv =
      eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
  const Eigen::MatrixXd N_pr = N.topRightCorner(n_p, n_r);
  out.N_red = N.topLeftCorner(n_p, n_p) - N_pr * pinv * N_pr.transpose();
  out.unreduced = N.topLeftCorner(n_p, n_p).diagonal();
  const Eigen::VectorXd s = out.unreduced.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd S = s.asDiagonal() * out.N_red * s.asDiagonal();
  const Eigen::VectorXd mu = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(S).eigenvalues();
  for (int i = 0; i < n_p; ++i) out.rank += mu[i] > 1e-10 * mu[n_p - 1] ? 1 : 0;
  if (out.rank == n_p) {
    const Eigen::MatrixXd V = s.asDiagonal() * S.inverse() * s.asDiagonal();
    out.u = V.diagonal().cwiseSqrt();
  }
  return out;
}

}  // namespace artcal::testing
