// Simulation (method.md section 6): the portable Gaussian source, exact readings, the noise it
// adds, the artifact's systematic error, the TRUTH file, and the simulate command.

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "artcal/internal.hpp"
#include "artcal/calibration/simulation.hpp"
#include "artcal/io/truth_io.hpp"
#include "cli_runner.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace simulation_test {

Plan testPlan(const std::string& name) {
  return loadPlan(test_support::testDataFile(name + ".json"));
}

std::string dataPath(const std::string& name) {
  return test_support::testDataFile(name + ".json");
}

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "/artcal-simulation-" + name;
}

struct CommandResult {
  int status = -1;
  std::string err;
};

// stderr through a pipe, not a shared file: ctest runs these tests in parallel.
CommandResult runCli(const std::string& arguments) {
  const test_support::CliRun run = test_support::runCli(arguments, test_support::Stderr::Only);
  return {run.status, run.out};
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void writeFile(const std::string& path, const std::string& content) {
  std::ofstream(path) << content;
}

// ------------------------------------------------------------------------------- random source

TEST(NormalSource, IsDeterministicPerSeed) {
  NormalSource a(42), b(42), c(43);
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    const double x = a();
    EXPECT_EQ(x, b());
    differs = differs || x != c();
  }
  EXPECT_TRUE(differs);
}

TEST(NormalSource, HasStandardNormalMoments) {
  NormalSource normal(7);
  const int n = 200000;
  double sum = 0.0, sum2 = 0.0, sum4 = 0.0;
  int beyond_two = 0;
  for (int i = 0; i < n; ++i) {
    const double x = normal();
    sum += x;
    sum2 += x * x;
    sum4 += x * x * x * x;
    beyond_two += std::abs(x) > 2.0 ? 1 : 0;
  }
  EXPECT_NEAR(sum / n, 0.0, 4.0 / std::sqrt(n));
  EXPECT_NEAR(sum2 / n, 1.0, 4.0 * std::sqrt(2.0 / n));
  EXPECT_NEAR(sum4 / n, 3.0, 4.0 * std::sqrt(96.0 / n));
  // P(|x| > 2) = 0.0455: a wrong shape (e.g. uniform) would miss it.
  EXPECT_NEAR(static_cast<double>(beyond_two) / n, 0.0455, 4.0 * std::sqrt(0.0455 / n));
}

TEST(NormalSource, TrialSeedsAreDistinct) {
  EXPECT_NE(trialSeed(1, 0), trialSeed(1, 1));
  EXPECT_NE(trialSeed(1, 0), trialSeed(2, 0));
  EXPECT_EQ(trialSeed(5, 9), trialSeed(5, 9));
}

// ------------------------------------------------------------------------------------ readings

TEST(Simulator, NoiseFreeAtNominalReproducesThePlannedReadings) {
  for (const char* name : {"ref-2r-5bars", "ref-aacmm-3bars-3postures"}) {
    const Plan plan = testPlan(name);
    SimulationOptions options;
    options.noise_scale = 0.0;
    NormalSource normal(1);
    const SimulatedRun run = Simulator(plan, options).simulate(plan.machine.nominal, normal);
    ASSERT_EQ(run.placements.size(), plan.placements.size());
    // The planned readings are only as consistent as the fitted nominal pose: compare points.
    const std::vector<RigidTransform> poses =
        fitPlacements(plan, plan.placements, plan.machine.nominal);
    Eigen::VectorXd planned, simulated;
    for (std::size_t j = 0; j < plan.placements.size(); ++j) {
      for (std::size_t i = 0; i < plan.placements[j].measurements.size(); ++i) {
        forwardOrThrow(*plan.machine.mechanism, plan.machine.nominal,
                       plan.placements[j].measurements[i].joints, planned);
        forwardOrThrow(*plan.machine.mechanism, plan.machine.nominal,
                       run.placements[j].measurements[i].joints, simulated);
        const Artifact& artifact =
            plan.artifacts[static_cast<std::size_t>(plan.placements[j].artifact)];
        const int feature = plan.placements[j].measurements[i].feature;
        EXPECT_NEAR((poses[j].apply(simulated) - artifact.features.col(feature)).norm(), 0.0, 1e-8)
            << name;
        EXPECT_LT((simulated - planned).norm(), 0.01) << name;  // same posture, same ball
      }
    }
  }
}

TEST(Simulator, NoiseFreeReadingsPutTheTrueMachineOnTheFeatures) {
  const Plan plan = testPlan("ref-aacmm-3bars-3postures");
  Eigen::VectorXd truth = plan.machine.nominal;
  for (int k = 0; k < plan.machine.calibratedCount(); ++k) {
    truth[plan.machine.calibrated[static_cast<std::size_t>(k)]] += (k % 2 ? 0.05 : -0.0005);
  }
  SimulationOptions options;
  options.noise_scale = 0.0;
  NormalSource normal(1);
  const Simulator simulator(plan, options);
  const SimulatedRun run = simulator.simulate(truth, normal);
  Eigen::VectorXd x;
  for (std::size_t j = 0; j < run.placements.size(); ++j) {
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(run.placements[j].artifact)];
    for (const Measurement& m : run.placements[j].measurements) {
      forwardOrThrow(*plan.machine.mechanism, truth, m.joints, x);
      EXPECT_NEAR((simulator.nominalPoses()[j].apply(x) - artifact.features.col(m.feature)).norm(),
                  0.0, 1e-8);
    }
  }
}

// The probed point f(p_true, q_read) scatters about the feature with covariance
// s_p^2 I + J_q Sigma_q J_q^T (method.md section 2).
TEST(Simulator, ReadingNoiseHasTheDeclaredCovariance) {
  const Plan plan = testPlan("ref-2r-5bars");
  const Simulator simulator(plan);
  const int draws = 4000;
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  Eigen::VectorXd x;
  Eigen::MatrixXd J_x_q;
  const Measurement& planned = plan.placements[2].measurements[1];
  const Eigen::VectorXd target =
      simulator.nominalPoses()[2].inverse().apply(plan.artifacts[0].features.col(planned.feature));
  for (int s = 0; s < draws; ++s) {
    NormalSource normal(trialSeed(3, static_cast<std::uint64_t>(s)));
    const SimulatedRun run = simulator.simulate(plan.machine.nominal, normal);
    forwardOrThrow(*plan.machine.mechanism, plan.machine.nominal,
                   run.placements[2].measurements[1].joints, x);
    scatter += (x - target) * (x - target).transpose();
  }
  scatter /= draws;
  forwardOrThrow(*plan.machine.mechanism, plan.machine.nominal, planned.joints, x, nullptr, &J_x_q);
  Eigen::Matrix2d expected =
      J_x_q * plan.noise.encoder.array().square().matrix().asDiagonal() * J_x_q.transpose();
  expected.diagonal().array() += plan.noise.probe * plan.noise.probe;
  const double tolerance = 4.0 * std::sqrt(2.0 / draws);
  EXPECT_NEAR(scatter.trace() / expected.trace(), 1.0, tolerance);
  EXPECT_NEAR(scatter(0, 0) / expected(0, 0), 1.0, tolerance);
  EXPECT_NEAR(scatter(1, 1) / expected(1, 1), 1.0, tolerance);
}

// One draw per physical artifact: the same length error in every placement of the bar.
TEST(Simulator, ArtifactErrorIsTheSameInEveryPlacement) {
  Plan plan = testPlan("cal-2r-5bars-ulength");
  plan.noise.probe = 0.0;
  plan.noise.encoder.setZero();
  Eigen::VectorXd x0, x1;
  double sum2 = 0.0;
  const int draws = 400;
  for (int s = 0; s < draws; ++s) {
    NormalSource normal(static_cast<std::uint64_t>(100 + s));
    const SimulatedRun run = Simulator(plan).simulate(plan.machine.nominal, normal);
    ASSERT_EQ(run.systematic.size(), 1);
    sum2 += run.systematic[0] * run.systematic[0];
    for (const Placement& placement : run.placements) {
      forwardOrThrow(*plan.machine.mechanism, plan.machine.nominal,
                     placement.measurements[0].joints, x0);
      forwardOrThrow(*plan.machine.mechanism, plan.machine.nominal,
                     placement.measurements[1].joints, x1);
      EXPECT_NEAR((x1 - x0).norm(), 80.0 + run.systematic[0], 1e-8);
    }
  }
  EXPECT_NEAR(std::sqrt(sum2 / draws), 0.004, 0.004 * 4.0 / std::sqrt(2.0 * draws));
}

TEST(Simulator, UnreachablePointIsARunErrorNamingTheReading) {
  const Plan plan = testPlan("ref-2r-5bars");
  Eigen::VectorXd truth = plan.machine.nominal;
  truth[0] = 50.0;  // l1 = 50 mm: the far balls are out of reach
  NormalSource normal(1);
  try {
    Simulator(plan).simulate(truth, normal);
    FAIL() << "expected a RunError";
  } catch (const RunError& e) {
    EXPECT_EQ(e.pointer().rfind("/placements/", 0), 0u) << e.pointer();
    EXPECT_NE(std::string(e.what()).find("out of its reach"), std::string::npos) << e.what();
  }
}

// A reading planned 0.5 deg inside the elbow's limit of 170 deg: a true dt2 of -1 deg needs the
// elbow at 170.5 deg (the elbow limited to [0, 170] deg, so that the other branch is no way out).
// The error names the reading and joint 2 with the reading it would need.
TEST(Simulator, ReadingBeyondAJointLimitNamesTheJoint) {
  Plan plan = testPlan("ref-2r-5bars");
  plan.machine.joint_limits[1] = {0.0, degToRad(170.0)};
  const Eigen::Vector2d q(degToRad(10.0), degToRad(169.5));
  Eigen::VectorXd x;
  forwardOrThrow(*plan.machine.mechanism, plan.machine.nominal, q, x);
  const Eigen::Vector2d across = Eigen::Vector2d(-x[1], x[0]).normalized();
  const Eigen::Vector2d x1 = x.head<2>() + 80.0 * across;
  Placement placement = plan.placements[0];
  placement.pose.reset();
  placement.measurements = {{0, q}};
  const auto far = planar2rInverse(plan.machine.nominal, x1);
  ASSERT_FALSE(far.empty());
  Eigen::VectorXd q1 = far[0];
  applyJointLimits(plan.machine, q1);
  placement.measurements.push_back({1, q1});
  plan.placements = {placement};
  Eigen::VectorXd truth = plan.machine.nominal;
  truth[2] = degToRad(-1.0);
  NormalSource normal(1);
  SimulationOptions quiet;
  quiet.noise_scale = 0.0;
  try {
    Simulator(plan, quiet).simulate(truth, normal);
    FAIL() << "expected a RunError";
  } catch (const RunError& e) {
    EXPECT_EQ(e.pointer(), "/placements/0/measurements/0");
    EXPECT_NE(std::string(e.what()).find("joint 2 would have to read 170.5"), std::string::npos)
        << e.what();
  }
}

// ----------------------------------------------------------------------------------- TRUTH file

TEST(Truth, NamedParametersOverTheNominalOnes) {
  const Plan plan = testPlan("ref-2r-5bars");
  const Eigen::VectorXd p = parseTruth(
      nlohmann::json::parse(R"({"parameters": {"l1": 150.02, "dt2": 0.004}})"), "t.json", plan);
  EXPECT_DOUBLE_EQ(p[0], 150.02);
  EXPECT_DOUBLE_EQ(p[1], 100.0);
  EXPECT_DOUBLE_EQ(p[2], degToRad(0.004));
}

TEST(Truth, AcceptsAMachineBlockAsWritten) {
  const Plan plan = testPlan("ref-aacmm-3bars-3postures");
  Eigen::VectorXd truth = plan.machine.nominal;
  truth[5] += 0.3;
  truth[7] += degToRad(0.01);
  const nlohmann::json block = machineToJson(plan.machine, truth);
  const Eigen::VectorXd bare = parseTruth(block, "m.json", plan);
  EXPECT_NEAR((bare - truth).norm(), 0.0, 1e-12);
  const nlohmann::json wrapped = {{"machine", block}, {"parameters", {{"probe.x", 151.0}}}};
  const Eigen::VectorXd both = parseTruth(wrapped, "m.json", plan);
  EXPECT_DOUBLE_EQ(both[plan.machine.mechanism->parameterIndex("probe.x")], 151.0);
  EXPECT_DOUBLE_EQ(both[5], truth[5]);
}

void expectTruthError(const Plan& plan, const std::string& text, const std::string& pointer) {
  try {
    parseTruth(nlohmann::json::parse(text), "t.json", plan);
    FAIL() << "expected an InputError for " << text;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "t.json");
    EXPECT_EQ(e.pointer(), pointer) << e.what();
  }
}

TEST(Truth, FaultsNameTheirPlace) {
  const Plan plan = testPlan("ref-2r-5bars");
  expectTruthError(plan, R"({"parameters": {"l3": 1.0}})", "/parameters/l3");
  expectTruthError(plan, R"({"parameters": {"l1": "long"}})", "/parameters/l1");
  expectTruthError(plan, R"({"parameters": {"l1": 150}, "extra": 1})", "/extra");
  expectTruthError(plan, R"({"model": "planar2r", "parameters": {"l1": -1, "l2": 100}})",
                   "/parameters/l1");
  expectTruthError(plan, R"({"machine": {"model": "planar2r", "parameters": {"l1": 150}}})",
                   "/machine/parameters/l2");
  const Plan arm = testPlan("ref-aacmm-3bars-3postures");
  expectTruthError(arm, R"({"model": "planar2r", "parameters": {"l1": 150, "l2": 100}})", "/model");
  expectTruthError(plan, R"([1, 2])", "/");
  expectTruthError(plan, R"({})", "/");
}

// ------------------------------------------------------------------------------------------ CLI

TEST(SimulateCommand, WritesACompletePlanDeterministicPerSeed) {
  const std::string truth = tempPath("truth.json");
  writeFile(truth, R"({"parameters": {"l1": 150.02, "l2": 99.985, "dt2": 0.004}})");
  const std::string a = tempPath("a.json"), b = tempPath("b.json"), c = tempPath("c.json");
  const std::string plan = dataPath("ref-2r-5bars");
  ASSERT_EQ(runCli("simulate " + plan + " --truth " + truth + " --seed 9 -o " + a).status, 0);
  ASSERT_EQ(runCli("simulate " + plan + " --truth " + truth + " --seed 9 -o " + b).status, 0);
  ASSERT_EQ(runCli("simulate " + plan + " --truth " + truth + " --seed 10 -o " + c).status, 0);
  EXPECT_EQ(readFile(a), readFile(b));
  EXPECT_NE(readFile(a), readFile(c));
  const Plan simulated = loadPlan(a);  // a plan calibrate can read
  EXPECT_TRUE(simulated.warnings.empty());
  ASSERT_EQ(simulated.placements.size(), 5u);
  const nlohmann::json document = nlohmann::json::parse(readFile(a));
  EXPECT_EQ(document["simulation"]["seed"], 9);
  EXPECT_DOUBLE_EQ(document["simulation"]["parameters"]["l1"].get<double>(), 150.02);
  EXPECT_EQ(runCli("calibrate " + a).status, 0);
}

TEST(SimulateCommand, BadTruthExitsTwoWithoutOutput) {
  const std::string truth = tempPath("bad-truth.json");
  writeFile(truth, R"({"parameters": {"l9": 1.0}})");
  const std::string out = tempPath("never.json");
  std::remove(out.c_str());
  const CommandResult result =
      runCli("simulate " + dataPath("ref-2r-5bars") + " --truth " + truth + " -o " + out);
  EXPECT_EQ(result.status, 2);
  EXPECT_NE(result.err.find(truth + ": /parameters/l9:"), std::string::npos) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1);
  EXPECT_FALSE(std::ifstream(out).good());
}

}  // namespace simulation_test
}  // namespace artcal
