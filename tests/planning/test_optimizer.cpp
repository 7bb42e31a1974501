// The planner: design space, counting refusal, the search (reachable readings inside the region,
// never worse than its start, deterministic per seed whatever the thread count) and the
// `artcal optimize` command (plan written, evaluate reproduces `predicted`, refusals exit 2).

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>

#include "artcal/internal.hpp"
#include "artcal/model/inverse_kinematics.hpp"
#include "artcal/planning/design_space.hpp"
#include "artcal/planning/optimizer.hpp"
#include "cli_runner.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace optimizer_test {

// The seed's arm and bar (method.md section 8) with a design block; the workspace sweeps the
// reach profile at t1 = 0.
nlohmann::json seedSpec(int placements, const nlohmann::json& region) {
  return {{"format", "artcal-plan/1"},
          {"name", "seed-2r-test"},
          {"machine",
           {{"model", "planar2r"},
            {"parameters", {{"l1", 150.0}, {"l2", 100.0}, {"dt2", 0.0}}},
            {"calibrate", {"l1", "l2", "dt2"}},
            {"joint_limits", {{-180, 180}, {-180, 180}}}}},
          {"noise", {{"probe", 0.005}, {"encoder", 0.001}}},
          {"artifacts", {{"bar80", {{"type", "ball_bar"}, {"length", 80.0}, {"u_length", 0.0}}}}},
          {"workspace", {{"configurations", {{0, 24}, {0, 60}, {0, 100}, {0, 140}, {0, 169}}}}},
          {"design",
           {{"artifact", "bar80"},
            {"placements", placements},
            {"postures", 1},
            {"region", region},
            {"seed", 3},
            {"starts", 4},
            {"time_limit", 60}}}};
}

nlohmann::json aacmmSpec(int placements) {
  nlohmann::json doc = readJsonFile(test_support::testDataFile("ref-aacmm-3bars-3postures.json"));
  doc.erase("placements");
  doc["workspace"] = {{"samples", 64}, {"seed", 2}};
  doc["design"] = {{"artifact", "bar"}, {"placements", placements},
                   {"postures", 3},     {"region", {{"reach", {400, 1100}}}},
                   {"seed", 1},         {"starts", 2}};
  return doc;
}

OptimizerOptions smallEffort(const Plan& plan, int threads) {
  OptimizerOptions options = OptimizerOptions::fromDesign(*plan.design);
  options.pool_size = 40;
  options.refine_evaluations = 300;
  options.threads = threads;
  return options;
}

// Every reading hits its feature at the placement's pose, within the limits and the region.
void expectFeasible(const Plan& plan, const std::vector<Placement>& placements) {
  const Region& region = plan.design->region;
  for (const Placement& p : placements) {
    ASSERT_TRUE(p.pose.has_value());
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(p.artifact)];
    const RigidTransform to_machine =
        (plan.machine.dimension() == 2
             ? placePlanar(p.pose->center.head<2>(), p.pose->angle)
             : placeSpatial(p.pose->center.head<3>(), p.pose->direction, p.pose->roll))
            .inverse();
    for (const Measurement& m : p.measurements) {
      const Eigen::VectorXd feature = to_machine.apply(artifact.features.col(m.feature));
      EXPECT_TRUE(plan.machine.withinLimits(m.joints));
      Eigen::VectorXd x;  // through the reading's own stylus (a CMM's second stylus)
      ASSERT_EQ(plan.machine.mechanism->forwardStylus(m.stylus, plan.machine.nominal, m.joints, x),
                ForwardStatus::Ok);
      EXPECT_LT((x - feature).norm(), 1e-9);
      EXPECT_TRUE(region.contains(feature)) << feature.transpose();
    }
  }
}

TEST(DesignSpace, PlanarBarFeaturesFollowThePose) {
  const Plan plan = parsePlan(seedSpec(5, {{"reach", {55, 245}}}), "spec", false);
  const DesignSpace space(plan);
  ASSERT_EQ(space.poseSize(), 3);
  const Eigen::Vector3d v(100.0, 50.0, std::numbers::pi / 6);
  const Eigen::MatrixXd x = space.featurePositions(v);
  EXPECT_NEAR((x.col(0) - Eigen::Vector2d(100.0, 50.0)).norm(), 0.0, 1e-12);
  const Eigen::Vector2d second =
      Eigen::Vector2d(100.0, 50.0) + 80.0 * Eigen::Vector2d(std::sqrt(3.0) / 2, 0.5);
  EXPECT_NEAR((x.col(1) - second).norm(), 0.0, 1e-12);
  EXPECT_EQ(space.regionViolation(v), 0.0);
  // Balls at 275 and 355 mm, 30 and 110 mm beyond the outer reach: the violation adds them.
  const Eigen::Vector3d outside(275.0, 0.0, 0.0);
  EXPECT_NEAR(space.regionViolation(outside), 30.0 + 110.0, 1e-9);
}

TEST(DesignSpace, RandomPlacementsAreFeasible) {
  const Plan plan = parsePlan(aacmmSpec(2), "spec", false);
  const DesignSpace space(plan);
  std::mt19937_64 rng(4);
  std::vector<Placement> placements;
  for (int i = 0; i < 3; ++i) {
    const auto drawn = space.randomPlacement(rng, 200);
    ASSERT_TRUE(drawn.has_value());
    EXPECT_EQ(drawn->second.measurements.size(), 2u * 3u);  // 2 balls x 3 postures
    placements.push_back(drawn->second);
  }
  expectFeasible(plan, placements);
}

TEST(Optimizer, RefusesACountThatCannotBeIdentifiable) {
  // Planar bar: 2 x 2 - 3 = 1 equation per placement, 3 parameters: 2 placements cannot do.
  const Plan plan = parsePlan(seedSpec(2, {{"reach", {55, 245}}}), "spec.json", false);
  try {
    optimizePlan(plan, smallEffort(plan, 1));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "/design/placements");
    EXPECT_NE(std::string(e.what()).find("at least 3 placements"), std::string::npos) << e.what();
  }
}

TEST(Optimizer, RefusesAnUnreachableRegion) {
  const Plan plan = parsePlan(seedSpec(5, {{"reach", {300, 400}}}), "spec.json", false);
  try {
    optimizePlan(plan, smallEffort(plan, 1));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "/design/region");
  }
}

TEST(Optimizer, PlanarResultIsFeasibleAndNeverWorseThanItsStart) {
  const Plan plan = parsePlan(seedSpec(5, {{"reach", {55, 245}}}), "spec", false);
  const OptimizerSummary summary = optimizePlan(plan, smallEffort(plan, 2));
  ASSERT_EQ(summary.placements.size(), 5u);
  expectFeasible(plan, summary.placements);
  for (const StartResult& s : summary.starts) {
    ASSERT_TRUE(s.done);
    EXPECT_LE(s.exchanged, s.initial);
    EXPECT_LE(s.refined, s.exchanged);
  }
  // The value is the evaluator's worst-case tip uncertainty of the written plan.
  Plan result = plan;
  result.placements = summary.placements;
  const Evaluation evaluation = evaluatePlan(result);
  ASSERT_TRUE(evaluation.tip.has_value());
  EXPECT_NEAR(summary.value, evaluation.tip->worst.total, 1e-12);
  // Far better than a typical random layout (median about 18 um, method.md section 8 scale).
  EXPECT_LT(summary.value, 0.0125);
}

TEST(Optimizer, SameSeedSamePlanWhateverTheThreadCount) {
  const Plan plan = parsePlan(seedSpec(4, {{"reach", {55, 245}}}), "spec", false);
  const OptimizerSummary one = optimizePlan(plan, smallEffort(plan, 1));
  const OptimizerSummary two = optimizePlan(plan, smallEffort(plan, 2));
  ASSERT_EQ(one.placements.size(), two.placements.size());
  EXPECT_EQ(one.value, two.value);
  EXPECT_EQ(one.best_start, two.best_start);
  for (std::size_t j = 0; j < one.placements.size(); ++j) {
    ASSERT_EQ(one.placements[j].measurements.size(), two.placements[j].measurements.size());
    for (std::size_t i = 0; i < one.placements[j].measurements.size(); ++i) {
      EXPECT_EQ(one.placements[j].measurements[i].joints, two.placements[j].measurements[i].joints);
    }
  }
  // Another seed, another search.
  OptimizerOptions other = smallEffort(plan, 2);
  other.seed = 99;
  EXPECT_NE(optimizePlan(plan, other).value, one.value);
}

// The polish (restarts and kicks of the best designs' refinement) keeps every guarantee of a
// start: feasible, never worse than without it, the same plan whatever the thread count.
TEST(Optimizer, PolishNeverWorseAndTheSamePlanWhateverTheThreads) {
  const Plan plan = parsePlan(seedSpec(4, {{"reach", {55, 245}}}), "spec", false);
  const OptimizerSummary plain = optimizePlan(plan, smallEffort(plan, 2));
  auto polished = [&](int threads) {
    OptimizerOptions options = smallEffort(plan, threads);
    options.polish = 3;
    options.kicks = 4;
    return optimizePlan(plan, options);
  };
  const OptimizerSummary one = polished(1);
  const OptimizerSummary two = polished(2);
  expectFeasible(plan, two.placements);
  EXPECT_LE(two.value, plain.value);
  EXPECT_EQ(one.value, two.value);
  EXPECT_EQ(one.best_start, two.best_start);
  ASSERT_EQ(one.placements.size(), two.placements.size());
  for (std::size_t j = 0; j < one.placements.size(); ++j) {
    for (std::size_t i = 0; i < one.placements[j].measurements.size(); ++i)
      EXPECT_EQ(one.placements[j].measurements[i].joints, two.placements[j].measurements[i].joints);
  }
  for (std::size_t s = 0; s < two.starts.size(); ++s)
    EXPECT_LE(two.starts[s].refined, plain.starts[s].refined) << s;
  // The value is the evaluator's G of the polished plan.
  Plan result = plan;
  result.placements = two.placements;
  EXPECT_NEAR(two.value, evaluatePlan(result).tip->worst.total, 1e-12);
}

TEST(Optimizer, TimeLimitStopsTheSearchWithAUsableResult) {
  const Plan plan = parsePlan(seedSpec(5, {{"reach", {55, 245}}}), "spec", false);
  OptimizerOptions options = smallEffort(plan, 2);
  options.starts = 64;
  options.time_limit = 1e-9;
  const OptimizerSummary summary = optimizePlan(plan, options);
  EXPECT_EQ(summary.termination, OptimizerSummary::Termination::TimeLimit);
  EXPECT_EQ(summary.startsDone(), 1);
  ASSERT_EQ(summary.best_start, 0);
  EXPECT_LE(summary.value, summary.starts[0].initial);
  expectFeasible(plan, summary.placements);
}

TEST(Optimizer, TwoPosturesUseBothElbowBranches) {
  // 2 balls x 2 postures x 2 coordinates - 3 = 5 equations per bar: one bar suffices by count,
  // two are asked.
  nlohmann::json doc = seedSpec(2, {{"reach", {55, 245}}});
  doc["design"]["postures"] = 2;
  const Plan plan = parsePlan(doc, "spec", false);
  const OptimizerSummary summary = optimizePlan(plan, smallEffort(plan, 2));
  ASSERT_EQ(summary.placements.size(), 2u);
  expectFeasible(plan, summary.placements);
  for (const Placement& p : summary.placements) {
    ASSERT_EQ(p.measurements.size(), 4u);
    for (int feature = 0; feature < 2; ++feature) {
      std::vector<double> elbows;
      for (const Measurement& m : p.measurements) {
        if (m.feature == feature) elbows.push_back(m.joints[1]);
      }
      ASSERT_EQ(elbows.size(), 2u);
      EXPECT_LT(elbows[0] * elbows[1], 0.0);  // opposite branches (dt2 = 0)
    }
  }
}

TEST(Optimizer, FixedPlacementsCountAndStay) {
  // One bar given in the spec: with it, 2 more bars meet the count that 2 alone cannot.
  nlohmann::json doc = seedSpec(2, {{"reach", {55, 245}}});
  const Plan bare = parsePlan(doc, "spec", false);
  std::mt19937_64 rng(21);
  const Placement fixed = DesignSpace(bare).randomPlacement(rng, 1000)->second;
  Plan plan = bare;
  plan.placements.push_back(fixed);
  const OptimizerSummary summary = optimizePlan(plan, smallEffort(plan, 2));
  ASSERT_EQ(summary.placements.size(), 2u);  // the designed ones only
  Plan result = plan;
  for (const Placement& p : summary.placements) result.placements.push_back(p);
  const Evaluation evaluation = evaluatePlan(result);
  ASSERT_TRUE(evaluation.identifiable());
  EXPECT_NEAR(summary.value, evaluation.tip->worst.total, 1e-12);
}

// The polish starts from the value of the whole plan, fixed placements included: the two
// designed bars alone cannot identify p (a polish that started from them alone would start from
// +infinity and accept whatever its first round finds). With polish and kicks the written plan's
// G, evaluated independently, is the value reported, no start ends worse than without the polish,
// and the result does not depend on the threads.
TEST(Optimizer, PolishStartsFromTheFixedPlacements) {
  const Plan bare = parsePlan(seedSpec(2, {{"reach", {55, 245}}}), "spec", false);
  std::mt19937_64 rng(21);
  Plan plan = bare;
  plan.placements.push_back(DesignSpace(bare).randomPlacement(rng, 1000)->second);
  const OptimizerSummary plain = optimizePlan(plan, smallEffort(plan, 2));
  OptimizerOptions options = smallEffort(plan, 1);
  options.polish = 4;
  options.kicks = 6;
  const OptimizerSummary one = optimizePlan(plan, options);
  options.threads = 2;
  const OptimizerSummary two = optimizePlan(plan, options);
  ASSERT_EQ(two.placements.size(), 2u);
  EXPECT_EQ(one.value, two.value);
  EXPECT_LE(two.value, plain.value);
  int polished = 0;
  for (std::size_t s = 0; s < two.starts.size(); ++s) {
    EXPECT_LE(two.starts[s].refined, plain.starts[s].refined) << s;
    // The polish starts from the refined design with the fixed placement's information: the
    // same value the unpolished run ended that start with (same seed, same designs).
    if (two.starts[s].polished_from == 0.0) continue;
    ++polished;
    EXPECT_NEAR(two.starts[s].polished_from, plain.starts[s].refined,
                1e-9 * plain.starts[s].refined)
        << s;
  }
  EXPECT_GT(polished, 0);
  Plan result = plan;
  for (const Placement& p : two.placements) result.placements.push_back(p);
  const Evaluation evaluation = evaluatePlan(result);
  ASSERT_TRUE(evaluation.identifiable());
  EXPECT_NEAR(two.value, evaluation.tip->worst.total, 1e-12);
}

TEST(Optimizer, BoxRegionIsRespected) {
  const nlohmann::json region = {{"reach", {55, 245}}, {"box", {{0, 0}, {250, 250}}}};
  const Plan plan = parsePlan(seedSpec(5, region), "spec", false);
  const OptimizerSummary summary = optimizePlan(plan, smallEffort(plan, 2));
  expectFeasible(plan, summary.placements);
}

TEST(Optimizer, OtherCriteriaImproveOnTheirStart) {
  for (const char* criterion : {"mean-tip", "D", "A", "E"}) {
    nlohmann::json doc = seedSpec(5, {{"reach", {55, 245}}});
    doc["design"]["criterion"] = criterion;
    const Plan plan = parsePlan(doc, "spec", false);
    const OptimizerSummary summary = optimizePlan(plan, smallEffort(plan, 2));
    const StartResult& best = summary.starts[static_cast<std::size_t>(summary.best_start)];
    EXPECT_TRUE(std::isfinite(summary.value)) << criterion;
    EXPECT_LT(summary.value, best.initial) << criterion;
    expectFeasible(plan, summary.placements);
  }
}

TEST(DesignCriterion, AdditiveTermsGiveTheEvaluatorsInformation) {
  // The exchange sums placements' terms: the sum must equal the evaluator's information.
  const Plan spec = parsePlan(aacmmSpec(2), "spec", false);
  const DesignSpace space(spec);
  std::mt19937_64 rng(8);
  Plan plan = spec;
  DesignCriterion criterion(spec, Criterion::WorstTip);
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(criterion.globalSize(), criterion.globalSize());
  for (int i = 0; i < 3; ++i) {
    plan.placements.push_back(space.randomPlacement(rng, 200)->second);
    sum += criterion.contribution(plan.placements.back());
  }
  const Evaluation evaluation = evaluatePlan(plan);
  EXPECT_LT((sum - evaluation.information).norm(), 1e-9 * evaluation.information.norm());
  ASSERT_TRUE(evaluation.tip.has_value());
  PlanEvaluator evaluator(plan);
  EXPECT_NEAR(criterion.value(sum), evaluator.tip(plan.placements)->worst.total, 1e-12);
}

TEST(Optimizer, SerialArmResultIsFeasible) {
  const Plan plan = parsePlan(aacmmSpec(2), "spec", false);
  OptimizerOptions options = smallEffort(plan, 2);
  options.pool_size = 8;
  options.refine_evaluations = 60;
  const OptimizerSummary summary = optimizePlan(plan, options);
  ASSERT_EQ(summary.placements.size(), 2u);
  expectFeasible(plan, summary.placements);
  const StartResult& best = summary.starts[static_cast<std::size_t>(summary.best_start)];
  EXPECT_LE(summary.value, best.initial);
}

// ---------------------------------------------------------------------------------------------
// The optimized plans in plans/ (written by `artcal optimize plans/NAME.spec.json`)

TEST(OptimizedPlans, ReadingsFeasibleAndPredictedReproduced) {
  for (const char* name :
       {"seed-2r-5bars", "seed-2r-20bars", "aacmm-4bars-3postures", "cmm-plate-2styli",
        "hexapod-10bars", "machine-tool-trunnion-8probings", "machine-tool-head-table-8probings"}) {
    SCOPED_TRACE(name);
    const std::string path = test_support::planFile(std::string(name) + "-optimized.json");
    const nlohmann::json document = readJsonFile(path);
    const Plan plan = parsePlan(document, path);
    ASSERT_TRUE(plan.design.has_value());
    EXPECT_EQ(static_cast<int>(plan.placements.size()), plan.design->placements);
    expectFeasible(plan, plan.placements);
    const Evaluation evaluation = evaluatePlan(plan);
    ASSERT_TRUE(evaluation.identifiable());
    const nlohmann::json& predicted = document.at("predicted");
    EXPECT_NEAR(evaluation.tip->worst.total, predicted["tip"]["worst"]["total"].get<double>(),
                1e-9 * evaluation.tip->worst.total);
    EXPECT_LE(predicted["optimization"]["value"].get<double>(),
              predicted["optimization"]["best_start"]["initial"].get<double>());
    // The spec is the plan without placements and predictions.
    nlohmann::json spec = document;
    spec.erase("placements");
    spec.erase("predicted");
    EXPECT_EQ(spec, readJsonFile(test_support::planFile(std::string(name) + ".spec.json")));
  }
  // Issue 3's target for the seed's arm, 5 bars: 11.6 um or less.
  const Plan five = loadPlan(test_support::planFile("seed-2r-5bars-optimized.json"));
  EXPECT_LE(evaluatePlan(five).tip->worst.total, 0.0116);
}

// ---------------------------------------------------------------------------------------------
// The command line

using test_support::CliRun;

CliRun runCli(const std::string& arguments) {
  return test_support::runCli(arguments, test_support::Stderr::Merge);
}

class OptimizeCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("artcal-optimize-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& name, const nlohmann::json& doc) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << doc.dump(1);
    return path;
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::filesystem::path dir_;
};

constexpr const char* kSmall = " --pool 40 --evaluations 300 --quiet";

TEST_F(OptimizeCli, WritesAPlanThatEvaluateReproduces) {
  const std::string spec = write("spec.json", seedSpec(5, {{"reach", {55, 245}}}));
  const CliRun run = runCli("optimize " + spec + " -o " + path("plan.json") + kSmall + " --json");
  ASSERT_EQ(run.status, 0) << run.out;
  const nlohmann::json plan = readJsonFile(path("plan.json"));
  EXPECT_EQ(plan["placements"].size(), 5u);
  EXPECT_TRUE(plan.contains("design"));
  EXPECT_EQ(plan["workspace"], seedSpec(5, {{"reach", {55, 245}}})["workspace"]);
  const nlohmann::json& predicted = plan["predicted"];
  EXPECT_LE(predicted["optimization"]["value"].get<double>(),
            predicted["optimization"]["best_start"]["initial"].get<double>());
  const CliRun evaluate = runCli("evaluate --json " + path("plan.json"));
  ASSERT_EQ(evaluate.status, 0) << evaluate.out;
  const nlohmann::json ev = nlohmann::json::parse(evaluate.out);
  EXPECT_NEAR(ev["tip"]["worst"]["total"].get<double>(),
              predicted["tip"]["worst"]["total"].get<double>(), 1e-12);
  EXPECT_NEAR(ev["tip"]["mean"].get<double>(), predicted["tip"]["mean"].get<double>(), 1e-12);
  ASSERT_EQ(ev["parameters"].size(), predicted["parameters"].size());
  for (std::size_t i = 0; i < ev["parameters"].size(); ++i) {
    EXPECT_NEAR(ev["parameters"][i]["u"].get<double>(),
                predicted["parameters"][i]["u"].get<double>(), 1e-12);
  }
  EXPECT_EQ(ev["identifiable"], predicted["identifiable"]);
  EXPECT_NEAR(predicted["optimization"]["value"].get<double>(),
              ev["tip"]["worst"]["total"].get<double>(), 1e-12);
}

TEST_F(OptimizeCli, NoProgressLineWhenStderrIsNotATerminal) {
  // stderr is merged into the captured pipe: without --quiet it must still hold nothing.
  const std::string spec = write("spec.json", seedSpec(4, {{"reach", {55, 245}}}));
  const CliRun run = runCli("optimize " + spec + " -o " + path("plan.json") +
                            " --pool 40 --evaluations 100 --json");
  ASSERT_EQ(run.status, 0) << run.out;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  EXPECT_EQ(out["plan"], path("plan.json"));
  EXPECT_EQ(out["optimization"]["starts_done"], 4);
}

// design.pool and design.target_tip of a spec are used (a sweep names the smallest count reaching
// the target; --pool and --target-tip would override them).
TEST_F(OptimizeCli, SpecsPoolAndTargetTipAreUsed) {
  nlohmann::json doc = seedSpec(3, {{"reach", {55, 245}}});
  doc["design"]["pool"] = 40;
  doc["design"]["target_tip"] = 0.5;  // mm: every count reaches it
  const std::string spec = write("spec.json", doc);
  CliRun run =
      runCli("optimize " + spec + " -o " + path("plan.json") + " --evaluations 100 --quiet --json");
  ASSERT_EQ(run.status, 0) << run.out;
  EXPECT_EQ(nlohmann::json::parse(run.out)["optimization"]["pool"], 40);
  run = runCli("optimize " + spec + " --placements 3..4 -o " + path("sweep") +
               " --evaluations 100 --quiet");
  ASSERT_EQ(run.status, 0) << run.out;
  const nlohmann::json summary = readJsonFile(path("sweep/summary.json"));
  EXPECT_DOUBLE_EQ(summary["target_tip"].get<double>(), 0.5);
  EXPECT_EQ(summary["smallest_reaching"], 3);
}

TEST_F(OptimizeCli, SameSeedSameFileWhateverTheThreads) {
  const std::string spec = write("spec.json", seedSpec(4, {{"reach", {55, 245}}}));
  ASSERT_EQ(runCli("optimize " + spec + " -o " + path("a.json") + kSmall + " --threads 1").status,
            0);
  ASSERT_EQ(runCli("optimize " + spec + " -o " + path("b.json") + kSmall + " --threads 2").status,
            0);
  EXPECT_EQ(readJsonFile(path("a.json")), readJsonFile(path("b.json")));
}

TEST_F(OptimizeCli, RefusalsExitWithStatus2AndOneLine) {
  const std::string too_few = write("few.json", seedSpec(2, {{"reach", {55, 245}}}));
  CliRun run = runCli("optimize " + too_few + " -o " + path("x.json") + kSmall);
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.out.find("few.json: /design/placements: cannot be identifiable"), std::string::npos)
      << run.out;
  const std::string far = write("far.json", seedSpec(5, {{"reach", {300, 400}}}));
  run = runCli("optimize " + far + " -o " + path("x.json") + kSmall);
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.out.find("far.json: /design/region: no placement"), std::string::npos) << run.out;
  nlohmann::json no_design = seedSpec(5, {{"reach", {55, 245}}});
  no_design.erase("design");
  run = runCli("optimize " + write("none.json", no_design) + " -o " + path("x.json") + kSmall);
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.out.find("none.json: /design: missing"), std::string::npos) << run.out;
  EXPECT_FALSE(std::filesystem::exists(path("x.json")));
}

// j1.theta turns the whole arm about the base z axis: every placement's rigid motion absorbs
// it, so no design identifies it (docs/method.md section 5). optimize says which to fix, exit 1.
TEST_F(OptimizeCli, AnUnidentifiableSetNamesTheParametersToFix) {
  nlohmann::json doc = aacmmSpec(2);
  doc["machine"]["calibrate"].insert(doc["machine"]["calibrate"].begin(), "j1.theta");
  const CliRun run =
      runCli("optimize " + write("theta.json", doc) + " -o " + path("x.json") + kSmall);
  EXPECT_EQ(run.status, 1);
  EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1) << run.out;
  EXPECT_NE(run.out.find("theta.json: /machine/calibrate: "), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("fix (keep at nominal): j1.theta (not observed, or absorbed by the "
                         "placements' rigid motions); calibrate the 21 others: j1.a "),
            std::string::npos)
      << run.out;
  EXPECT_FALSE(std::filesystem::exists(path("x.json")));
}

// "identifiable" in a spec is resolved on the design space, not kept whole. The independent
// argument (standard DH, probe (150, 0, 0) on x6, alpha6 = a6 = d6 = 0): j1.theta and j1.d are
// a rotation about and a translation along the base z axis (rigid motions); the tip is
// Rz(q6 + theta6) [(a6, 0, d6) + Rx(alpha6) probe], where Rx(alpha6) leaves a probe on x6 in
// place (alpha6 unobserved), probe.x moves it as a6 does, probe.z as d6, probe.y as theta6
// (150 mm lever): in the model's order j6's parameters come first and the probe's are dropped.
TEST_F(OptimizeCli, IdentifiableInASpecIsResolvedOnItsDesigns) {
  nlohmann::json doc = aacmmSpec(2);
  doc["machine"]["calibrate"] = "identifiable";
  const CliRun run =
      runCli("optimize " + write("ident.json", doc) + " -o " + path("p.json") + kSmall);
  ASSERT_EQ(run.status, 0) << run.out;
  EXPECT_NE(run.out.find("calibrate \"identifiable\" resolved on "), std::string::npos) << run.out;
  const nlohmann::json plan = readJsonFile(path("p.json"));
  const nlohmann::json dropped = {"j1.theta", "j1.d", "j6.alpha", "probe.x", "probe.y", "probe.z"};
  EXPECT_EQ(plan["predicted"]["calibrate_dropped"], dropped);
  EXPECT_EQ(plan["predicted"]["calibrate_resolved"].size(), 21u);
  EXPECT_EQ(plan["machine"]["calibrate"], "identifiable");
  // Read again, the plan resolves "identifiable" on its own placements to the same set.
  const CliRun check = runCli("check --json " + path("p.json"));
  ASSERT_EQ(check.status, 0) << check.out;
  const nlohmann::json checked = nlohmann::json::parse(check.out);
  EXPECT_EQ(checked["calibrate_resolved"], plan["predicted"]["calibrate_resolved"]);
  EXPECT_EQ(checked["calibrate_dropped"], dropped);
}

// D, A and E of a known V (calibrated l1, l2: both lengths, no scaling; no systematic error):
// V = [[4, 1], [1, 9]] um^2 has det 35 um^4 and eigenvalues (13 +- sqrt(29)) / 2 um^2, so
// D = det^(1/4), A = sqrt(trace / 2), E = sqrt(largest eigenvalue), all in mm.
TEST(DesignCriterion, DAndAAndEOfAKnownCovariance) {
  nlohmann::json doc = seedSpec(5, {{"reach", {55, 245}}});
  doc["machine"]["calibrate"] = {"l1", "l2"};
  const Plan plan = parsePlan(doc, "spec", false);
  Eigen::Matrix2d V;
  V << 4e-6, 1e-6, 1e-6, 9e-6;
  const Eigen::MatrixXd information = V.inverse();
  DesignCriterion d(plan, Criterion::D), a(plan, Criterion::A), e(plan, Criterion::E);
  ASSERT_EQ(d.globalSize(), 2);
  EXPECT_NEAR(d.value(information), std::pow(35e-12, 0.25), 1e-12);
  EXPECT_NEAR(a.value(information), std::sqrt(13e-6 / 2), 1e-12);
  EXPECT_NEAR(e.value(information), std::sqrt((13.0 + std::sqrt(29.0)) / 2 * 1e-6), 1e-12);
}

// A bar whose length is known to 4 um (u_length > 0): the criterion's V_p must be the
// evaluator's, whose prior on the length error is eliminated in normal_matrix.cpp (method.md
// section 3). Without the prior (or with it dropped from the optimizer's copy) the bar's scale
// is free and the criterion differs.
TEST(DesignCriterion, KeepsThePriorOfASystematicBarLength) {
  nlohmann::json doc = seedSpec(5, {{"reach", {55, 245}}});
  doc["machine"]["calibrate"] = {"l1", "l2"};
  doc["artifacts"]["bar80"]["u_length"] = 0.004;
  Plan plan = parsePlan(doc, "spec", false);
  DesignSpace space(plan);
  std::mt19937_64 rng(11);
  DesignCriterion a(plan, Criterion::A);
  ASSERT_EQ(a.globalSize(), 3);  // l1, l2 and the bar's length error
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(3, 3);
  for (int j = 0; j < 5; ++j) {
    auto placed = space.randomPlacement(rng, 1000);
    ASSERT_TRUE(placed);
    information += a.contribution(placed->second);
    plan.placements.push_back(placed->second);
  }
  const Evaluation ev = evaluatePlan(plan);
  ASSERT_TRUE(ev.covariance);
  const double expected = std::sqrt(ev.covariance->V.trace() / 2);
  EXPECT_NEAR(a.value(information), expected, 1e-9 * expected);
}

}  // namespace optimizer_test
}  // namespace artcal
