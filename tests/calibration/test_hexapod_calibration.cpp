// The hexapod end to end (models.md section 3): the plans' task-space workspaces assemble, and a
// simulated machine off nominal is recovered by the calibrator.

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <random>

#include "artcal/internal.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace hexapod_calibration_test {

Plan handMadePlan() {
  return loadPlan(test_support::planFile("hexapod-10bars.json"));
}

// Forward kinematics from home converges over the whole task-space workspace (4096 probe
// positions, platform tilts up to 10 deg): nothing is dropped for a failed or foreign assembly.
TEST(HexapodWorkspace, ForwardKinematicsConvergesOverTheTaskSpaceWorkspace) {
  const Plan plan = handMadePlan();
  ASSERT_EQ(plan.workspace.kind, WorkspaceSpec::Kind::TaskSpace);
  WorkspaceDrops drops;
  const auto configurations = workspaceConfigurations(plan.machine, plan.workspace, &drops);
  EXPECT_EQ(drops.failed, 0);
  EXPECT_EQ(static_cast<int>(configurations.size()) + drops.total(), plan.workspace.samples);
  // Every configuration is within the leg ranges and puts the probe inside the region.
  Eigen::VectorXd x;
  for (const Eigen::VectorXd& q : configurations) {
    ASSERT_TRUE(plan.machine.withinLimits(q));
    ASSERT_EQ(plan.machine.mechanism->forward(plan.machine.nominal, q, x), ForwardStatus::Ok);
    ASSERT_TRUE(plan.workspace.region.contains(x));
  }
}

// Leg offsets 0.5 mm and joint centres 0.2 mm (each coordinate) off nominal, with random signs;
// the 12 parameters that fix the base and platform frames stay at nominal (they are not
// calibrated: the frames are a convention, models.md section 3).
TEST(HexapodCalibration, RecoversSimulatedParametersWithinThreeStandardUncertainties) {
  const Plan plan = handMadePlan();
  ASSERT_EQ(plan.placements.size(), 10u);
  const Machine& machine = plan.machine;
  Eigen::VectorXd truth = machine.nominal;
  std::mt19937_64 signs(3);
  for (int k : machine.calibrated) {
    const bool offset = machine.mechanism->parameters()[k].name.find("offset") != std::string::npos;
    truth[k] += ((signs() & 1) ? 1.0 : -1.0) * (offset ? 0.5 : 0.2);
  }
  const Simulator simulator(plan);
  NormalSource normal(11);
  const SimulatedRun run = simulator.simulate(truth, normal);
  CalibrationOptions options;
  Calibrator calibrator(plan, options);
  const Calibration result = calibrator.run(run.placements);
  ASSERT_TRUE(result.summary.converged());
  ASSERT_TRUE(result.covariance.has_value());
  const Eigen::VectorXd estimate = result.estimate(machine);
  const Eigen::VectorXd expected = machine.calibratedValues(truth);
  for (int k = 0; k < machine.calibratedCount(); ++k) {
    EXPECT_LE(std::abs(estimate[k] - expected[k]), 3.0 * result.covariance->u[k])
        << machine.calibratedInfo(k).name;
  }
  // Jointly: the estimate's error is a chi-square with 33 degrees of freedom in the metric of
  // V_p (mean 33, sd 8), and the nominal machine is far outside it: the test can fail.
  const Eigen::MatrixXd information = result.covariance->V.inverse();
  const auto mahalanobis = [&](const Eigen::VectorXd& e) { return e.dot(information * e); };
  const double of_estimate = mahalanobis(estimate - expected);
  const double of_nominal = mahalanobis(machine.calibratedValues(machine.nominal) - expected);
  EXPECT_LT(of_estimate, 33.0 + 4.0 * std::sqrt(66.0));
  EXPECT_GT(of_nominal, 10.0 * (33.0 + 4.0 * std::sqrt(66.0)));
  EXPECT_LT(result.chi2_per_dof, 1.5);
}

// A reading the forward kinematics cannot solve is bad input, named by its JSON pointer.
TEST(HexapodPlan, UnsolvableReadingIsAnInputErrorNamingIt) {
  nlohmann::json doc = readJsonFile(test_support::planFile("hexapod-10bars.json"));
  doc["placements"][2]["measurements"][4]["joints"] = {450, 800, 450, 800, 450, 800};
  try {
    parsePlan(doc, "broken.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "/placements/2/measurements/4/joints");
  }
}

}  // namespace hexapod_calibration_test
}  // namespace artcal
