// The calibrator (method.md section 6): reference estimates, its derivative against finite
// differences, convergence from wrong nominal values, a mis-probed ball, non-convergence, and the
// damping strategy on its own.

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <array>
#include <cstdio>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

#include "artcal/internal.hpp"
#include "artcal/calibration/calibrator.hpp"
#include "artcal/calibration/levenberg_marquardt.hpp"
#include "artcal/calibration/simulation.hpp"
#include "artcal/io/truth_io.hpp"
#include "artcal/report/calibration_report.hpp"
#include "cli_runner.hpp"
#include "plan_builders.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace calibrator_test {

Plan testPlan(const std::string& name) {
  return loadPlan(test_support::testDataFile(name + ".json"));
}

using test_support::CliRun;
using test_support::runCli;

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "/artcal-calibrator-" + name;
}

/// Lengths 1 % off, angles 1 deg off, over the calibrated parameters.
Eigen::VectorXd wrongNominal(const Machine& machine) {
  Eigen::VectorXd p = machine.nominal;
  for (int k = 0; k < machine.calibratedCount(); ++k) {
    const int i = machine.calibrated[static_cast<std::size_t>(k)];
    if (machine.calibratedInfo(k).quantity == Quantity::Angle) {
      p[i] += degToRad(1.0);
    } else {
      p[i] *= 1.01;
    }
  }
  return p;
}

/// Readings of a machine with parameters `truth`, without any noise.
std::vector<Placement> exactReadings(const Plan& plan, const Eigen::VectorXd& truth) {
  SimulationOptions options;
  options.noise_scale = 0.0;
  NormalSource normal(1);
  return Simulator(plan, options).simulate(truth, normal).placements;
}

// ------------------------------------------------------------------------------------------ LM

// A parameter prior (machine.prior, docs/method.md section 3) is a whitened row per parameter:
// V_p = (N_red + Sigma_p0^-1)^-1 against the dense inverse, and identifiability is the readings'.
TEST(ParameterPrior, AddsItsInverseVarianceToTheInformation) {
  Plan plan =
      testing::seedPlanar2RPlan(0.002);  // with a systematic c: the prior must sit beside it
  plan.placements = testing::randomPlanarBars(plan, 5, 21);
  const Eigen::MatrixXd N0 = placementsInformation(plan, plan.placements, plan.machine.nominal);
  const Eigen::Vector3d sigma(0.004, 0.0, 2e-5);  // l2 without a prior
  plan.machine.prior_sigma = sigma;
  const PlanInformation with = planInformation(plan, plan.placements, plan.machine.nominal);
  EXPECT_LT((with.reduced - N0).cwiseAbs().maxCoeff(), 1e-9 * N0.cwiseAbs().maxCoeff());
  Eigen::Matrix3d expected = N0;
  expected(0, 0) += 1.0 / (sigma[0] * sigma[0]);
  expected(2, 2) += 1.0 / (sigma[2] * sigma[2]);
  const Evaluation evaluation = evaluatePlan(plan);
  ASSERT_TRUE(evaluation.covariance);
  const Eigen::Matrix3d V = expected.inverse();
  EXPECT_LT((evaluation.covariance->V - V).cwiseAbs().maxCoeff(), 1e-9 * V.cwiseAbs().maxCoeff());
  EXPECT_LT(evaluation.covariance->u[0], sigma[0]);
  EXPECT_EQ(GlobalLayout::of(plan).priorRows(), 2);
}

// The calibrator's cost has the prior rows too: a prior far tighter than the data holds a
// parameter at its nominal value, and a simulated offset goes into the others' estimates.
TEST(ParameterPrior, TightHoldsAParameterAtNominalInTheCalibration) {
  Plan plan = testing::seedPlanar2RPlan(0.0);
  plan.placements = testing::randomPlanarBars(plan, 5, 21);
  Eigen::VectorXd p_true = plan.machine.nominal;
  p_true[0] += 0.2;  // l1 0.2 mm off: many u
  SimulationOptions exact;
  exact.noise_scale = 0.0;
  const Simulator simulator(plan, exact);
  NormalSource normal(3);
  plan.placements = simulator.simulate(p_true, normal).placements;
  plan.machine.prior_sigma = Eigen::Vector3d(1e-7, 0.0, 0.0);
  const Calibration held = calibratePlan(plan);
  ASSERT_TRUE(held.summary.converged());
  EXPECT_LT(std::abs(held.parameters[0] - plan.machine.nominal[0]), 1e-5);
  EXPECT_GT(held.chi2, 10.0);  // the readings disagree with l1 at nominal
  plan.machine.prior_sigma = Eigen::Vector3d(10.0, 0.0, 0.0);
  const Calibration free = calibratePlan(plan);
  ASSERT_TRUE(free.summary.converged());
  // A 10 mm prior pulls by about offset * u(l1)^2 / sigma^2 ~ 1e-7 mm; convergence stops ~1e-6.
  EXPECT_NEAR(free.parameters[0], p_true[0], 1e-5);
}

TEST(LevenbergMarquardt, SmallDampingGivesTheGaussNewtonStep) {
  Eigen::MatrixXd N(2, 2);
  N << 4.0, 1.0, 1.0, 9.0;
  const Eigen::VectorXd b = Eigen::Vector2d(1.0, -2.0);
  DampingOptions options;
  options.initial_mu = 1e-14;
  LevenbergMarquardtStrategy strategy(options);
  Eigen::VectorXd dg;
  ASSERT_TRUE(strategy.computeStep(N, b, dg));
  const Eigen::VectorXd exact = N.ldlt().solve(b);
  EXPECT_NEAR((dg - exact).norm(), 0.0, 1e-12);
  // The predicted reduction of the quadratic model at its minimum is b^T N^-1 b.
  EXPECT_NEAR(LevenbergMarquardtStrategy::predictedReduction(N, b, dg), b.dot(exact), 1e-12);
}

TEST(LevenbergMarquardt, DampingShortensTheStepAlongTheScaledGradient) {
  Eigen::MatrixXd N(2, 2);
  N << 4.0, 1.0, 1.0, 9.0;
  const Eigen::VectorXd b = Eigen::Vector2d(1.0, -2.0);
  DampingOptions options;
  options.initial_mu = 1e6;
  LevenbergMarquardtStrategy strategy(options);
  Eigen::VectorXd dg;
  ASSERT_TRUE(strategy.computeStep(N, b, dg));
  // (D N D + mu I) y = D b with mu huge: dg ~ D^2 b / mu.
  const Eigen::VectorXd expected = N.diagonal().cwiseInverse().cwiseProduct(b) / 1e6;
  EXPECT_NEAR((dg - expected).norm() / expected.norm(), 0.0, 1e-5);
}

TEST(LevenbergMarquardt, MuFollowsNielsensRule) {
  DampingOptions options;
  options.initial_mu = 1.0;
  options.max_mu = 100.0;
  LevenbergMarquardtStrategy strategy(options);
  strategy.stepRejected();
  EXPECT_DOUBLE_EQ(strategy.mu(), 2.0);
  strategy.stepRejected();
  EXPECT_DOUBLE_EQ(strategy.mu(), 8.0);
  strategy.stepAccepted(1.0);  // a perfect model: mu / 3
  EXPECT_DOUBLE_EQ(strategy.mu(), 8.0 / 3.0);
  strategy.stepAccepted(0.5);  // 1 - 0^3 = 1: unchanged
  EXPECT_DOUBLE_EQ(strategy.mu(), 8.0 / 3.0);
  strategy.stepRejected();  // nu was reset to 2 by the accepted steps
  EXPECT_DOUBLE_EQ(strategy.mu(), 16.0 / 3.0);
  EXPECT_FALSE(strategy.exhausted());
  for (int i = 0; i < 4; ++i) strategy.stepRejected();
  EXPECT_TRUE(strategy.exhausted());
}

TEST(LevenbergMarquardt, OptionsAreValidated) {
  std::string error;
  DampingOptions bad;
  bad.initial_mu = -1.0;
  EXPECT_FALSE(bad.isValid(&error));
  EXPECT_FALSE(error.empty());
  EXPECT_TRUE(DampingOptions{}.isValid(&error));
  CalibrationOptions options;
  options.max_iterations = 0;
  EXPECT_FALSE(options.isValid(&error));
  EXPECT_THROW(Calibrator(testPlan("ref-2r-5bars"), options), std::invalid_argument);
}

// --------------------------------------------------------------------------------- reference

TEST(Calibrator, MatchesTheReferenceCalibration) {
  const Plan plan = testPlan("ref-2r-calibrate");
  std::ifstream in(test_support::testDataFile("ref-2r-calibrate.expected.json"));
  const nlohmann::json expected = nlohmann::json::parse(in);
  const Calibration calibration = calibratePlan(plan);
  ASSERT_TRUE(calibration.summary.converged()) << calibration.summary.briefReport();
  const nlohmann::json got = calibrationToJson(plan, plan.placements, calibration);
  ASSERT_EQ(got["parameters"].size(), expected["parameters"].size());
  for (std::size_t k = 0; k < expected["parameters"].size(); ++k) {
    const auto& e = expected["parameters"][k];
    const auto& g = got["parameters"][k];
    EXPECT_EQ(g["name"], e["name"]);
    const double u = e["u"].get<double>();
    EXPECT_NEAR(g["estimate"].get<double>(), e["estimate"].get<double>(), 0.05 * u) << e["name"];
    EXPECT_NEAR(g["u"].get<double>(), u, 0.05 * u) << e["name"];
    EXPECT_NEAR(g["u_posterior"].get<double>(),
                u * std::sqrt(expected["chi2_per_dof"].get<double>()), 0.05 * u);
  }
  EXPECT_NEAR(got["chi2_per_dof"].get<double>(), expected["chi2_per_dof"].get<double>(), 1e-3);
  EXPECT_EQ(got["dof"], 7);  // 10 bars x 4 coordinates - 3 parameters - 10 x 3 rigid
}

// ------------------------------------------------------------------------- finite differences

// Along (dg, dr_j = rigidStep(dg) - rigidStep(0)) the cost changes at the rate -2 b^T dg; a
// central difference checks the reduced gradient, the prior term on c and the back-substitution.
// The encoder noise is switched off: with it the weights depend on p (through J_q) and b is the
// reweighted Gauss-Newton right-hand side, which leaves that dependence out by design.
TEST(Calibrator, ReducedGradientMatchesFiniteDifferences) {
  Plan plan = testPlan("cal-2r-5bars-ulength");
  plan.noise.encoder.setZero();
  NormalSource normal(11);
  const std::vector<Placement> readings =
      Simulator(plan).simulate(wrongNominal(plan.machine), normal).placements;
  Calibrator calibrator(plan);
  CalibrationState state = calibrator.initialState(readings, plan.machine.nominal);
  state.c[0] = 0.003;
  Linearization at;
  ASSERT_TRUE(calibrator.linearize(readings, state, at));
  ASSERT_EQ(at.b.size(), 4);
  const Eigen::VectorXd directions[] = {
      Eigen::Vector4d(1e-3, 0, 0, 0), Eigen::Vector4d(0, 1e-3, 0, 0),
      Eigen::Vector4d(0, 0, 1e-5, 0), Eigen::Vector4d(0, 0, 0, 1e-3),
      Eigen::Vector4d(2e-3, -1e-3, 3e-5, 1e-3)};
  for (const Eigen::VectorXd& dg : directions) {
    auto costAt = [&](double t) {
      CalibrationState moved = state;
      moved.p = plan.machine.withCalibrated(
          state.p, plan.machine.calibratedValues(state.p) + t * dg.head(3));
      moved.c = state.c + t * dg.tail(1);
      for (std::size_t j = 0; j < readings.size(); ++j) {
        const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(readings[j].artifact)];
        const Eigen::VectorXd dr =
            at.eliminations[j].rigidStep(dg) - at.eliminations[j].rigidStep(0.0 * dg);
        moved.poses[j] = state.poses[j].perturbed(artifact.expandFullRigidStep(t * dr));
      }
      Linearization lin;
      EXPECT_TRUE(calibrator.linearize(readings, moved, lin));
      return lin.cost;
    };
    const double h = 1e-3;
    const double numeric = (costAt(h) - costAt(-h)) / (2 * h);
    const double analytic = -2.0 * at.b.dot(dg);
    EXPECT_NEAR(numeric, analytic, 1e-5 * std::abs(analytic) + 1e-9) << dg.transpose();
  }
}

// ------------------------------------------------------------------------------ convergence

void expectConvergesFromWrongNominal(const Plan& plan) {
  const Eigen::VectorXd truth = plan.machine.nominal;
  const std::vector<Placement> readings = exactReadings(plan, truth);
  Calibrator calibrator(plan);
  const Calibration calibration = calibrator.run(readings, wrongNominal(plan.machine));
  ASSERT_TRUE(calibration.summary.converged()) << calibration.summary.briefReport();
  ASSERT_TRUE(calibration.covariance.has_value());
  const Eigen::VectorXd error =
      calibration.estimate(plan.machine) - plan.machine.calibratedValues(truth);
  for (int k = 0; k < error.size(); ++k) {
    EXPECT_LT(std::abs(error[k]), 1e-3 * calibration.covariance->u[k])
        << plan.machine.calibratedInfo(k).name;
  }
  EXPECT_LT(calibration.chi2_per_dof, 1e-6);  // noise-free readings fit exactly
}

TEST(Calibrator, ConvergesFromWrongNominalPlanar2R) {
  expectConvergesFromWrongNominal(testPlan("ref-2r-5bars"));
}

TEST(Calibrator, ConvergesFromWrongNominalSixAxisArm) {
  expectConvergesFromWrongNominal(testPlan("ref-aacmm-3bars-3postures"));
}

TEST(Calibrator, ConvergesFromWrongNominalWithSystematicArtifactError) {
  expectConvergesFromWrongNominal(testPlan("cal-2r-5bars-ulength"));
}

TEST(Calibrator, UncertaintyAtTheEstimateEqualsThePredictionAtTheTruth) {
  // With exact readings the estimate is the truth, so V_p there is evaluatePlan's V_p.
  const Plan plan = testPlan("ref-aacmm-3bars-3postures");
  const Calibration calibration = Calibrator(plan).run(exactReadings(plan, plan.machine.nominal));
  const Evaluation prediction = evaluatePlan(plan);
  ASSERT_TRUE(calibration.covariance && prediction.covariance);
  for (int k = 0; k < plan.machine.calibratedCount(); ++k) {
    EXPECT_NEAR(calibration.covariance->u[k], prediction.covariance->u[k],
                1e-6 * prediction.covariance->u[k]);
  }
}

TEST(Calibrator, ReportsNonConvergenceWithFiniteNumbers) {
  const Plan plan = testPlan("ref-2r-5bars");
  CalibrationOptions options;
  options.max_iterations = 1;
  const Calibration calibration =
      Calibrator(plan, options).run(exactReadings(plan, wrongNominal(plan.machine)));
  EXPECT_FALSE(calibration.summary.converged());
  EXPECT_EQ(calibration.summary.termination, TerminationType::NoConvergence);
  EXPECT_EQ(calibration.summary.iterations, 1);
  EXPECT_TRUE(calibration.parameters.allFinite());
  EXPECT_TRUE(std::isfinite(calibration.chi2));
  const std::string json = calibrationToJson(plan, plan.placements, calibration).dump();
  EXPECT_EQ(json.find("NaN"), std::string::npos);
  EXPECT_EQ(json.find("null"), std::string::npos);
}

// -------------------------------------------------------------------------------- residuals

/// Moves reading `i` of placement `j` so that it probes a point `shift` (machine frame, mm) away
/// from where it did: a mis-probed ball.
void misprobe(Plan& plan, int j, int i, const Eigen::VectorXd& shift) {
  Measurement& m =
      plan.placements[static_cast<std::size_t>(j)].measurements[static_cast<std::size_t>(i)];
  Eigen::VectorXd x;
  forwardOrThrow(*plan.machine.mechanism, plan.machine.nominal, m.joints, x);
  const auto q = solveInverseKinematics(plan.machine, plan.machine.nominal, x + shift, m.joints);
  ASSERT_TRUE(q.has_value());
  m.joints = *q;
}

TEST(Calibrator, MisprobedBallStandsOutPlanar2R) {
  Plan plan = testPlan("ref-2r-calibrate");
  const Calibration clean = calibratePlan(plan);
  ASSERT_GE(clean.largest_residual, 0);
  EXPECT_LT(clean.residuals[static_cast<std::size_t>(clean.largest_residual)].score, 3.0);
  // 50 um (10 s_p) along the bar: the bar's only redundant direction in the plane.
  const RigidTransform pose = fitPlacements(plan, plan.placements, clean.parameters)[4];
  misprobe(plan, 4, 1, 0.05 * pose.R.row(0).transpose());
  const Calibration corrupted = calibratePlan(plan);
  ASSERT_TRUE(corrupted.summary.converged());
  const ResidualEntry& largest =
      corrupted.residuals[static_cast<std::size_t>(corrupted.largest_residual)];
  EXPECT_EQ(largest.placement, 4);  // a 2-D bar: both of its balls carry the same misfit
  EXPECT_TRUE(largest.flagged);
  // With 7 degrees of freedom the fit spreads part of the error over the other bars; the
  // mis-probed bar still stands clearly above every other one.
  double elsewhere = 0.0;
  for (const ResidualEntry& entry : corrupted.residuals) {
    if (entry.placement != 4) elsewhere = std::max(elsewhere, entry.score);
  }
  EXPECT_GT(largest.score, 1.5 * elsewhere);
}

// The 3-bar plan has 18 degrees of freedom for 54 coordinates: the fit absorbs much of any
// single error, and some directions at some readings hardly show at all. A 0.2 mm (20 s_p)
// mis-probe at two different readings must still be the largest, flagged residual.
void expectMisprobeStandsOut(int placement, int measurement) {
  Plan plan = testPlan("ref-aacmm-3bars-3postures");
  NormalSource normal(5);
  plan.placements = Simulator(plan).simulate(plan.machine.nominal, normal).placements;
  const Calibration clean = calibratePlan(plan);
  ASSERT_TRUE(clean.summary.converged());
  EXPECT_LT(clean.residuals[static_cast<std::size_t>(clean.largest_residual)].score, 3.0);
  misprobe(plan, placement, measurement, 0.2 * Eigen::Vector3d(1, -1, 1).normalized());
  const Calibration corrupted = calibratePlan(plan);
  ASSERT_TRUE(corrupted.summary.converged());
  const ResidualEntry& largest =
      corrupted.residuals[static_cast<std::size_t>(corrupted.largest_residual)];
  EXPECT_EQ(largest.placement, placement);
  EXPECT_EQ(largest.measurement, measurement);
  EXPECT_TRUE(largest.flagged);
  EXPECT_GT(corrupted.chi2_per_dof, 3.0 * clean.chi2_per_dof);
}

TEST(Calibrator, MisprobedBallStandsOutSixAxisArm) {
  expectMisprobeStandsOut(0, 4);
  expectMisprobeStandsOut(2, 0);
}

// The standardised residuals have unit variance under the noise model: over many simulated
// calibrations their mean square is 1 (the whitened ones alone would average dof / rows).
TEST(Calibrator, StandardisedResidualsHaveUnitVariance) {
  const Plan plan = testPlan("ref-aacmm-3bars-3postures");
  Calibrator calibrator(plan);
  double sum = 0.0;
  int count = 0;
  for (int seed = 1; seed <= 200; ++seed) {
    NormalSource normal(static_cast<std::uint64_t>(seed));
    const Calibration c =
        calibrator.run(Simulator(plan).simulate(plan.machine.nominal, normal).placements);
    for (const ResidualEntry& entry : c.residuals) {
      sum += entry.standardized.squaredNorm();
      count += static_cast<int>(entry.standardized.size());
    }
  }
  EXPECT_NEAR(sum / count, 1.0, 0.05);
}

// The gross-error limit is gross_threshold * max(1, Birge ratio): readings that scatter less than
// the stated noise (Birge ratio < 1) must not lower the limit below gross_threshold. Readings
// simulated with a third of the stated noise, one reading moved by 0.08 mm: its score (2.3) lies
// between threshold * Birge ratio (2.5 * 0.75) and the threshold 2.5, so it is not gross.
TEST(Calibrator, GrossLimitIsNeverBelowTheThresholdWhenTheScatterIsSmall) {
  Plan plan = testPlan("ref-aacmm-3bars-3postures");
  SimulationOptions quiet;
  quiet.noise_scale = 1.0 / 3.0;
  NormalSource normal(11);
  plan.placements = Simulator(plan, quiet).simulate(plan.machine.nominal, normal).placements;
  misprobe(plan, 0, 4, 0.08 * Eigen::Vector3d(1, -1, 1).normalized());
  CalibrationOptions options;
  options.gross_threshold = 2.5;
  const Calibration c = Calibrator(plan, options).run(plan.placements);
  ASSERT_TRUE(c.summary.converged());
  const double birge = std::sqrt(c.chi2 / c.dof);  // from chi2 and dof, not birgeRatio()
  ASSERT_LT(birge, 0.9);
  EXPECT_DOUBLE_EQ(c.gross_limit, options.gross_threshold);
  const ResidualEntry& largest = c.residuals[static_cast<std::size_t>(c.largest_residual)];
  EXPECT_EQ(largest.placement, 0);
  EXPECT_EQ(largest.measurement, 4);
  // The moved reading stands between the two limits: a limit scaled down would call it gross.
  EXPECT_GT(largest.score, options.gross_threshold * birge);
  EXPECT_LT(largest.score, options.gross_threshold);
  for (const ResidualEntry& entry : c.residuals) {
    EXPECT_EQ(entry.gross, entry.score > options.gross_threshold);
  }
}

// Above 1 the Birge ratio scales the limit: readings with twice the stated noise.
TEST(Calibrator, GrossLimitScalesWithTheBirgeRatioAboveOne) {
  Plan plan = testPlan("ref-aacmm-3bars-3postures");
  SimulationOptions loud;
  loud.noise_scale = 2.0;
  NormalSource normal(12);
  plan.placements = Simulator(plan, loud).simulate(plan.machine.nominal, normal).placements;
  const Calibration c = calibratePlan(plan);
  ASSERT_TRUE(c.summary.converged());
  const double birge = std::sqrt(c.chi2 / c.dof);
  ASSERT_GT(birge, 1.3);
  EXPECT_NEAR(c.gross_limit, CalibrationOptions{}.gross_threshold * birge, 1e-9 * birge);
}

// The degrees of freedom calibrate prints, with parameter priors and with ball bars whose roll
// the readings do not see (5 of the 6 rigid directions): counted here from the plan, and
// checked against their meaning, the mean chi2 of calibrations of readings simulated from
// machines drawn from the prior (300 runs, fixed seeds; the mean of chi2 has a standard
// deviation of sqrt(2 dof / 300)).
TEST(Calibrator, DegreesOfFreedomWithPriorsAndBarsAreTheMeanChi2) {
  Plan plan = testPlan("ref-aacmm-3bars-3postures");
  Machine& machine = plan.machine;
  machine.prior_sigma = Eigen::VectorXd::Zero(machine.nominal.size());
  constexpr int kPriors = 4;
  for (int k = 0; k < kPriors; ++k) {
    const int i = machine.calibrated[static_cast<std::size_t>(k)];
    machine.prior_sigma[i] =
        machine.calibratedInfo(k).quantity == Quantity::Angle ? degToRad(0.005) : 0.02;
  }
  int rows = 0;
  for (const Placement& placement : plan.placements)
    rows += 3 * static_cast<int>(placement.measurements.size());
  constexpr int kRigidOfABar = 5;  // a bar's two balls do not show its roll
  const int expected_dof = rows + kPriors - machine.calibratedCount() -
                           kRigidOfABar * static_cast<int>(plan.placements.size());
  ASSERT_EQ(expected_dof, 22);
  Calibrator calibrator(plan);
  const Simulator simulator(plan);
  constexpr int kTrials = 300;
  double chi2 = 0.0;
  for (int t = 0; t < kTrials; ++t) {
    NormalSource normal(trialSeed(31, static_cast<std::uint64_t>(t)));
    Eigen::VectorXd truth = machine.nominal;
    for (int i = 0; i < truth.size(); ++i) truth[i] += machine.prior_sigma[i] * normal();
    const Calibration c = calibrator.run(simulator.simulate(truth, normal).placements);
    ASSERT_TRUE(c.summary.converged());
    ASSERT_EQ(c.dof, expected_dof);
    chi2 += c.chi2 / kTrials;
  }
  EXPECT_NEAR(chi2, expected_dof, 4.0 * std::sqrt(2.0 * expected_dof / kTrials));
}

// -------------------------------------------------------------------------------------- CLI

TEST(CalibrateCommand, JsonCarriesThePromisedFields) {
  const std::string plan = test_support::testDataFile("ref-2r-calibrate.json");
  const std::string machine = tempPath("machine.json");
  std::remove(machine.c_str());
  const CliRun result = runCli("calibrate " + plan + " --json --write-machine " + machine);
  ASSERT_EQ(result.status, 0);
  const nlohmann::json out = nlohmann::json::parse(result.out);
  EXPECT_TRUE(out["converged"].get<bool>());
  EXPECT_GT(out["iterations"].get<int>(), 0);
  const double chi2_per_dof = out["chi2_per_dof"].get<double>();
  for (const auto& p : out["parameters"]) {
    EXPECT_NEAR(p["u_posterior"].get<double>(), p["u"].get<double>() * std::sqrt(chi2_per_dof),
                1e-12);
    EXPECT_TRUE(p.contains("unit"));
  }
  EXPECT_EQ(out["residuals"].size(), 10u);
  EXPECT_EQ(out["flagged"], 0);
  // The written machine block is the next plan's machine: its nominal values are the estimates.
  std::ifstream in(machine);
  const nlohmann::json block = nlohmann::json::parse(in);
  const Plan original = loadPlan(plan);
  const Eigen::VectorXd reread = parseTruth(block, machine, original);
  for (int k = 0; k < 3; ++k) {
    const ParameterInfo& info = original.machine.calibratedInfo(k);
    EXPECT_NEAR(toFileUnit(info.quantity, reread[k]),
                out["parameters"][static_cast<std::size_t>(k)]["estimate"].get<double>(), 1e-12);
  }
}

// The table `calibrate` prints is its --json in the units the table names: the unit column is
// deg for an angle and mm for a length, each number the JSON's to the digits printed, the
// degrees of freedom the JSON's; and the JSON's u is the evaluator's (an independent code path)
// for the same readings at the estimate, u_posterior that times sqrt(chi2 / dof).
TEST(CalibrateCommand, PrintedTableIsTheJsonInItsUnits) {
  const std::string plan_path = test_support::testDataFile("ref-2r-calibrate.json");
  const CliRun table = runCli("calibrate " + plan_path);
  const CliRun json_run = runCli("calibrate --json " + plan_path);
  ASSERT_EQ(table.status, 0);
  ASSERT_EQ(json_run.status, 0);
  const nlohmann::json out = nlohmann::json::parse(json_run.out);
  const int dof = out["dof"].get<int>();
  EXPECT_NE(table.out.find(" on " + std::to_string(dof) + " degrees of freedom"),
            std::string::npos);
  Plan plan = loadPlan(plan_path);
  const Machine& machine = plan.machine;
  ASSERT_EQ(out["parameters"].size(), static_cast<std::size_t>(machine.calibratedCount()));
  Eigen::VectorXd estimate = machine.nominal;
  for (int k = 0; k < machine.calibratedCount(); ++k) {
    const auto& parameter = out["parameters"][static_cast<std::size_t>(k)];
    estimate[machine.calibrated[static_cast<std::size_t>(k)]] =
        fromFileUnit(machine.calibratedInfo(k).quantity, parameter["estimate"].get<double>());
  }
  plan.machine.nominal = estimate;
  const Evaluation at_estimate = evaluatePlan(plan);
  ASSERT_TRUE(at_estimate.identifiable());
  const double birge = std::sqrt(out["chi2"].get<double>() / dof);
  std::istringstream lines(table.out);
  std::string line;
  while (std::getline(lines, line) && line.rfind("parameter ", 0) != 0) {
  }
  ASSERT_FALSE(lines.eof()) << "no parameter table";
  for (int k = 0; k < machine.calibratedCount(); ++k) {
    const ParameterInfo& info = machine.calibratedInfo(k);
    const auto& parameter = out["parameters"][static_cast<std::size_t>(k)];
    ASSERT_TRUE(std::getline(lines, line));
    std::istringstream row(line);
    std::string name, unit;
    double nominal = 0.0, value = 0.0, u = 0.0, u_posterior = 0.0;
    row >> name >> nominal >> value >> u >> u_posterior >> unit;
    ASSERT_FALSE(row.fail()) << line;
    SCOPED_TRACE(line);
    EXPECT_EQ(name, info.name);
    EXPECT_EQ(unit, info.quantity == Quantity::Angle ? "deg" : "mm");
    EXPECT_EQ(parameter["unit"].get<std::string>(), unit);
    EXPECT_NEAR(nominal, parameter["nominal"].get<double>(), 1e-6);
    EXPECT_NEAR(value, parameter["estimate"].get<double>(), 1e-6);
    const double json_u = parameter["u"].get<double>();
    EXPECT_NEAR(u, json_u, 5e-3 * json_u);
    EXPECT_NEAR(u_posterior, parameter["u_posterior"].get<double>(), 5e-3 * u_posterior);
    EXPECT_NEAR(json_u, toFileUnit(info.quantity, at_estimate.covariance->u[k]), 1e-6 * json_u);
    EXPECT_NEAR(parameter["u_posterior"].get<double>(), json_u * birge, 1e-9 * json_u);
  }
}

// A URDF's parameter names differ in length (the Panda's panda_joint2.x and panda_joint2.pitch;
// a UR5e's wrist_3_link-tool0_fixed_joint.x): the name column is as wide as the longest, so each
// number column ends at the same place in every row (it shifted by each name's excess over 10).
TEST(CalibrateCommand, TableColumnsLineUpWithNamesOfAnyLength) {
  const CliRun table =
      runCli("calibrate " + test_support::testDataFile("ref-chain-panda-2placements.json"));
  ASSERT_EQ(table.status, 0);
  std::istringstream lines(table.out);
  std::string line;
  while (std::getline(lines, line) && line.rfind("parameter ", 0) != 0) {
  }
  ASSERT_FALSE(lines.eof()) << "no parameter table";
  std::set<std::size_t> name_lengths, column_ends;
  while (std::getline(lines, line) && !line.empty()) {
    name_lengths.insert(line.find(' '));
    // the end of each of the four numbers: a non-blank followed by a blank
    std::vector<std::size_t> ends;
    for (std::size_t i = line.find(' '); i + 1 < line.size(); ++i)
      if (line[i] != ' ' && line[i + 1] == ' ') ends.push_back(i);
    ASSERT_GE(ends.size(), 4u) << line;
    for (std::size_t k = 0; k < 4; ++k) column_ends.insert(ends[k] * 10 + k);
  }
  EXPECT_GT(name_lengths.size(), 1u);  // names of several lengths
  EXPECT_EQ(column_ends.size(), 4u);   // each of the 4 columns ends at one place in every row
}

TEST(CalibrateCommand, NonConvergenceExitsOneWithoutNaN) {
  const std::string plan = test_support::testDataFile("ref-2r-calibrate.json");
  const std::string machine = tempPath("unconverged-machine.json");
  std::remove(machine.c_str());
  const CliRun result =
      runCli("calibrate " + plan + " --json --max-iterations 1 --write-machine " + machine);
  EXPECT_EQ(result.status, 1);
  EXPECT_FALSE(std::ifstream(machine).good());  // an unconverged estimate is not written
  const nlohmann::json out = nlohmann::json::parse(result.out);
  EXPECT_FALSE(out["converged"].get<bool>());
  EXPECT_EQ(result.out.find("NaN"), std::string::npos);
  EXPECT_EQ(result.out.find("nan"), std::string::npos);
  const CliRun table = runCli("calibrate " + plan + " --max-iterations 1");
  EXPECT_EQ(table.status, 1);
  EXPECT_NE(table.out.find("NOT CONVERGED"), std::string::npos);
}

TEST(CalibrateCommand, BadOptionsExitTwo) {
  const std::string plan = test_support::testDataFile("ref-2r-calibrate.json");
  EXPECT_EQ(runCli("calibrate " + plan + " --max-iterations 0").status, 2);
  EXPECT_EQ(runCli("calibrate " + plan + " --flag-threshold -1").status, 2);
  EXPECT_EQ(runCli("calibrate /nonexistent/plan.json").status, 2);
}

}  // namespace calibrator_test
}  // namespace artcal
