// The real readings of the MUKCa Franka Panda (tests/data/mukca, MIT licence): the gross errors
// the calibration names, and the leave-one-out test of docs/panda.md, the target of issue 11:
// trained on every clean position but one, the held-out position's spread is within 30 % of the
// posterior prediction, and its MAE better than the authors' 0.349 mm from one position.

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <tuple>

#include "artcal/artcal.hpp"
#include "artcal/calibration/verification.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace {

using test_support::planFile;

// On the 8 clean positions the four readings with the ball lifted 1.3-1.8 mm out of its socket
// stand at |z| 10-14; the next reading is at 4.1, below the test's 5 x Birge ratio 1.40 = 7.0.
TEST(PandaReadings, TheGrossErrorsAreTheFourBallsNotSeated) {
  const Plan plan = loadPlan(planFile("panda-8positions.json"));
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
    const Plan training = loadPlan(planFile(std::string("panda-all-but-") + held_out + ".json"));
    const Plan position = loadPlan(planFile(std::string("panda-position-") + held_out + ".json"));
    const Calibration c = calibratePlan(training);
    ASSERT_TRUE(c.summary.converged()) << held_out;
    ASSERT_TRUE(c.covariance);
    for (const ResidualEntry& e : c.residuals) EXPECT_FALSE(e.gross) << held_out;
    ParameterUncertainty u;
    u.indices = training.machine.calibrated;
    u.V = c.covariance->V;
    u.birge_ratio = std::sqrt(c.chi2_per_dof);
    EXPECT_GT(u.birge_ratio, 1.1) << held_out;  // the several positions misfit visibly
    const Verification v = verifyMachine(position, c.parameters, u);
    EXPECT_NEAR(v.predicted_spread_rms_posterior / v.spread_rms, 1.0, 0.3) << held_out;
    EXPECT_LT(v.spread_mean, 0.349) << held_out;  // mm, the authors' held-out MAE
  }
}

}  // namespace
}  // namespace artcal
