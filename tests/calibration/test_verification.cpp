// artcal verify (models.md section 6): spreads and length errors against a direct computation,
// the predicted spread against Monte-Carlo runs of simulate -> calibrate -> verify on held-out
// readings (fixed seeds), and the real readings of the MUKCa Franka Panda (tests/data/mukca, MIT
// licence): the gross errors the calibration names, and the leave-one-out test of
// docs/panda.md, the target of issue 11: trained on every clean position but one, the held-out
// position's spread is within 30 % of the posterior prediction, and its MAE better than the
// authors' 0.349 mm from one position.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

#include "artcal/calibration/verification.hpp"
#include "artcal/internal.hpp"
#include "cli_runner.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace verification_test {

Plan serialPlan() {
  return loadPlan(test_support::planFile("aacmm-6axis-3bars.json"));
}

/// A true machine: nominal plus a few-standard-uncertainty perturbation of every calibrated
/// parameter (fixed values, not drawn).
Eigen::VectorXd perturbedTruth(const Plan& plan) {
  Eigen::VectorXd p = plan.machine.nominal;
  for (int k = 0; k < plan.machine.calibratedCount(); ++k) {
    const int i = plan.machine.calibrated[static_cast<std::size_t>(k)];
    const bool angle = plan.machine.calibratedInfo(k).quantity == Quantity::Angle;
    p[i] += (k % 2 ? 1.0 : -1.0) * (angle ? degToRad(0.01) : 0.05);
  }
  return p;
}

TEST(Verification, SpreadAndLengthErrorsMatchADirectComputation) {
  Plan plan = serialPlan();
  SimulationOptions options;
  options.noise_scale = 1.0;
  NormalSource normal(7);
  plan.placements = Simulator(plan, options).simulate(perturbedTruth(plan), normal).placements;
  const Verification v = verifyMachine(plan, plan.machine.nominal, std::nullopt);
  ASSERT_EQ(v.placements.size(), plan.placements.size());
  double sum2 = 0.0;
  int count = 0;
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    Eigen::Vector3d mean[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    int n[2] = {0, 0};
    std::vector<Eigen::Vector3d> x;
    for (const Measurement& m : plan.placements[j].measurements) {
      Eigen::VectorXd xi;
      forwardOrThrow(*plan.machine.mechanism, plan.machine.nominal, m.joints, xi);
      x.push_back(xi);
      mean[m.feature] += xi;
      ++n[m.feature];
    }
    for (int f : {0, 1}) mean[f] /= n[f];
    for (std::size_t i = 0; i < x.size(); ++i) {
      sum2 += (x[i] - mean[plan.placements[j].measurements[i].feature]).squaredNorm();
      ++count;
    }
    ASSERT_EQ(v.placements[j].length_errors.size(), 1u);
    EXPECT_NEAR(v.placements[j].length_errors[0].error, (mean[1] - mean[0]).norm() - 300.0, 1e-9);
    // The rigid fit with p fixed leaves residuals no larger than the spread explains.
    EXPECT_GT(v.placements[j].residual_rms, 0.0);
  }
  EXPECT_NEAR(v.spread_rms, std::sqrt(sum2 / count), 1e-12);
  EXPECT_GT(v.spread_rms, 0.01);  // the perturbed machine's readings do not meet at nominal
  EXPECT_FALSE(v.predicted);
}

TEST(Verification, NoiseFreeReadingsOfTheTrueMachineHaveNoSpread) {
  Plan plan = serialPlan();
  SimulationOptions options;
  options.noise_scale = 0.0;
  options.artifact_errors = false;
  NormalSource normal(3);
  const Eigen::VectorXd truth = perturbedTruth(plan);
  plan.placements = Simulator(plan, options).simulate(truth, normal).placements;
  const Verification v = verifyMachine(plan, truth, std::nullopt);
  EXPECT_LT(v.spread_rms, 1e-7);
  EXPECT_LT(v.length_error_rms, 1e-7);
  EXPECT_LT(v.residual_rms, 1e-7);
}

// The predicted spread is E|d_i|^2 of the header: over many calibrations on one simulated run
// and verifications on another, the mean observed squared spread must match it.
TEST(Verification, PredictedSpreadMatchesMonteCarlo) {
  const Plan plan = serialPlan();
  const Eigen::VectorXd truth = perturbedTruth(plan);
  const Simulator simulator(plan);
  Calibrator calibrator(plan);
  Plan held_out = plan;
  double observed2 = 0.0, predicted2 = 0.0, noise_only2 = 0.0;
  constexpr int kTrials = 200;
  for (int t = 0; t < kTrials; ++t) {
    NormalSource normal(trialSeed(11, static_cast<std::uint64_t>(t)));
    const SimulatedRun training = simulator.simulate(truth, normal);
    const Calibration calibration = calibrator.run(training.placements);
    ASSERT_TRUE(calibration.summary.converged());
    const auto u = calibration.uncertainty(plan.machine);
    ASSERT_TRUE(u);
    held_out.placements = simulator.simulate(truth, normal).placements;
    const Verification v = verifyMachine(held_out, calibration.parameters, u);
    const Verification n = verifyMachine(held_out, calibration.parameters, std::nullopt);
    observed2 += v.spread_rms * v.spread_rms / kTrials;
    predicted2 += v.predicted_spread_rms * v.predicted_spread_rms / kTrials;
    noise_only2 += n.predicted_spread_rms * n.predicted_spread_rms / kTrials;
  }
  // 200 trials of 18 readings: the mean of squares is known to a few percent.
  EXPECT_NEAR(observed2 / predicted2, 1.0, 0.08);
  EXPECT_GT(predicted2, noise_only2 * 1.05);  // the calibration's V_p is a visible part
}

SimulationOptions twiceTheStatedNoise() {
  SimulationOptions twice;
  twice.noise_scale = 2.0;
  return twice;
}

/// Calibrations on readings that scatter twice as much as the serial plan states, each verified on
/// held-out readings of the same kind: mean squares over the trials of the observed spread and
/// of its predictions, and sums over the length pairs of the observed error^2 and posterior u^2.
struct TwiceTheStatedScatter {
  static constexpr int kTrials = 200;
  Plan plan = serialPlan();
  Eigen::VectorXd truth = perturbedTruth(plan);
  Simulator simulator{plan, twiceTheStatedNoise()};
  Plan held_out = plan;
  double observed2 = 0.0, predicted2 = 0.0, posterior2 = 0.0;
  double length_observed2 = 0.0, length_posterior2 = 0.0;
  int pairs = 0;

  /// Verifies the machine of `calibration` on fresh held-out readings drawn from `normal`.
  Verification verify(const Eigen::VectorXd& p, const ParameterUncertainty& u,
                      NormalSource& normal) {
    held_out.placements = simulator.simulate(truth, normal).placements;
    const Verification v = verifyMachine(held_out, p, u);
    observed2 += v.spread_rms * v.spread_rms / kTrials;
    predicted2 += v.predicted_spread_rms * v.predicted_spread_rms / kTrials;
    posterior2 += v.predicted_spread_rms_posterior * v.predicted_spread_rms_posterior / kTrials;
    for (const PlacementVerification& placement : v.placements) {
      for (const LengthError& e : placement.length_errors) {
        length_observed2 += e.error * e.error;
        length_posterior2 += e.predicted_u_posterior * e.predicted_u_posterior;
        ++pairs;
      }
    }
    return v;
  }
};

// Readings that scatter twice as much as the plan states: the calibration's Birge ratio says so
// (about 2), and the posterior prediction (predicted times that ratio) is the spread then
// observed on held-out readings of the same kind, where the stated-noise prediction is half; the
// length errors' posterior u likewise (600 pairs, as PredictedLengthErrorUMatchesMonteCarlo).
TEST(Verification, PosteriorSpreadMatchesMonteCarloWhenTheNoiseIsUnderstated) {
  TwiceTheStatedScatter runs;
  Calibrator calibrator(runs.plan);
  for (int t = 0; t < TwiceTheStatedScatter::kTrials; ++t) {
    NormalSource normal(trialSeed(23, static_cast<std::uint64_t>(t)));
    const Calibration calibration =
        calibrator.run(runs.simulator.simulate(runs.truth, normal).placements);
    ASSERT_TRUE(calibration.summary.converged());
    const auto u = calibration.uncertainty(runs.plan.machine);
    ASSERT_TRUE(u);
    const double birge = std::sqrt(calibration.chi2 / calibration.dof);
    EXPECT_NEAR(u->birge_ratio, birge, 1e-15 * birge);
    const Verification v = runs.verify(calibration.parameters, *u, normal);
    EXPECT_DOUBLE_EQ(v.birge_ratio, u->birge_ratio);
    EXPECT_NEAR(v.predicted_spread_rms_posterior, v.predicted_spread_rms * birge, 1e-14);
  }
  EXPECT_NEAR(runs.observed2 / runs.posterior2, 1.0, 0.1);
  EXPECT_NEAR(runs.observed2 / runs.predicted2, 4.0, 0.4);
  ASSERT_EQ(runs.pairs, 600);
  EXPECT_NEAR(runs.length_observed2 / runs.length_posterior2, 1.0, 0.2);
}

// The same readings (twice the stated scatter) calibrated with `"probe": "estimate"`: the
// calibration's Birge ratio is then 1 by construction, and the held-out plan states the noise
// (import-readings' first guess, here half the true scatter). The posterior prediction is made
// with the calibration's estimated noise and is the spread observed on held-out readings; the
// stated-noise prediction falls well short of it (before, the posterior was that one times 1).
TEST(Verification, PosteriorSpreadUsesTheEstimatedProbeNoiseWhenThePlanStatesOne) {
  TwiceTheStatedScatter runs;
  Plan estimating = runs.plan;
  estimating.noise.estimate_probe = true;
  ASSERT_FALSE(runs.held_out.noise.estimate_probe);
  double estimate2 = 0.0;
  for (int t = 0; t < TwiceTheStatedScatter::kTrials; ++t) {
    NormalSource normal(trialSeed(29, static_cast<std::uint64_t>(t)));
    Plan training = estimating;
    training.placements = runs.simulator.simulate(runs.truth, normal).placements;
    const CalibrationRun run = calibrateReadings(training);
    const Calibration& calibration = run.calibration;
    ASSERT_TRUE(calibration.summary.converged());
    const auto u = calibration.uncertainty(run.decided.machine);
    ASSERT_TRUE(u);
    ASSERT_TRUE(calibration.noise_estimate);
    EXPECT_NEAR(u->birge_ratio, 1.0, 1e-2);
    estimate2 += u->probe_noise * u->probe_noise / TwiceTheStatedScatter::kTrials;
    const Verification v = runs.verify(calibration.parameters, *u, normal);
    EXPECT_DOUBLE_EQ(v.posterior_probe_noise, u->probe_noise);
  }
  // The probe's share of the scatter is twice the stated one (the encoders' too, which the
  // estimate, encoders as stated, takes into the probe's).
  EXPECT_GT(std::sqrt(estimate2), 1.8 * runs.plan.noise.probe);
  EXPECT_NEAR(runs.observed2 / runs.posterior2, 1.0, 0.1);
  EXPECT_GT(runs.observed2 / runs.predicted2, 2.0);
  ASSERT_EQ(runs.pairs, 600);
  EXPECT_NEAR(runs.length_observed2 / runs.length_posterior2, 1.0, 0.2);
}

// The rule of "worse than nominal" on hand-made figures: a larger spread is worse; a length
// error's mean |e| is worse only beyond twice the RMS of the calibrated pairs' posterior u (the
// prediction of the readings' noise alone when no posterior is known), since the nominal one can
// be small by chance (a UR5e trial: 0.343 mm calibrated, 0.215 mm nominal, posterior u 0.163 mm).
TEST(Verification, WorseThanNominalCountsALengthErrorBeyondTwiceItsPosteriorU) {
  const auto figures = [](double spread, double error, double u, double u_posterior) {
    Verification v;
    v.spread_mean = spread;
    v.spread_rms = 1.1 * spread;
    v.length_error_mean_abs = error;
    PlacementVerification placement;
    for (const double sign : {1.0, -1.0}) {
      LengthError e;
      e.error = sign * error;
      e.predicted_u = u;
      e.predicted_u_posterior = u_posterior;
      placement.length_errors.push_back(e);
    }
    v.placements.push_back(placement);
    return v;
  };
  const Verification nominal = figures(5.0, 0.215, 0.0, 0.0);
  EXPECT_TRUE(worseThanNominal(figures(0.3, 0.343, 0.08, 0.163), nominal).empty());
  EXPECT_EQ(worseThanNominal(figures(0.3, 0.343, 0.03, 0.05), nominal),
            std::vector<std::string>{"length_error_mean_abs"});  // 0.128 > 2 x 0.05
  EXPECT_EQ(worseThanNominal(figures(0.3, 0.343, 0.05, 0.0), nominal),
            std::vector<std::string>{"length_error_mean_abs"});  // no posterior: 2 x 0.05
  EXPECT_TRUE(worseThanNominal(figures(0.3, 0.343, 0.07, 0.0), nominal).empty());
  EXPECT_EQ(worseThanNominal(figures(5.2, 0.2, 0.0, 0.0), nominal),
            (std::vector<std::string>{"spread_mean", "spread_rms"}));
}

// Figures printed alike to the micrometre are not called worse (issue 44 warned "0.009 mm > 0.009
// mm"); a micrometre more is.
TEST(Verification, WorseThanNominalIgnoresFiguresThatPrintAlike) {
  const auto spreads = [](double mean, double rms) {
    Verification v;
    v.spread_mean = mean;
    v.spread_rms = rms;
    return v;
  };
  const Verification nominal = spreads(0.0081, 0.0089);                     // 0.008, 0.009 mm
  EXPECT_TRUE(worseThanNominal(spreads(0.0084, 0.0093), nominal).empty());  // 0.008, 0.009
  EXPECT_EQ(worseThanNominal(spreads(0.0084, 0.0096), nominal),             // 0.008, 0.010
            std::vector<std::string>{"spread_rms"});
}

// The pairs' u the rule reads is their RMS, the root of the mean u^2 (the expected mean square
// of the calibrated machine's length errors), not their mean: pairs of posterior u 0.03 and
// 0.09 mm have RMS sqrt((0.03^2 + 0.09^2) / 2) = 0.06708 mm (mean 0.06 mm). A calibrated mean |e|
// 0.128 mm above the nominal one is within twice the RMS (0.134 mm), one 0.138 mm above is not.
TEST(Verification, WorseThanNominalReadsTheRmsOfThePairsU) {
  const auto figures = [](double error, std::vector<double> u_posterior) {
    Verification v;
    v.spread_mean = 0.3;
    v.spread_rms = 0.33;
    v.length_error_mean_abs = error;
    PlacementVerification placement;
    for (const double u : u_posterior) {
      LengthError e;
      e.error = error;
      e.predicted_u = 0.001;  // the prior prediction, replaced by the posterior
      e.predicted_u_posterior = u;
      placement.length_errors.push_back(e);
    }
    v.placements.push_back(placement);
    return v;
  };
  const double rms = std::sqrt((0.03 * 0.03 + 0.09 * 0.09) / 2.0);
  ASSERT_NEAR(2.0 * rms, 0.13416, 1e-5);
  const Verification nominal = figures(0.1, {});
  EXPECT_TRUE(worseThanNominal(figures(0.228, {0.03, 0.09}), nominal).empty());
  EXPECT_EQ(worseThanNominal(figures(0.238, {0.03, 0.09}), nominal),
            std::vector<std::string>{"length_error_mean_abs"});
  // Over two placements alike: the RMS is over every pair of every placement.
  Verification split = figures(0.228, {0.03});
  split.placements.push_back(figures(0.228, {0.09}).placements.front());
  EXPECT_TRUE(worseThanNominal(split, nominal).empty());
}

// A machine of a calibration at a stated noise carries no estimate: the posterior stays the
// prediction times the Birge ratio, and no estimated noise is named.
TEST(Verification, StatedNoiseCalibrationKeepsTheBirgeScaledPosterior) {
  Plan plan = serialPlan();
  NormalSource normal(31);
  const Simulator simulator(plan, twiceTheStatedNoise());
  const Eigen::VectorXd truth = perturbedTruth(plan);
  const Calibration calibration =
      Calibrator(plan).run(simulator.simulate(truth, normal).placements);
  const auto u = calibration.uncertainty(plan.machine);
  ASSERT_TRUE(u);
  EXPECT_EQ(u->probe_noise, 0.0);
  plan.placements = simulator.simulate(truth, normal).placements;
  const Verification v = verifyMachine(plan, calibration.parameters, u);
  EXPECT_EQ(v.posterior_probe_noise, 0.0);
  EXPECT_NEAR(v.predicted_spread_rms_posterior, v.predicted_spread_rms * u->birge_ratio, 1e-14);
}

/// 200 trials (seeds trialSeed(seed, t)): calibrate on readings simulated from the perturbed
/// truth, simulate held-out readings with `held_out_simulator` and hand each held-out plan and
/// the calibration (with its uncertainty) to `verify`.
template <class Verify>
void calibrateThenVerify(const Plan& plan, Plan held_out, const Simulator& held_out_simulator,
                         std::uint64_t seed, Verify verify) {
  const Eigen::VectorXd truth = perturbedTruth(plan);
  const Simulator simulator(plan);
  Calibrator calibrator(plan);
  for (int t = 0; t < 200; ++t) {
    NormalSource normal(trialSeed(seed, static_cast<std::uint64_t>(t)));
    const Calibration calibration = calibrator.run(simulator.simulate(truth, normal).placements);
    ASSERT_TRUE(calibration.summary.converged());
    const auto u = calibration.uncertainty(plan.machine);
    ASSERT_TRUE(u);
    held_out.placements = held_out_simulator.simulate(truth, normal).placements;
    verify(held_out, calibration.parameters, *u);
  }
}

// The predicted u of a length error (header: the calibration's V_p through the mean Jacobians,
// the readings' own noise): over many calibrations on one simulated run and verifications on
// another, the mean squared length error must match the mean predicted u^2 (600 pairs: the
// mean of squares to about 6 %).
TEST(Verification, PredictedLengthErrorUMatchesMonteCarlo) {
  const Plan plan = serialPlan();
  double observed2 = 0.0, predicted2 = 0.0, noise_only2 = 0.0;
  int pairs = 0;
  calibrateThenVerify(
      plan, plan, Simulator(plan), 17,
      [&](const Plan& held_out, const Eigen::VectorXd& p, const ParameterUncertainty& u) {
        const Verification v = verifyMachine(held_out, p, u);
        const Verification n = verifyMachine(held_out, p, std::nullopt);
        for (std::size_t j = 0; j < v.placements.size(); ++j) {
          for (std::size_t e = 0; e < v.placements[j].length_errors.size(); ++e) {
            const LengthError& length = v.placements[j].length_errors[e];
            observed2 += length.error * length.error;
            predicted2 += length.predicted_u * length.predicted_u;
            const double alone = n.placements[j].length_errors[e].predicted_u;
            noise_only2 += alone * alone;
            ++pairs;
          }
        }
      });
  ASSERT_EQ(pairs, 600);
  EXPECT_NEAR(observed2 / predicted2, 1.0, 0.2);
  EXPECT_GT(predicted2, noise_only2 * 1.05);  // the calibration's V_p is a visible part
}

// The calibration's part of a length error's predicted u alone: held-out readings without noise
// (and a plan stating almost none), so that the length errors come from the calibration's
// parameter error only and the prediction is sqrt(dJ V_p dJ^T) along the length.
TEST(Verification, PredictedLengthErrorUOfTheCalibrationAloneMatchesMonteCarlo) {
  const Plan plan = serialPlan();
  Plan held_out = plan;
  held_out.noise.probe = 1e-9;
  held_out.noise.encoder.setZero();
  SimulationOptions exact;
  exact.noise_scale = 0.0;
  exact.artifact_errors = false;
  double observed2 = 0.0, predicted2 = 0.0;
  calibrateThenVerify(
      plan, held_out, Simulator(held_out, exact), 19,
      [&](const Plan& readings, const Eigen::VectorXd& p, const ParameterUncertainty& u) {
        for (const PlacementVerification& placement : verifyMachine(readings, p, u).placements) {
          for (const LengthError& length : placement.length_errors) {
            observed2 += length.error * length.error;
            predicted2 += length.predicted_u * length.predicted_u;
          }
        }
      });
  EXPECT_NEAR(observed2 / predicted2, 1.0, 0.2);
}

// The tables `verify` prints are its --json in mm (the unit its first line names), to the 4
// decimals printed: per feature the spreads and predictions, per pair the length error and its
// predicted u, and the summary line.
TEST(Verification, PrintedTablesAreTheJsonInMillimetres) {
  const std::string plan = test_support::planFile("aacmm-6axis-3bars.json");
  const std::string machine = ::testing::TempDir() + "/verify-table-machine.json";
  ASSERT_EQ(test_support::runCli("calibrate " + plan + " --write-machine " + machine).status, 0);
  const auto table = test_support::runCli("verify " + plan + " --machine " + machine);
  const auto json_run = test_support::runCli("verify --json " + plan + " --machine " + machine);
  ASSERT_EQ(table.status, 0);
  ASSERT_EQ(json_run.status, 0);
  const nlohmann::json v = nlohmann::json::parse(json_run.out)["verify"];
  EXPECT_NE(table.out.find("parameters held fixed (mm)"), std::string::npos);
  std::istringstream lines(table.out);
  std::string line;
  while (std::getline(lines, line) && line.rfind("placement feature", 0) != 0) {
  }
  int rows = 0;
  while (std::getline(lines, line) && !line.empty()) {
    std::istringstream row(line);
    std::size_t j = 0, f = 0;
    int postures = 0;
    double mean = 0, rms = 0, predicted = 0, posterior = 0;
    row >> j >> f >> postures >> mean >> rms >> predicted >> posterior;
    ASSERT_FALSE(row.fail()) << line;
    const nlohmann::json& feature = v["placements"][j]["features"][f];
    EXPECT_EQ(postures, feature["postures"].get<int>());
    EXPECT_NEAR(mean, feature["spread_mean"].get<double>(), 5.1e-5) << line;
    EXPECT_NEAR(rms, feature["spread_rms"].get<double>(), 5.1e-5) << line;
    EXPECT_NEAR(predicted, feature["predicted_spread_rms"].get<double>(), 5.1e-5) << line;
    EXPECT_NEAR(posterior, feature["predicted_spread_rms_posterior"].get<double>(), 5.1e-5);
    EXPECT_GT(feature["predicted_spread_rms"].get<double>(), 0.01);  // a figure to compare
    ++rows;
  }
  EXPECT_EQ(rows, 6);
  while (std::getline(lines, line) && line.rfind("placement  from", 0) != 0) {
  }
  rows = 0;
  while (std::getline(lines, line) && !line.empty()) {
    std::istringstream row(line);
    std::size_t j = 0;
    int from = 0, to = 0;
    double error = 0, predicted_u = 0;
    row >> j >> from >> to >> error >> predicted_u;
    ASSERT_FALSE(row.fail()) << line;
    const nlohmann::json& length = v["placements"][j]["length_errors"][0];
    EXPECT_EQ(from, length["from"].get<int>());
    EXPECT_EQ(to, length["to"].get<int>());
    EXPECT_NEAR(error, length["error"].get<double>(), 5.1e-5) << line;
    EXPECT_NEAR(predicted_u, length["predicted_u"].get<double>(), 5.1e-5) << line;
    EXPECT_GT(length["predicted_u"].get<double>(), 0.005);
    ++rows;
  }
  EXPECT_EQ(rows, 3);
  char summary[160];
  std::snprintf(summary, sizeof summary, "predicted rms %.4f",
                v["predicted_spread_rms"].get<double>());
  EXPECT_NE(table.out.find(summary), std::string::npos) << summary;
}

// ------------------------------------------------------------------ the MUKCa Panda readings

// On the 8 clean positions the four readings with the ball lifted 1.3-1.8 mm out of its socket
// stand at |z| 10-14; the next reading is at 4.1, below the test's 5 x Birge ratio 1.40 = 7.0.
TEST(PandaReadings, TheGrossErrorsAreTheFourBallsNotSeated) {
  const Plan plan = loadPlan(test_support::planFile("panda-8positions.json"));
  const Calibration c = calibratePlan(plan);
  ASSERT_TRUE(c.summary.converged());
  std::set<std::tuple<std::string, int>> gross;
  for (const ResidualEntry& e : c.residuals) {
    if (!e.gross) continue;
    const Measurement& m = plan.placements[static_cast<std::size_t>(e.placement)]
                               .measurements[static_cast<std::size_t>(e.measurement)];
    const auto slash = m.csv.find("panda_2/");
    ASSERT_NE(slash, std::string::npos) << m.csv;
    gross.insert({m.csv.substr(slash + 8), m.csv_row});
    EXPECT_GT(e.residual.norm(), 1.0);  // mm: a ball not seated, not scatter
  }
  const std::set<std::tuple<std::string, int>> expected = {{"front_left/hole_1.csv", 22},
                                                           {"front_left/hole_1.csv", 23},
                                                           {"front_right/hole_0.csv", 15},
                                                           {"back_left/hole_1.csv", 31}};
  EXPECT_EQ(gross, expected);
  EXPECT_NEAR(c.gross_limit, 5.0 * std::sqrt(c.chi2_per_dof), 1e-12);
}

TEST(PandaReadings, LeaveOneOutPosteriorSpreadIsWithin30PercentOfTheObserved) {
  for (const char* held_out : {"front-center", "front-left", "front-right", "mid-left", "mid-right",
                               "mid-high", "back-left", "back-right"}) {
    const Plan training =
        loadPlan(test_support::planFile(std::string("panda-all-but-") + held_out + ".json"));
    const Plan position =
        loadPlan(test_support::planFile(std::string("panda-position-") + held_out + ".json"));
    const Calibration c = calibratePlan(training);
    ASSERT_TRUE(c.summary.converged()) << held_out;
    for (const ResidualEntry& e : c.residuals) EXPECT_FALSE(e.gross) << held_out;
    const auto u = c.uncertainty(training.machine);
    ASSERT_TRUE(u) << held_out;
    EXPECT_GT(std::sqrt(c.chi2 / c.dof), 1.1) << held_out;  // the several positions misfit visibly
    const Verification v = verifyMachine(position, c.parameters, u);
    EXPECT_NEAR(v.predicted_spread_rms_posterior / v.spread_rms, 1.0, 0.3) << held_out;
    EXPECT_LT(v.spread_mean, 0.349) << held_out;  // mm, the authors' held-out MAE
  }
}

// The predicted spread of plane touches (verification.hpp: E d_i^2 = diag P Sigma P, P the part
// the refitted placement leaves; encoders, probe and flatness) against Monte-Carlo with fixed
// seeds: the planned touches of plans/planes/arm6-planes.json (point contacts on a table in
// three placements and a gauge block's two faces) simulated at the nominal machine and verified
// with it (nothing calibrated: the noise alone), the mean observed squared spread over 400 runs,
// in total and face by face; and the same for flush contacts (plans/planes/arm6-flush.json), whose
// placement is refitted on their tilt rows too (the prediction once projected the distance rows
// alone and was 7 to 17 % low per face, issue 44).
void expectTouchSpreadMatchesMonteCarlo(const std::string& plan_file) {
  SCOPED_TRACE(plan_file);
  const Plan plan = loadPlan(test_support::planFile(plan_file));
  const Eigen::VectorXd& p = plan.machine.nominal;
  const Simulator simulator(plan);
  Plan held_out = plan;
  constexpr int kTrials = 400;
  double observed2 = 0.0, predicted2 = 0.0;
  std::map<std::pair<int, int>, std::pair<double, double>> faces;  // observed2, predicted2
  for (int t = 0; t < kTrials; ++t) {
    NormalSource normal(trialSeed(44, static_cast<std::uint64_t>(t)));
    held_out.placements = simulator.simulate(p, normal).placements;
    const Verification v = verifyMachine(held_out, p, std::nullopt);
    observed2 += v.spread_rms * v.spread_rms / kTrials;
    predicted2 += v.predicted_spread_rms * v.predicted_spread_rms / kTrials;
    for (const PlacementVerification& placement : v.placements) {
      for (const FeatureSpread& f : placement.features) {
        auto& [o, e] = faces[{placement.index, f.feature}];
        o += f.spread_rms * f.spread_rms / kTrials;
        e += f.predicted_spread_rms * f.predicted_spread_rms / kTrials;
      }
    }
  }
  // 400 runs of about a hundred touches: the mean of squares to about 1 %.
  EXPECT_NEAR(observed2 / predicted2, 1.0, 0.04);
  // A face of 8 to 30 touches: to 2 to 4 % over 400 runs.
  for (const auto& [face, figures] : faces)
    EXPECT_NEAR(figures.first / figures.second, 1.0, 0.12)
        << "placement " << face.first << ", face " << face.second;
}

TEST(Verification, PlaneTouchesPredictedSpreadMatchesMonteCarlo) {
  expectTouchSpreadMatchesMonteCarlo("planes/arm6-planes.json");
}

TEST(Verification, FlushTouchesPredictedSpreadMatchesMonteCarlo) {
  expectTouchSpreadMatchesMonteCarlo("planes/arm6-flush.json");
}

}  // namespace verification_test
}  // namespace artcal
