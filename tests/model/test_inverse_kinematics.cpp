// Inverse kinematics: round trips to 1e-9 mm, joint limits, distinct postures.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "artcal/internal.hpp"
#include "artcal/model/inverse_kinematics.hpp"
#include "artcal/planning/design_space.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace inverse_kinematics_test {

constexpr double kDeg = std::numbers::pi / 180.0;

Plan planar2rPlan(const nlohmann::json& limits) {
  const nlohmann::json doc = {{"format", "artcal-plan/1"},
                              {"machine",
                               {{"model", "planar2r"},
                                {"parameters", {{"l1", 150.0}, {"l2", 100.0}, {"dt2", 0.5}}},
                                {"joint_limits", limits}}},
                              {"noise", {{"probe", 0.005}, {"encoder", 0.001}}},
                              {"artifacts", {{"bar80", {{"type", "ball_bar"}, {"length", 80.0}}}}},
                              {"workspace", {{"grid", {1, 11}}}}};
  return parsePlan(doc, "planar2r", false);
}

// The 6-axis arm of the reference case, optionally with the joint limits given (deg).
Plan aacmmPlan(const nlohmann::json* limits = nullptr) {
  nlohmann::json doc = readJsonFile(test_support::testDataFile("ref-aacmm-3bars-3postures.json"));
  doc.erase("placements");
  if (limits) doc["machine"]["joint_limits"] = *limits;
  return parsePlan(doc, "aacmm", false);
}

Eigen::VectorXd randomJoints(const Machine& machine, std::mt19937_64& rng) {
  Eigen::VectorXd q(machine.jointCount());
  for (int i = 0; i < q.size(); ++i) {
    const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
    q[i] = lo + (hi - lo) * unitUniform(rng);
  }
  return q;
}

Eigen::VectorXd forward(const Machine& machine, const Eigen::VectorXd& q) {
  Eigen::VectorXd x;
  forwardOrThrow(*machine.mechanism, machine.nominal, q, x);
  return x;
}

TEST(Planar2rInverse, BothBranchesHitTheTarget) {
  const Plan plan = planar2rPlan({{-180, 180}, {-180, 180}});
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::VectorXd target = forward(plan.machine, randomJoints(plan.machine, rng));
    const auto solutions = planar2rInverse(plan.machine.nominal, target.head<2>());
    ASSERT_EQ(solutions.size(), 2u);
    for (const auto& q : solutions) EXPECT_LT((forward(plan.machine, q) - target).norm(), 1e-9);
    // The elbow branches: t2 + dt2 of opposite signs.
    const double dt2 = plan.machine.nominal[2];
    EXPECT_LT((solutions[0][1] + dt2) * (solutions[1][1] + dt2), 0.0);
  }
}

TEST(Planar2rInverse, OutOfReachHasNoSolution) {
  const Plan plan = planar2rPlan({{-180, 180}, {-180, 180}});
  EXPECT_TRUE(planar2rInverse(plan.machine.nominal, Eigen::Vector2d(260.0, 0.0)).empty());
  EXPECT_TRUE(planar2rInverse(plan.machine.nominal, Eigen::Vector2d(0.0, 40.0)).empty());
}

TEST(SolveInverseKinematics, Planar2rRespectsLimits) {
  // t2 limited to [0, 170]: only the positive elbow branch is allowed.
  const Plan plan = planar2rPlan({{-180, 180}, {0, 170}});
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::VectorXd target = forward(plan.machine, randomJoints(plan.machine, rng));
    const Eigen::Vector2d q0(0.0, -1.0);  // near the forbidden branch
    const auto q = solveInverseKinematics(plan.machine, plan.machine.nominal, target, q0);
    ASSERT_TRUE(q.has_value());
    EXPECT_TRUE(plan.machine.withinLimits(*q));
    EXPECT_LT((forward(plan.machine, *q) - target).norm(), 1e-9);
  }
}

TEST(SolveInverseKinematics, SerialRoundTripsFromRandomStarts) {
  const Plan plan = aacmmPlan();
  std::mt19937_64 rng(11);
  int solved = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::VectorXd target = forward(plan.machine, randomJoints(plan.machine, rng));
    Eigen::VectorXd q0 = randomJoints(plan.machine, rng);
    if (auto q = solveInverseKinematics(plan.machine, plan.machine.nominal, target, q0)) {
      ++solved;
      EXPECT_TRUE(plan.machine.withinLimits(*q));
      EXPECT_LT((forward(plan.machine, *q) - target).norm(), 1e-9);
    }
  }
  EXPECT_GE(solved, 30);  // a damped solver from a random start converges most of the time
}

TEST(SolveInverseKinematics, SerialRespectsNarrowLimits) {
  const nlohmann::json limits = {{-180, 180}, {-100, 10},  {-180, 180},
                                 {0, 150},    {-180, 180}, {-180, 180}};
  const Plan plan = aacmmPlan(&limits);
  std::mt19937_64 rng(13);
  int solved = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const Eigen::VectorXd target = forward(plan.machine, randomJoints(plan.machine, rng));
    std::mt19937_64 posture_rng(trial);
    for (const auto& q :
         diversePostures(plan.machine, plan.machine.nominal, target, 2, posture_rng)) {
      ++solved;
      EXPECT_TRUE(plan.machine.withinLimits(q));
      EXPECT_LT((forward(plan.machine, q) - target).norm(), 1e-9);
    }
  }
  EXPECT_GE(solved, 30);
}

// Limits of +-360 deg (a UR's) hold two equivalents of every angle: the solver returns the one
// nearest its start, e.g. 54 deg rather than -306 deg (it wrapped into [lo, lo + 360) before).
// The expected posture is the start moved a few degrees: every joint of the solution is within
// 180 deg of the start (no other equivalent is nearer), and the minimum-norm steps of the damped
// solver keep it within 30 deg of it.
TEST(SolveInverseKinematics, FullTurnJointsReturnTheEquivalentNearestTheStart) {
  const nlohmann::json limits = {{-360, 360}, {-360, 360}, {-360, 360},
                                 {-360, 360}, {-360, 360}, {-360, 360}};
  const Plan plan = aacmmPlan(&limits);
  std::mt19937_64 rng(19);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd start(6), moved(6);
    for (int i = 0; i < 6; ++i) {
      start[i] = (-170.0 + 340.0 * unitUniform(rng)) * kDeg;
      moved[i] = start[i] + (-5.0 + 10.0 * unitUniform(rng)) * kDeg;
    }
    const Eigen::VectorXd target = forward(plan.machine, moved);
    const auto q = solveInverseKinematics(plan.machine, plan.machine.nominal, target, start);
    ASSERT_TRUE(q.has_value()) << trial;
    EXPECT_LT((forward(plan.machine, *q) - target).norm(), 1e-9);
    for (int i = 0; i < 6; ++i) {
      EXPECT_LE(std::abs((*q)[i] - start[i]), 180.0 * kDeg) << "joint " << i + 1;
      EXPECT_LE(std::abs((*q)[i] - start[i]), 30.0 * kDeg) << "joint " << i + 1;
    }
  }
  // The case: a first joint started at 54 deg stays near 54 deg, not -306 deg.
  Eigen::VectorXd start(6);
  start << 54.0, 30.0, -60.0, 40.0, 70.0, 52.0;
  start *= kDeg;
  Eigen::VectorXd moved = start;
  moved[0] += 2.0 * kDeg;
  const auto q = solveInverseKinematics(plan.machine, plan.machine.nominal,
                                        forward(plan.machine, moved), start);
  ASSERT_TRUE(q.has_value());
  EXPECT_GT((*q)[0], 0.0);
  EXPECT_LT(std::abs((*q)[0] - 56.0 * kDeg), 5.0 * kDeg);
  EXPECT_LT(std::abs((*q)[5] - 52.0 * kDeg), 5.0 * kDeg);
}

TEST(DiversePostures, SerialPosturesAreDistinct) {
  const Plan plan = aacmmPlan();
  std::mt19937_64 rng(17);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::VectorXd target = forward(plan.machine, randomJoints(plan.machine, rng));
    std::mt19937_64 posture_rng(100 + trial);
    const auto postures =
        diversePostures(plan.machine, plan.machine.nominal, target, 3, posture_rng);
    ASSERT_EQ(postures.size(), 3u);
    for (std::size_t a = 0; a < postures.size(); ++a) {
      EXPECT_LT((forward(plan.machine, postures[a]) - target).norm(), 1e-9);
      for (std::size_t b = a + 1; b < postures.size(); ++b) {
        // Genuinely different: at least 20 degrees apart in joint space.
        EXPECT_GT((postures[a] - postures[b]).norm(), 20 * kDeg);
      }
    }
  }
}

TEST(DiversePostures, Planar2rGivesBothBranches) {
  const Plan plan = planar2rPlan({{-180, 180}, {-180, 180}});
  std::mt19937_64 rng(19);
  const Eigen::Vector2d target(120.0, 90.0);
  const auto postures = diversePostures(plan.machine, plan.machine.nominal, target, 2, rng);
  ASSERT_EQ(postures.size(), 2u);
  EXPECT_GT((postures[0] - postures[1]).norm(), 10 * kDeg);
  for (const auto& q : postures) EXPECT_LT((forward(plan.machine, q) - target).norm(), 1e-9);
}

TEST(ApplyJointLimits, WrapsFullTurnsAndClampsOthers) {
  const Plan plan = planar2rPlan({{-180, 180}, {-90, 90}});
  Eigen::VectorXd q(2);
  q << 270 * kDeg, 120 * kDeg;
  applyJointLimits(plan.machine, q);
  EXPECT_NEAR(q[0], -90 * kDeg, 1e-12);
  EXPECT_NEAR(q[1], 90 * kDeg, 1e-12);
}

}  // namespace inverse_kinematics_test
}  // namespace artcal
