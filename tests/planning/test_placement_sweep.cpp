// "How many placements?" (planning/placement_sweep.hpp): the optimizer for every count of a
// small spec with a short budget. The curve is monotone (a count never does worse than the one
// before it), each count's design has that many placements and its value is the plan's worst
// tip uncertainty as evaluatePlan computes it, and the smallest count reaching a target is named.

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "artcal/estimation/evaluator.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/planning/placement_sweep.hpp"

namespace artcal {
namespace placement_sweep_test {

// The seed's arm and bar (docs/method.md section 8), the reach profile at t1 = 0 as workspace.
Plan seedSpec() {
  const nlohmann::json doc = {
      {"format", "artcal-plan/1"},
      {"name", "sweep-test"},
      {"machine",
       {{"model", "planar2r"},
        {"parameters", {{"l1", 150.0}, {"l2", 100.0}, {"dt2", 0.0}}},
        {"calibrate", {"l1", "l2", "dt2"}},
        {"joint_limits", {{-180, 180}, {-170, 170}}}}},
      {"noise", {{"probe", 0.005}, {"encoder", 0.001}}},
      {"artifacts", {{"bar80", {{"type", "ball_bar"}, {"length", 80.0}}}}},
      {"workspace", {{"configurations", {{0, 24}, {0, 60}, {0, 100}, {0, 140}, {0, 169}}}}},
      {"design",
       {{"artifact", "bar80"},
        {"placements", 3},
        {"region", {{"reach", {60, 240}}}},
        {"seed", 2},
        {"starts", 2},
        {"time_limit", 30}}}};
  return parsePlan(doc, "sweep-test.json", /*require_placements=*/false);
}

TEST(PlacementSweep, MonotoneCurveWithEachCountsDesignAndTheSmallestCountReachingTheTarget) {
  const Plan spec = seedSpec();
  SweepOptions options;
  options.first = 2;  // too few for 3 parameters (counting condition): no design
  options.last = 6;
  options.optimizer = OptimizerOptions::fromDesign(*spec.design);
  options.optimizer.pool_size = 30;
  options.optimizer.refine_evaluations = 150;
  options.optimizer.threads = 1;
  options.target = 0.0105;  // mm
  const PlacementSweep sweep = sweepPlacements(spec, options);
  ASSERT_EQ(sweep.points.size(), 5u);
  EXPECT_TRUE(sweep.points[0].designed.empty());
  EXPECT_FALSE(std::isfinite(sweep.points[0].value));
  EXPECT_NE(sweep.points[0].message.find("counting condition"), std::string::npos);
  std::optional<std::size_t> first_reaching;
  for (std::size_t i = 1; i < sweep.points.size(); ++i) {
    const SweepPoint& point = sweep.points[i];
    SCOPED_TRACE(point.placements);
    ASSERT_EQ(static_cast<int>(point.designed.size()), point.placements);
    if (i > 1) {
      EXPECT_LE(point.value, sweep.points[i - 1].value);
    }
    EXPECT_LE(point.value, point.fresh);
    Plan plan = spec;
    plan.placements = point.designed;
    const Evaluation evaluation = evaluatePlan(plan);
    ASSERT_TRUE(evaluation.tip.has_value());
    EXPECT_NEAR(point.value, evaluation.tip->worst.total, 1e-9 * point.value);
    if (!first_reaching && point.value <= *options.target) first_reaching = i;
  }
  EXPECT_EQ(sweep.first_reaching, first_reaching);
}

TEST(PlacementSweep, CountRanges) {
  EXPECT_EQ(parseCountRange("3..20"), std::make_pair(3, 20));
  EXPECT_EQ(parseCountRange("7"), std::make_pair(7, 7));
  EXPECT_FALSE(parseCountRange("0..3"));
  EXPECT_FALSE(parseCountRange("5..3"));
  EXPECT_FALSE(parseCountRange("3..x"));
  EXPECT_FALSE(parseCountRange("3...5"));
  EXPECT_FALSE(parseCountRange(""));
}

}  // namespace placement_sweep_test
}  // namespace artcal
