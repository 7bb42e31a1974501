#include "artcal/acceptance/pose_acceptance.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "artcal/core/error.hpp"
#include "artcal/model/inverse_kinematics.hpp"
#include "artcal/model/rotation_vector.hpp"

namespace artcal {

std::vector<Eigen::Vector3d> poseTestPoints(double cube, const Eigen::Vector3d& center,
                                            const Eigen::Matrix3d& axes) {
  const double h = 0.5 * cube;
  const Eigen::Vector3d Q1 = center + axes * Eigen::Vector3d(-h, -h, -h);
  const Eigen::Vector3d Q2 = center + axes * Eigen::Vector3d(h, h, -h);
  const Eigen::Vector3d Q3 = center + axes * Eigen::Vector3d(h, h, h);
  const Eigen::Vector3d Q4 = center + axes * Eigen::Vector3d(-h, -h, h);
  return {center, Q1 + 0.1 * (Q3 - Q1), Q2 + 0.1 * (Q4 - Q2), Q3 + 0.1 * (Q1 - Q3),
          Q4 + 0.1 * (Q2 - Q4)};
}

double predictedRepeatability(const Eigen::Matrix3d& cycle_covariance) {
  const double m = expectedGaussianNorm(cycle_covariance);
  return m + 3.0 * std::sqrt(std::max(0.0, cycle_covariance.trace() - m * m));
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

/// Where the inverse kinematics of a point starts: with a seed posture, the previous point's
/// solution (the seed for P1); without, the workspace configuration nearest the point (the spec).
Eigen::VectorXd ikStart(const AcceptanceInput& input, const PoseTestOptions& options,
                        const Eigen::Vector3d& target,
                        const std::optional<Eigen::VectorXd>& previous) {
  if (!options.seed_posture) return nearestStart(input, target);
  return previous ? *previous : *options.seed_posture;
}

/// The joints that put the probe on `target`: from `start`, then with a seed posture each angle
/// moved by whole turns to the equivalent nearest the seed within the limits.
Eigen::VectorXd reachPoint(const AcceptanceInput& input, const PoseTestOptions& options, int index,
                           const Eigen::Vector3d& target, const Eigen::VectorXd& start) {
  const Machine& machine = *input.machine;
  auto q = solveInverseKinematics(machine, input.parameters, target, start);
  if (!q)
    throw RunError(
        input.source, "/machine",
        "ISO 9283: " + pointText(index, target) + " cannot be reached within the joint limits");
  if (!options.seed_posture) return *q;
  Eigen::VectorXd nearest = *q;
  return nearestEquivalentWithinLimits(machine, *options.seed_posture, nearest) ? nearest : *q;
}

/// The point's covariances and linear statistics at its joints (method.md section 9).
PosePoint makePoint(const AcceptanceInput& input, const PoseTestOptions& options,
                    const Eigen::Vector3d& target, const Eigen::VectorXd& joints) {
  const Machine& machine = *input.machine;
  PosePoint point;
  point.commanded = target;
  point.joints = joints;
  Eigen::VectorXd x;
  Eigen::MatrixXd J_p, J_q;
  forwardOrThrow(*machine.mechanism, input.parameters, point.joints, x, &J_p, &J_q, 0);
  point.J_p = calibratedColumns(J_p.topRows(3), input.uncertainty.indices);
  point.systematic_covariance = point.J_p * input.uncertainty.V * point.J_p.transpose();
  if (input.noise.encoder.size() > 0) {
    const Eigen::MatrixXd scaled = J_q.topRows(3) * input.noise.encoder.asDiagonal();
    point.cycle_covariance = scaled * scaled.transpose();
  }
  point.noise_covariance =
      point.cycle_covariance / static_cast<double>(std::max(options.cycles, 1));
  const Eigen::Matrix3d unmodelled =
      options.unmodelled * options.unmodelled * Eigen::Matrix3d::Identity();
  point.sigma_sys = std::sqrt(std::max(0.0, point.systematic_covariance.trace()));
  point.sigma_noise = std::sqrt(std::max(0.0, point.noise_covariance.trace()));
  point.sigma_unmodelled = std::sqrt(unmodelled.trace());
  point.ap_expected =
      expectedGaussianNorm(point.systematic_covariance + point.noise_covariance + unmodelled);
  point.rp = predictedRepeatability(point.cycle_covariance);
  return point;
}

/// The options a caller may have set out of range: InputError naming the option.
void checkPoseOptions(const Machine& machine, const PoseTestOptions& options) {
  // Every caller (command line, Python) gets the same answer: no cube of infinite edge.
  if (!(options.cube > 0.0) || !std::isfinite(options.cube))
    throw InputError("--cube", "", "the pose test needs --cube E (mm, > 0, finite)");
  if (!options.center.allFinite())
    throw InputError("--center", "", "expected X,Y,Z in mm, e.g. 500,0,400");
  if (!options.orientation.allFinite())
    throw InputError("--orientation", "", "expected ROLL,PITCH,YAW in deg, e.g. 0,0,45");
  // The bounds of every standard deviation of a plan (0 allowed here: unknown).
  if (!(options.unmodelled >= 0.0 && options.unmodelled <= 1e6))
    throw InputError("--unmodelled", "",
                     "the unmodelled error is a standard deviation per coordinate in mm, 0 .. 1e6");
  if (!options.seed_posture) return;
  const Eigen::VectorXd& seed = *options.seed_posture;
  if (seed.size() != machine.jointCount() || !seed.allFinite())
    throw InputError("--seed-posture", "",
                     "expected " + std::to_string(machine.jointCount()) +
                         " joint values (deg or mm), one per joint of the machine");
  Eigen::VectorXd equivalent = seed;
  if (!nearestEquivalentWithinLimits(machine, seed, equivalent))
    throw InputError("--seed-posture", "",
                     "the seed posture is outside the machine's joint_limits: check its values "
                     "and units (deg, mm)");
}

/// The seed posture within the limits: a revolute angle beyond them moved by whole turns (a
/// plan without joint_limits wraps its readings alike), checked by checkPoseOptions.
PoseTestOptions withSeedWithinLimits(const Machine& machine, PoseTestOptions options) {
  if (!options.seed_posture) return options;
  const Eigen::VectorXd seed = *options.seed_posture;
  nearestEquivalentWithinLimits(machine, seed, *options.seed_posture);
  return options;
}

}  // namespace

PoseTestPrediction predictPoseTestLinear(const AcceptanceInput& input,
                                         const PoseTestOptions& given) {
  if (input.machine->dimension() != 3)
    throw InputError(input.source, "/machine/model",
                     "the ISO 9283 pose test needs a mechanism whose probe moves in 3-D");
  checkPoseOptions(*input.machine, given);
  const PoseTestOptions options = withSeedWithinLimits(*input.machine, given);
  PoseTestPrediction prediction;
  prediction.mpe = options.mpe;
  const std::vector<Eigen::Vector3d> targets =
      poseTestPoints(options.cube, options.center, rpyToMatrix(options.orientation));
  std::optional<Eigen::VectorXd> previous;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const Eigen::VectorXd start = ikStart(input, options, targets[i], previous);
    previous = reachPoint(input, options, static_cast<int>(i), targets[i], start);
    prediction.points.push_back(makePoint(input, options, targets[i], *previous));
  }
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
    // The unmodelled error u_P: fixed over the cycles, independent between the points.
    const double u2 = point.sigma_unmodelled * point.sigma_unmodelled / 3.0;
    result.noise_factor =
        covarianceFactor(point.noise_covariance + u2 * Eigen::Matrix3d::Identity());
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
