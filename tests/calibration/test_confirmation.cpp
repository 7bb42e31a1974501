// Monte-Carlo confirmation (method.md section 6): the band, confirmation of the 5-bar planar
// plan, the 6-axis arm and a plan with a systematic bar-length error, the negative control
// (twice the declared noise must fail), and independence from the thread count.

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>

#include "artcal/internal.hpp"
#include "artcal/calibration/confirmation.hpp"
#include "artcal/report/calibration_report.hpp"
#include "cli_runner.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace confirmation_test {

/// The plan in plans/ when present, otherwise its copy in tests/data.
Plan planOrReference(const std::string& plan_name, const std::string& reference) {
  const std::string path = test_support::planFile(plan_name + ".json");
  if (std::filesystem::exists(path)) return loadPlan(path);
  return loadPlan(test_support::testDataFile(reference + ".json"));
}

Plan testPlan(const std::string& name) {
  return loadPlan(test_support::testDataFile(name + ".json"));
}

ConfirmationOptions options(int trials, std::uint64_t seed, double noise_scale = 1.0) {
  ConfirmationOptions o;
  o.trials = trials;
  o.seed = seed;
  o.noise_scale = noise_scale;
  o.threads = 2;
  return o;
}

void expectConfirmed(const Plan& plan, int trials, std::uint64_t seed) {
  const Confirmation c = confirmPlan(plan, options(trials, seed));
  EXPECT_TRUE(c.confirmed) << plan.name;
  EXPECT_EQ(c.converged_trials, trials);
  for (const ConfirmedParameter& p : c.parameters) {
    EXPECT_GE(p.ratio, c.band.low) << plan.name << " " << p.name;
    EXPECT_LE(p.ratio, c.band.high) << plan.name << " " << p.name;
  }
  EXPECT_NEAR(c.mean_chi2_per_dof, 1.0, 0.1) << plan.name;
}

void expectRejectedAtTwiceTheNoise(const Plan& plan, int trials, std::uint64_t seed) {
  const Confirmation c = confirmPlan(plan, options(trials, seed, 2.0));
  EXPECT_FALSE(c.confirmed) << plan.name;
  for (const ConfirmedParameter& p : c.parameters) {
    EXPECT_GT(p.ratio, c.band.high) << plan.name << " " << p.name;
    EXPECT_NEAR(p.ratio, 2.0, 0.4) << plan.name << " " << p.name;
  }
  EXPECT_NEAR(c.mean_chi2_per_dof, 4.0, 0.6) << plan.name;
}

TEST(Band, CoverageFactorIsTheNormalQuantile) {
  EXPECT_NEAR(bonferroniFactor(0.05, 1), 1.959964, 1e-5);
  EXPECT_NEAR(bonferroniFactor(0.01, 1), 2.575829, 1e-5);
  EXPECT_NEAR(bonferroniFactor(0.01, 3), 2.935199, 1e-5);  // Phi^-1(1 - 0.01 / 6)
  const Band band = confirmationBand(201, 3, 0.01, 0.05);
  EXPECT_NEAR(band.sampling, 0.05, 1e-12);
  EXPECT_NEAR(band.high - 1.0, 2.935199 * 0.05 + 0.05, 1e-5);
  EXPECT_NEAR(1.0 - band.low, band.high - 1.0, 1e-12);
}

// The statistics on small T, against values worked by hand: a sample deviation divided by T
// instead of T - 1 (sqrt(1.25) = 1.118 for 1, 2, 3, 4) would fail.
TEST(SampleStatistics, UnbiasedDeviationOnSmallSamples) {
  const std::vector<Eigen::VectorXd> samples = {
      Eigen::Vector2d(1.0, -2.0), Eigen::Vector2d(2.0, -2.0), Eigen::Vector2d(3.0, -2.0),
      Eigen::Vector2d(4.0, -2.0)};
  const SampleStatistics s = sampleStatistics(samples, 2);
  EXPECT_DOUBLE_EQ(s.mean[0], 2.5);
  EXPECT_DOUBLE_EQ(s.mean[1], -2.0);
  EXPECT_NEAR(s.deviation[0], std::sqrt(5.0 / 3.0), 1e-15);  // 1.2909944
  EXPECT_EQ(s.deviation[1], 0.0);
  // T = 2: the deviation of {a, b} is |a - b| / sqrt(2).
  const SampleStatistics two =
      sampleStatistics({Eigen::VectorXd::Constant(1, 0.5), Eigen::VectorXd::Constant(1, 1.5)}, 1);
  EXPECT_NEAR(two.deviation[0], 1.0 / std::sqrt(2.0), 1e-15);
  // T = 1 and T = 0: a mean but no spread.
  EXPECT_EQ(sampleStatistics({Eigen::VectorXd::Constant(1, 3.0)}, 1).deviation[0], 0.0);
  EXPECT_EQ(sampleStatistics({}, 3).mean.size(), 3);
}

TEST(Confirmation, ConfirmsTheFiveBarPlanarPlan) {
  expectConfirmed(planOrReference("paper-2r-5bars", "ref-2r-5bars"), 400, 1);
}

TEST(Confirmation, ConfirmsTheSixAxisArm) {
  expectConfirmed(planOrReference("aacmm-6axis-3bars", "ref-aacmm-3bars-3postures"), 200, 2);
}

TEST(Confirmation, ConfirmsAPlanWithASystematicBarLength) {
  const Plan plan = testPlan("cal-2r-5bars-ulength");
  expectConfirmed(plan, 400, 3);
  // The systematic error matters: u(l1) is well above the plan without it, and confirmed.
  const Plan without = planOrReference("paper-2r-5bars", "ref-2r-5bars");
  const Confirmation c = confirmPlan(plan, options(400, 3));
  const Confirmation d = confirmPlan(without, options(400, 3));
  EXPECT_GT(c.parameters[0].predicted_u, 1.2 * d.parameters[0].predicted_u);
}

TEST(Confirmation, TwiceTheDeclaredNoiseIsNotConfirmed) {
  expectRejectedAtTwiceTheNoise(planOrReference("paper-2r-5bars", "ref-2r-5bars"), 200, 4);
  expectRejectedAtTwiceTheNoise(planOrReference("aacmm-6axis-3bars", "ref-aacmm-3bars-3postures"),
                                100, 5);
  expectRejectedAtTwiceTheNoise(testPlan("cal-2r-5bars-ulength"), 200, 6);
}

TEST(Confirmation, SameResultForAnyThreadCount) {
  const Plan plan = planOrReference("aacmm-6axis-3bars", "ref-aacmm-3bars-3postures");
  ConfirmationOptions one = options(40, 8);
  one.threads = 1;
  ConfirmationOptions two = options(40, 8);
  two.threads = 2;
  const Confirmation a = confirmPlan(plan, one);
  const Confirmation b = confirmPlan(plan, two);
  ASSERT_EQ(a.parameters.size(), b.parameters.size());
  for (std::size_t k = 0; k < a.parameters.size(); ++k) {
    EXPECT_EQ(a.parameters[k].empirical_u, b.parameters[k].empirical_u);
    EXPECT_EQ(a.parameters[k].bias, b.parameters[k].bias);
  }
  EXPECT_EQ(a.mean_chi2_per_dof, b.mean_chi2_per_dof);
  const Confirmation c = confirmPlan(plan, options(40, 9));
  EXPECT_NE(a.parameters[0].empirical_u, c.parameters[0].empirical_u);
}

TEST(Confirmation, ProgressIsReportedForEveryTrial) {
  ConfirmationOptions o = options(30, 1);
  int calls = 0, last = 0;
  o.progress = [&](int done, int total) {
    ++calls;
    last = std::max(last, done);
    EXPECT_EQ(total, 30);
  };
  confirmPlan(testPlan("ref-2r-5bars"), o);
  EXPECT_EQ(calls, 30);
  EXPECT_EQ(last, 30);
}

TEST(Confirmation, UnidentifiablePlanHasNothingToConfirm) {
  EXPECT_THROW(confirmPlan(testPlan("ref-2r-ring-degenerate"), options(10, 1)), InputError);
  ConfirmationOptions bad = options(1, 1);
  EXPECT_THROW(confirmPlan(testPlan("ref-2r-5bars"), bad), std::invalid_argument);
}

// -------------------------------------------------------------------------------------- CLI

using test_support::CliRun;
using test_support::runCli;

TEST(ConfirmCommand, ExitStatusAndFields) {
  const std::string plan = test_support::testDataFile("ref-2r-5bars.json");
  const CliRun ok = runCli("confirm " + plan + " --trials 200 --seed 1 --json --quiet");
  ASSERT_EQ(ok.status, 0);
  const nlohmann::json out = nlohmann::json::parse(ok.out);
  EXPECT_TRUE(out["confirmed"].get<bool>());
  EXPECT_EQ(out["trials"], 200);
  EXPECT_LT(out["band"]["low"].get<double>(), 1.0);
  EXPECT_GT(out["band"]["high"].get<double>(), 1.0);
  ASSERT_EQ(out["parameters"].size(), 3u);
  for (const auto& p : out["parameters"]) {
    EXPECT_NEAR(p["ratio"].get<double>(),
                p["empirical_u"].get<double>() / p["predicted_u"].get<double>(), 1e-9);
  }
  EXPECT_EQ(out["parameters"][0]["name"], "l1");
  EXPECT_NEAR(out["parameters"][0]["predicted_u"].get<double>(), 0.009196, 1e-5);  // evaluate's u
  const CliRun bad = runCli("confirm " + plan + " --trials 200 --seed 1 --noise-scale 2 --quiet");
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.out.find("NOT CONFIRMED"), std::string::npos);
  EXPECT_NE(bad.out.find("band"), std::string::npos);
  EXPECT_EQ(runCli("confirm " + plan + " --trials 1").status, 2);
}

}  // namespace confirmation_test
}  // namespace artcal
