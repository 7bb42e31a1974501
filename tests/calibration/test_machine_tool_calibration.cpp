// Five-axis sphere probing end to end (docs/five-axis.md): a trunnion machine off nominal by
// typical location errors (10-50 um, 10-50 urad) is recovered by calibrate within 3 u, confirm
// confirms the plan's prediction, and verify on held-out probings (two other spheres, other rotary
// positions) agrees with the predicted spread over Monte-Carlo runs with fixed seeds.

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <random>

#include "artcal/artcal.hpp"
#include "artcal/calibration/calibrator.hpp"
#include "artcal/calibration/confirmation.hpp"
#include "artcal/calibration/simulation.hpp"
#include "artcal/calibration/verification.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace machine_tool_calibration_test {

Plan trunnionPlan() {
  return loadPlan(test_support::planFile("machine-tool-trunnion-2spheres.json"));
}

// Positions 10-50 um, angles 10-50 urad, random signs, on every calibrated parameter; E_C0C (a
// turn the spheres' positions absorb) off too: it must not disturb the rest.
Eigen::VectorXd typicalTruth(const Machine& machine, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> size(10.0, 50.0);
  Eigen::VectorXd truth = machine.nominal;
  for (int k : machine.calibrated) {
    const bool angle = machine.mechanism->parameters()[k].quantity == Quantity::Angle;
    const double sign = (rng() & 1) ? 1.0 : -1.0;
    truth[k] += sign * size(rng) * (angle ? 1e-6 : 1e-3);
  }
  truth[machine.mechanism->parameterIndex("E_C0C")] = 40e-6;
  return truth;
}

// Readings of `plan` simulated from a typical truth (truth_seed) with noise (noise_seed) and
// calibrated: every estimate within 3 u of the truth and, jointly, the Mahalanobis distance of
// 11 parameters' noise (chi-square with 11 degrees of freedom in the metric of V_p: mean 11, sd
// 4.7); the nominal machine is far outside it, so the test can fail.
Calibration expectTypicalTruthRecovered(const Plan& plan, std::uint64_t truth_seed,
                                        std::uint64_t noise_seed) {
  const Machine& machine = plan.machine;
  EXPECT_EQ(machine.calibratedCount(), 11);  // 14 less E_A0C, E_C0C, L (check's verdict)
  const Eigen::VectorXd truth = typicalTruth(machine, truth_seed);
  const Simulator simulator(plan);
  NormalSource normal(noise_seed);
  const SimulatedRun run = simulator.simulate(truth, normal);
  Calibrator calibrator(plan, CalibrationOptions{});
  const Calibration result = calibrator.run(run.placements);
  EXPECT_TRUE(result.summary.converged());
  if (!result.covariance) {
    ADD_FAILURE() << "no covariance";
    return result;
  }
  const Eigen::VectorXd estimate = result.estimate(machine);
  const Eigen::VectorXd expected = machine.calibratedValues(truth);
  for (int k = 0; k < machine.calibratedCount(); ++k) {
    EXPECT_LE(std::abs(estimate[k] - expected[k]), 3.0 * result.covariance->u[k])
        << machine.calibratedInfo(k).name;
  }
  const Eigen::MatrixXd information = result.covariance->V.inverse();
  const auto mahalanobis = [&](const Eigen::VectorXd& e) { return e.dot(information * e); };
  EXPECT_LT(mahalanobis(estimate - expected), 11.0 + 4.0 * std::sqrt(22.0));
  EXPECT_GT(mahalanobis(machine.calibratedValues(machine.nominal) - expected), 1000.0);
  EXPECT_LT(result.chi2_per_dof, 2.0);
  return result;
}

TEST(MachineToolCalibration, RecoversTypicalLocationErrorsWithinThreeU) {
  const Calibration result = expectTypicalTruthRecovered(trunnionPlan(), 5, 17);
  ASSERT_TRUE(result.covariance.has_value());
  // F_k >= 1 (a parameter is never better determined than alone).
  for (double f : result.covariance->confounding) EXPECT_GE(f, 1.0 - 1e-9);
}

// A probing cycle commands the rotary axes: the simulated readings hold them exactly as planned
// and the slides are where the true machine's probe sits at the sphere's centre. Noise-free, the
// true forward kinematics at the simulated readings lands on the centre the nominal machine's
// planned readings give (their mean); with noise the rotary readings are still the planned ones.
TEST(MachineToolCalibration, SimulatedProbingHoldsTheCommandedRotaryPositions) {
  const Plan plan = trunnionPlan();
  const Machine& machine = plan.machine;
  const Eigen::VectorXd truth = typicalTruth(machine, 5);
  for (const double scale : {0.0, 1.0}) {
    SimulationOptions options;
    options.noise_scale = scale;
    const Simulator simulator(plan, options);
    NormalSource normal(3);
    const SimulatedRun run = simulator.simulate(truth, normal);
    double largest_move = 0.0;
    for (std::size_t j = 0; j < plan.placements.size(); ++j) {
      const auto& planned = plan.placements[j].measurements;
      const auto& read = run.placements[j].measurements;
      ASSERT_EQ(read.size(), planned.size());
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (const Measurement& m : planned) {
        Eigen::VectorXd x;
        forwardOrThrow(*machine.mechanism, machine.nominal, m.joints, x);
        centre += x / static_cast<double>(planned.size());
      }
      for (std::size_t k = 0; k < planned.size(); ++k) {
        EXPECT_EQ(read[k].joints[3], planned[k].joints[3]);
        EXPECT_EQ(read[k].joints[4], planned[k].joints[4]);
        largest_move = std::max(
            largest_move,
            (read[k].joints.head<3>() - planned[k].joints.head<3>()).lpNorm<Eigen::Infinity>());
        if (scale > 0.0) continue;
        Eigen::VectorXd x;
        forwardOrThrow(*machine.mechanism, truth, read[k].joints, x);
        EXPECT_LT((x - centre).norm(), 1e-9) << j << " " << k;
      }
    }
    EXPECT_GT(largest_move, 0.01);  // the location errors move the slides (mm)
  }
}

TEST(MachineToolCalibration, ConfirmConfirmsThePrediction) {
  ConfirmationOptions options;
  options.trials = 120;
  options.seed = 4;
  options.threads = 1;
  const Confirmation confirmation = confirmPlan(trunnionPlan(), options);
  EXPECT_TRUE(confirmation.confirmed);
}

// Held-out probings: 30 Monte-Carlo runs (seeded) of calibrate on the plan and verify on the
// held-out readings of the same simulated machine. The mean squared observed spread over the mean
// squared predicted one is 1 up to sampling (each run's spread has 16 probings, 2 spheres); a
// nominal machine's spread is an order of magnitude larger, so the check can fail.
TEST(MachineToolCalibration, VerifyOnHeldOutProbingsAgreesWithThePredictedSpread) {
  const Plan plan = trunnionPlan();
  const Plan held_out = loadPlan(test_support::testDataFile("machine-tool-trunnion-held-out.json"));
  const Machine& machine = plan.machine;
  const Simulator simulator(plan), held_simulator(held_out);
  double observed2 = 0.0, predicted2 = 0.0, nominal2 = 0.0;
  const int runs = 30;
  for (int run = 0; run < runs; ++run) {
    const Eigen::VectorXd truth = typicalTruth(machine, 100 + static_cast<std::uint64_t>(run));
    NormalSource normal(200 + static_cast<std::uint64_t>(run));
    const SimulatedRun readings = simulator.simulate(truth, normal);
    Calibrator calibrator(plan, CalibrationOptions{});
    const Calibration result = calibrator.run(readings.placements);
    ASSERT_TRUE(result.summary.converged());
    ASSERT_TRUE(result.covariance.has_value());
    Plan held = held_out;
    held.placements = held_simulator.simulate(truth, normal).placements;
    ParameterUncertainty uncertainty;
    uncertainty.indices = machine.calibrated;
    uncertainty.V = result.covariance->V;
    const Verification verified = verifyMachine(held, result.parameters, uncertainty);
    observed2 += verified.spread_rms * verified.spread_rms;
    predicted2 += verified.predicted_spread_rms * verified.predicted_spread_rms;
    if (const auto nominal = verifyNominal(held))
      nominal2 += nominal->spread_rms * nominal->spread_rms;
  }
  const double ratio = std::sqrt(observed2 / predicted2);
  EXPECT_GT(ratio, 0.8);
  EXPECT_LT(ratio, 1.2);
  EXPECT_GT(std::sqrt(nominal2 / predicted2), 5.0);
}

// The double ball bar between a table ball and the spindle (plans/machine-tool-trunnion-
// ballbar.json: the ball at two positions, 60 readings each). The rank test finds what the spec
// states for a centre the placements absorb: E_C0C not observed (a turn about C moves the table
// ball, whose position is unknown), L tied to E_Z0A and E_A0C to E_A0A; the rest kept. Simulated
// readings of a machine off nominal by typical location errors are recovered within 3 u, and the
// joint Mahalanobis distance is that of noise.
TEST(MachineToolCalibration, TableSpindleBallBarRecoversTypicalLocationErrors) {
  const Plan plan = loadPlan(test_support::planFile("machine-tool-trunnion-ballbar.json"));
  const Machine& machine = plan.machine;
  ASSERT_TRUE(plan.calibrate_resolution.has_value());
  const CalibratedSetResolution& resolution = *plan.calibrate_resolution;
  std::vector<std::string> dropped;
  for (int k : resolution.dropped) dropped.push_back(machine.mechanism->parameters()[k].name);
  std::sort(dropped.begin(), dropped.end());
  EXPECT_EQ(dropped, (std::vector<std::string>{"E_A0C", "E_C0C", "L"}));
  for (std::size_t i = 0; i < resolution.dropped.size(); ++i) {
    const std::string name = machine.mechanism->parameters()[resolution.dropped[i]].name;
    std::vector<std::string> tied;
    for (const auto& [position, coefficient] : resolution.ties[i])
      if (std::abs(coefficient) > 0.05)
        tied.push_back(machine.mechanism->parameters()[resolution.listed[position]].name);
    std::sort(tied.begin(), tied.end());
    if (name == "L") {
      EXPECT_EQ(tied, (std::vector<std::string>{"E_Z0A", "L"}));
    } else if (name == "E_A0C") {
      EXPECT_EQ(tied, (std::vector<std::string>{"E_A0A", "E_A0C"}));
    } else {
      EXPECT_TRUE(tied.empty() || tied == std::vector<std::string>{"E_C0C"});
    }
  }
  expectTypicalTruthRecovered(plan, 9, 23);
}

TEST(MachineToolCalibration, TableSpindleBallBarConfirmsThePrediction) {
  ConfirmationOptions options;
  options.trials = 120;
  options.seed = 4;
  options.threads = 1;
  const Confirmation confirmation =
      confirmPlan(loadPlan(test_support::planFile("machine-tool-trunnion-ballbar.json")), options);
  EXPECT_TRUE(confirmation.confirmed);
}

}  // namespace machine_tool_calibration_test
}  // namespace artcal
