// Calibrating a Cartesian CMM (models.md section 4): a simulated machine with known error
// functions of degree 3 (a few um and um/m) is recovered within 3 standard uncertainties on
// every identifiable coefficient, and, the model being nearly linear in p, two plain
// Gauss-Newton steps from nominal converge.

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "artcal/artcal.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace cartesian_calibration_test {

Plan cmmPlan() {
  return loadPlan(test_support::planFile("cmm-plate-3planes-2styli-diagonals.json"));
}

// Every calibrated coefficient drawn uniformly within +-3 um (translations) or +-3 um/m
// (rotations); the others stay at 0 (the plan cannot tell them from the kept ones).
Eigen::VectorXd knownErrors(const Plan& plan, std::uint64_t seed) {
  NormalSource draw(seed);
  Eigen::VectorXd p = plan.machine.nominal;
  for (const int i : plan.machine.calibrated) {
    const bool rotation =
        plan.machine.mechanism->parameters()[static_cast<std::size_t>(i)].name.find(".r") !=
        std::string::npos;
    p[i] = (2.0 * draw.uniform() - 1.0) * (rotation ? 3e-6 : 0.003);
  }
  return p;
}

TEST(CartesianCalibration, KnownErrorFunctionsRecoveredWithinThreeUncertainties) {
  const Plan plan = cmmPlan();
  ASSERT_EQ(plan.machine.mechanism->parameterCount(), 54);
  ASSERT_GE(plan.machine.calibratedCount(), 50);
  const Eigen::VectorXd truth = knownErrors(plan, 21);
  NormalSource normal(4);
  const std::vector<Placement> readings = Simulator(plan).simulate(truth, normal).placements;
  const Calibration result = Calibrator(plan).run(readings);
  ASSERT_TRUE(result.summary.converged()) << result.summary.briefReport();
  ASSERT_TRUE(result.covariance);
  EXPECT_GT(result.chi2_per_dof, 0.8);
  EXPECT_LT(result.chi2_per_dof, 1.2);
  int beyond_one_u = 0, many_u = 0;
  for (int k = 0; k < plan.machine.calibratedCount(); ++k) {
    const int i = plan.machine.calibrated[static_cast<std::size_t>(k)];
    const double u = result.covariance->u[k];
    const double error = result.parameters[i] - truth[i];
    EXPECT_LT(std::abs(error), 3.0 * u) << plan.machine.calibratedInfo(k).name;
    beyond_one_u += std::abs(error) > u;
    many_u += std::abs(truth[i]) > 3.0 * u;
  }
  // Most errors are many u: recovering them is not a matter of staying at nominal.
  EXPECT_GT(many_u, plan.machine.calibratedCount() / 3);
  // About a third of Gaussian errors exceed 1 u: the u are not inflated either.
  EXPECT_GT(beyond_one_u, plan.machine.calibratedCount() / 8);
}

TEST(CartesianCalibration, TwoGaussNewtonStepsConverge) {
  const Plan plan = cmmPlan();
  const Eigen::VectorXd truth = knownErrors(plan, 5);
  NormalSource normal(6);
  const std::vector<Placement> readings = Simulator(plan).simulate(truth, normal).placements;
  Calibrator calibrator(plan);
  CalibrationState state = calibrator.initialState(readings, plan.machine.nominal);
  CalibrationState next;
  Linearization lin;
  std::vector<double> steps;  // largest |dg_i| sqrt(N_ii): the step in conditional u
  for (int it = 0; it < 3; ++it) {
    ASSERT_TRUE(calibrator.linearize(readings, state, lin));
    const Eigen::VectorXd dg = lin.N.ldlt().solve(lin.b);  // undamped Gauss-Newton
    steps.push_back((dg.array().abs() * lin.N.diagonal().array().sqrt()).maxCoeff());
    if (it == 2) break;
    calibrator.step(state, lin, dg, readings, next);
    state = next;
  }
  EXPECT_GT(steps[0], 10.0);  // the first step moves the estimate by many u
  EXPECT_LT(steps[2], 1e-3);  // after two steps what is left is the convergence tolerance
  // ... and the two-step estimate is the Levenberg-Marquardt calibration's.
  const Calibration full = calibrator.run(readings);
  ASSERT_TRUE(full.summary.converged());
  ASSERT_TRUE(full.covariance);
  for (int k = 0; k < plan.machine.calibratedCount(); ++k) {
    const int i = plan.machine.calibrated[static_cast<std::size_t>(k)];
    EXPECT_NEAR(state.p[i], full.parameters[i], 1e-2 * full.covariance->u[k])
        << plan.machine.calibratedInfo(k).name;
  }
}

}  // namespace cartesian_calibration_test
}  // namespace artcal
