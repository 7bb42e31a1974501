#include "artcal/acceptance/pose_acceptance.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "artcal/core/error.hpp"
#include "artcal/model/inverse_kinematics.hpp"

namespace artcal {

std::vector<Eigen::Vector3d> poseTestPoints(double cube, const Eigen::Vector3d& center) {
  const double h = 0.5 * cube;
  const Eigen::Vector3d Q1 = center + Eigen::Vector3d(-h, -h, -h);
  const Eigen::Vector3d Q2 = center + Eigen::Vector3d(h, h, -h);
  const Eigen::Vector3d Q3 = center + Eigen::Vector3d(h, h, h);
  const Eigen::Vector3d Q4 = center + Eigen::Vector3d(-h, -h, h);
  return {center, Q1 + 0.1 * (Q3 - Q1), Q2 + 0.1 * (Q4 - Q2), Q3 + 0.1 * (Q1 - Q3),
          Q4 + 0.1 * (Q2 - Q4)};
}

namespace {

/// The workspace configuration whose probe is nearest `target` (the joint-range middle when the
/// workspace is empty).
Eigen::VectorXd nearestStart(const AcceptanceInput& input, const Eigen::Vector3d& target) {
  const Machine& machine = *input.machine;
  Eigen::VectorXd best(machine.jointCount());
  for (int j = 0; j < machine.jointCount(); ++j)
    best[j] = 0.5 * (machine.joint_limits[j][0] + machine.joint_limits[j][1]);
  double best_distance = std::numeric_limits<double>::infinity();
  Eigen::VectorXd x;
  for (const Eigen::VectorXd& q : input.workspace) {
    if (machine.mechanism->forward(input.parameters, q, x) != ForwardStatus::Ok) continue;
    const double distance = (x.head<3>() - target).norm();
    if (distance < best_distance) {
      best_distance = distance;
      best = q;
    }
  }
  return best;
}

std::string pointText(int index, const Eigen::Vector3d& point) {
  std::ostringstream out;
  out << "P" << index + 1 << " (" << point.x() << ", " << point.y() << ", " << point.z() << ") mm";
  return out.str();
}

PosePoint makePoint(const AcceptanceInput& input, int index, const Eigen::Vector3d& target,
                    int cycles) {
  const Machine& machine = *input.machine;
  PosePoint point;
  point.commanded = target;
  auto q = solveInverseKinematics(machine, input.parameters, target, nearestStart(input, target));
  if (!q)
    throw RunError(
        input.source, "/machine",
        "ISO 9283: " + pointText(index, target) + " cannot be reached within the joint limits");
  point.joints = *q;
  Eigen::VectorXd x;
  Eigen::MatrixXd J_p, J_q;
  forwardOrThrow(*machine.mechanism, input.parameters, point.joints, x, &J_p, &J_q, 0);
  point.J_p = calibratedColumns(J_p.topRows(3), input.uncertainty.indices);
  point.systematic_covariance = point.J_p * input.uncertainty.V * point.J_p.transpose();
  if (input.noise.encoder.size() > 0) {
    const Eigen::MatrixXd scaled = J_q.topRows(3) * input.noise.encoder.asDiagonal();
    point.noise_covariance = scaled * scaled.transpose() / static_cast<double>(cycles);
  }
  point.sigma_sys = std::sqrt(std::max(0.0, point.systematic_covariance.trace()));
  point.sigma_noise = std::sqrt(std::max(0.0, point.noise_covariance.trace()));
  return point;
}

}  // namespace

PoseTestPrediction predictPoseTestLinear(const AcceptanceInput& input,
                                         const PoseTestOptions& options) {
  if (input.machine->dimension() != 3)
    throw InputError(input.source, "/machine/model",
                     "the ISO 9283 pose test needs a mechanism whose probe moves in 3-D");
  // Every caller (command line, Python) gets the same answer: no cube of infinite edge.
  if (!(options.cube > 0.0) || !std::isfinite(options.cube))
    throw InputError("--cube", "", "the pose test needs --cube E (mm, > 0, finite)");
  if (!options.center.allFinite())
    throw InputError("--center", "", "expected X,Y,Z in mm, e.g. 500,0,400");
  PoseTestPrediction prediction;
  prediction.mpe = options.mpe;
  const std::vector<Eigen::Vector3d> targets = poseTestPoints(options.cube, options.center);
  for (std::size_t i = 0; i < targets.size(); ++i)
    prediction.points.push_back(
        makePoint(input, static_cast<int>(i), targets[i], std::max(options.cycles, 1)));
  return prediction;
}

LinearGaussianTest poseTestModel(const PoseTestPrediction& prediction,
                                 const AcceptanceInput& input) {
  LinearGaussianTest test;
  test.record_results = true;
  const auto n = static_cast<Eigen::Index>(input.uncertainty.indices.size());
  Eigen::MatrixXd J(3 * static_cast<Eigen::Index>(prediction.points.size()), n);
  for (std::size_t i = 0; i < prediction.points.size(); ++i) {
    const PosePoint& point = prediction.points[i];
    J.middleRows(3 * static_cast<Eigen::Index>(i), 3) = point.J_p;
    TestResult result;
    result.first_row = 3 * static_cast<int>(i);
    result.size = 3;
    result.noise_factor = covarianceFactor(point.noise_covariance);
    result.scale = prediction.mpe ? 1.0 / *prediction.mpe : 1.0;
    test.results.push_back(std::move(result));
  }
  test.A = J * covarianceFactor(input.uncertainty.V);
  return test;
}

PoseTestPrediction predictPoseTest(const AcceptanceInput& input, const PoseTestOptions& options) {
  PoseTestPrediction prediction = predictPoseTestLinear(input, options);
  prediction.monte_carlo = runMonteCarlo(poseTestModel(prediction, input), options.monte_carlo);
  const double unit = prediction.mpe ? *prediction.mpe : 1.0;
  auto inMm = [unit](Quantiles q) {
    q.mean *= unit;
    q.median *= unit;
    q.q95 *= unit;
    return q;
  };
  prediction.max_ap = inMm(prediction.monte_carlo.statistic);
  for (std::size_t i = 0; i < prediction.points.size(); ++i)
    prediction.points[i].ap = inMm(prediction.monte_carlo.results[i]);
  return prediction;
}

}  // namespace artcal
