// The optimizer's active set (optimizer.hpp, docs/optimize.md "How it searches", step 5): the
// worst-tip criterion over a few configurations is a lower bound of G over the workspace, equal
// to G for every design it was activated on, and each search decision is confirmed on the whole
// workspace (the seed's arm: 96 configurations along the reach). G here is recomputed apart from
// the criterion: TipEvaluator over the plan's workspace with V_p from evaluatePlan of the same
// design.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "artcal/artcal.hpp"
#include "artcal/planning/design_space.hpp"
#include "artcal/planning/optimizer.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace active_set_test {

/// G of `plan` with `placements`, by evaluatePlan (no optimizer code).
double worstTipOf(Plan plan, const std::vector<Placement>& placements) {
  plan.placements = placements;
  const Evaluation evaluation = evaluatePlan(plan);
  return evaluation.tip ? evaluation.tip->worst.total : INFINITY;
}

TEST(ActiveSet, BoundsGFromBelowAndEqualsItWhereActivated) {
  const Plan spec = loadPlan(test_support::planFile("seed-2r-5bars.spec.json"),
                             /*require_placements=*/false);
  DesignSpace space(spec);
  DesignCriterion criterion(spec, Criterion::WorstTip);
  std::mt19937_64 rng(7);
  auto randomDesign = [&](std::vector<Placement>& placements) {
    placements.clear();
    Eigen::MatrixXd total = Eigen::MatrixXd::Zero(criterion.globalSize(), criterion.globalSize());
    while (placements.size() < 5) {
      if (auto drawn = space.randomPlacement(rng, 1000)) {
        placements.push_back(drawn->second);
        total += criterion.contribution(drawn->second);
      }
    }
    return total;
  };
  std::vector<Placement> first, other;
  const Eigen::MatrixXd I_first = randomDesign(first);
  const double G_first = worstTipOf(spec, first);
  ASSERT_TRUE(std::isfinite(G_first));
  // Empty set: the full criterion.
  EXPECT_NEAR(criterion.activeValue(I_first), G_first, 1e-9 * G_first);
  EXPECT_EQ(criterion.activeSize(), 0);
  // Activated: G itself, from a handful of configurations.
  EXPECT_NEAR(criterion.activate(I_first), G_first, 1e-9 * G_first);
  EXPECT_GT(criterion.activeSize(), 0);
  EXPECT_LE(criterion.activeSize(), 4);
  EXPECT_NEAR(criterion.activeValue(I_first), G_first, 1e-9 * G_first);
  // Other designs: never above G; activating each makes the bound exact for it too, and the
  // set grows only where the bound was short.
  int short_bounds = 0;
  for (int k = 0; k < 20; ++k) {
    const Eigen::MatrixXd I = randomDesign(other);
    const double G = worstTipOf(spec, other);
    const double bound = criterion.activeValue(I);
    EXPECT_LE(bound, G * (1.0 + 1e-9));
    const int before = criterion.activeSize();
    EXPECT_NEAR(criterion.activate(I), G, 1e-9 * G);
    EXPECT_NEAR(criterion.activeValue(I), G, 1e-9 * G);
    if (bound < G * (1.0 - 1e-9)) {
      ++short_bounds;
      EXPECT_GT(criterion.activeSize(), before);
    } else {
      EXPECT_EQ(criterion.activeSize(), before);
    }
  }
  criterion.resetActive();
  EXPECT_EQ(criterion.activeSize(), 0);
  RecordProperty("short_bounds", short_bounds);
}

}  // namespace active_set_test
}  // namespace artcal
