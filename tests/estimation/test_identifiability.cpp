// Identifiability (method.md section 5): the counting condition, and the two known rank traps it
// cannot see: the ring layout (deficiency 2) and a standard-DH serial arm with all 4n + 3
// parameters calibrated (deficiency 6).

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <numeric>
#include <random>

#include "artcal/artcal.hpp"
#include "plan_builders.hpp"

namespace artcal {
namespace identifiability_test {

using testing::aacmmPlan;
using testing::loadTestPlan;
using testing::randomPlanarBars;
using testing::randomSpatialBars;
using testing::seedPlanar2RPlan;

Identifiability analyse(const Plan& plan) {
  return analyseIdentifiability(plan, plan.placements,
                                planInformation(plan, plan.placements, plan.machine.nominal));
}

bool startsWith(const std::string& s, const std::string& prefix) {
  return s.rfind(prefix, 0) == 0;
}

TEST(Counting, SeedExamples) {
  Plan plan = seedPlanar2RPlan();
  plan.placements = randomPlanarBars(plan, 5, 1);
  const CountingCondition count = countingCondition(plan, plan.placements);
  EXPECT_EQ(count.N_p, 3);
  EXPECT_EQ(count.N_b, 20);
  EXPECT_EQ(count.N_r, 15);
  EXPECT_TRUE(count.satisfied);
  EXPECT_EQ(count.minimum_alike, 3);  // m >= 3 / (2 * 1 * 2 - 3)
  // 6-axis arm, 21 parameters, each ball in 3 postures: m >= 21 / (2 * 3 * 3 - 5) = 2.
  Plan arm = loadTestPlan("ref-aacmm-3bars-3postures");
  const CountingCondition six = countingCondition(arm, arm.placements);
  EXPECT_EQ(six.N_p, 21);
  EXPECT_EQ(six.N_b, 54);
  EXPECT_EQ(six.N_r, 15);
  EXPECT_EQ(six.minimum_alike, 2);
  // Two bars of the 2R arm are too few.
  plan.placements.resize(2);
  EXPECT_FALSE(countingCondition(plan, plan.placements).satisfied);
  EXPECT_FALSE(analyse(plan).identifiable());
}

TEST(RankTrap, RingLayoutSatisfiesTheCountButLosesRankTwo) {
  const Plan plan = loadTestPlan("ref-2r-ring-degenerate");
  const Identifiability id = analyse(plan);
  EXPECT_TRUE(id.counting.satisfied);
  EXPECT_EQ(id.deficiency, 2);
  EXPECT_EQ(id.rank, 1);
  EXPECT_FALSE(id.identifiable());
  EXPECT_EQ(id.unidentifiable.size(), 2u);
  EXPECT_FALSE(std::isfinite(id.condition_number));
  EXPECT_FALSE(evaluatePlan(plan).identifiable());
}

TEST(RankTrap, RandomBarsOfTheSeedArmAreIdentifiable) {
  Plan plan = seedPlanar2RPlan();
  plan.placements = randomPlanarBars(plan, 5, 2);
  const Identifiability id = analyse(plan);
  EXPECT_EQ(id.deficiency, 0);
  EXPECT_EQ(id.rank, 3);
  EXPECT_TRUE(std::isfinite(id.condition_number));
  EXPECT_TRUE(id.unidentifiable.empty());
}

// The 6-axis arm with every one of its 4n + 3 = 27 parameters calibrated, 8 bars with each ball
// read in 3 postures (count satisfied many times over).
Plan fullArmPlan(const Eigen::Vector3d& probe = Eigen::Vector3d(150.0, 0.0, 0.0)) {
  Plan plan = aacmmPlan();
  plan.machine.nominal.tail(3) = probe;
  plan.placements = randomSpatialBars(plan, 8, 3, 31);
  plan.machine.calibrated.clear();
  for (int i = 0; i < plan.machine.mechanism->parameterCount(); ++i) {
    plan.machine.calibrated.push_back(i);
  }
  return plan;
}

// With the probe on the last joint's x axis (the reference arm) j6.alpha moves nothing at all
// and is reported alone; with the probe off that axis it trades against the probe offset.
void expectDeficiencySix(const Eigen::Vector3d& probe, bool alpha_alone) {
  const Plan plan = fullArmPlan(probe);
  ASSERT_EQ(plan.machine.calibratedCount(), 27);
  const Identifiability id = analyse(plan);
  EXPECT_TRUE(id.counting.satisfied);
  EXPECT_EQ(id.deficiency, 6);
  EXPECT_EQ(id.rank, 21);
  ASSERT_EQ(id.unidentifiable.size(), 6u);
  // j1.theta and j1.d move with the base frame, which the r_j absorb: each alone.
  int alone_theta = 0, alone_d = 0, alone_alpha = 0;
  for (const Combination& c : id.unidentifiable) {
    ASSERT_FALSE(c.names.empty());
    if (c.names == std::vector<std::string>{"j1.theta"}) {
      ++alone_theta;
    } else if (c.names == std::vector<std::string>{"j1.d"}) {
      ++alone_d;
    } else if (c.names == std::vector<std::string>{"j6.alpha"}) {
      ++alone_alpha;
    } else {
      // Every other combination trades the last joint against the probe offset.
      for (const std::string& name : c.names) {
        EXPECT_TRUE(startsWith(name, "j6.") || startsWith(name, "probe.")) << name;
      }
      EXPECT_GE(c.names.size(), 2u);
      EXPECT_TRUE(startsWith(c.names.front(), "j6."));
    }
    const double largest =
        *std::max_element(c.coefficients.begin(), c.coefficients.end(),
                          [](double a, double b) { return std::abs(a) < std::abs(b); });
    EXPECT_NEAR(std::abs(largest), 1.0, 1e-12);
  }
  EXPECT_EQ(alone_theta, 1);
  EXPECT_EQ(alone_d, 1);
  EXPECT_EQ(alone_alpha, alpha_alone ? 1 : 0);
}

TEST(RankTrap, SerialArmWithAllParametersHasDeficiencySix) {
  expectDeficiencySix(Eigen::Vector3d(150.0, 0.0, 0.0), true);
  expectDeficiencySix(Eigen::Vector3d(150.0, 12.0, -25.0), false);
}

// Without j1.theta, j1.d and the last joint's four parameters: N(p) = 4n - 3 = 21, full rank.
TEST(RankTrap, SerialArmWithoutTheSixIsIdentifiable) {
  Plan plan = fullArmPlan();
  const Mechanism& arm = *plan.machine.mechanism;
  plan.machine.calibrated.clear();
  for (int i = 0; i < arm.parameterCount(); ++i) {
    const std::string& name = arm.parameters()[static_cast<std::size_t>(i)].name;
    if (name == "j1.theta" || name == "j1.d" || startsWith(name, "j6.")) continue;
    plan.machine.calibrated.push_back(i);
  }
  ASSERT_EQ(plan.machine.calibratedCount(), 4 * 6 - 3);
  const Identifiability id = analyse(plan);
  EXPECT_EQ(id.deficiency, 0);
  EXPECT_EQ(id.rank, 21);
  EXPECT_TRUE(id.identifiable());
  EXPECT_TRUE(std::isfinite(id.condition_number));
  EXPECT_GT(id.condition_number, 1.0);
}

TEST(RankTrap, ScalingAParameterDoesNotChangeTheRank) {
  // The rank test runs on the column-scaled matrix: multiplying the information of one
  // parameter by a unit change (deg <-> rad, mm <-> m) changes neither rank nor condition number.
  const Plan plan = loadTestPlan("ref-2r-5bars");
  const PlanInformation info = planInformation(plan, plan.placements, plan.machine.nominal);
  Eigen::Vector3d scale(1e3, 1.0, 180.0 / 3.141592653589793);
  PlanInformation scaled = info;
  scaled.reduced = scale.asDiagonal() * info.reduced * scale.asDiagonal();
  scaled.unreduced_diagonal = scale.cwiseAbs2().cwiseProduct(info.unreduced_diagonal);
  const Identifiability a = analyseIdentifiability(plan, plan.placements, info);
  const Identifiability b = analyseIdentifiability(plan, plan.placements, scaled);
  EXPECT_EQ(a.rank, b.rank);
  EXPECT_NEAR(a.condition_number, b.condition_number, 1e-6 * a.condition_number);
}

/// A made-up 40 x 12 Jacobian drawn from `rng`: independent normal columns but column 3, nearly
/// columns 0 + 1 (surviving fraction about 1e-7), and column 9, never observed.
Eigen::MatrixXd madeUpJacobian(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(40, 12);
  for (int r = 0; r < A.rows(); ++r) {
    for (int c = 0; c < A.cols(); ++c) A(r, c) = normal(rng);
  }
  Eigen::VectorXd noise(A.rows());
  for (int r = 0; r < A.rows(); ++r) noise[r] = normal(rng);
  A.col(3) = A.col(0) + A.col(1) + 5e-4 * noise;
  A.col(9).setZero();
  return A;
}

// The greedy choice (chooseIdentifiableSet) against a dense oracle: the smallest eigenvalue of the
// scaled information over kept + {i}, decomposed afresh for every trial. Columns of a made-up
// Jacobian: independent ones, one nearly a combination of two (surviving fraction about 1e-7:
// held at 1e-6, kept at 1e-10), one an exact copy, one never observed.
TEST(GreedyChoice, AgreesWithTheSmallestEigenvalueOfEveryTrial) {
  std::mt19937_64 rng(18);
  Eigen::MatrixXd A = madeUpJacobian(rng);
  A.col(7) = 2.5 * A.col(2);
  A.col(10) *= 1e4;  // a parameter in other units: the scaling makes it alike
  PlanInformation information;
  information.reduced = A.transpose() * A;
  information.unreduced_diagonal = information.reduced.diagonal();
  const int n = static_cast<int>(A.cols());
  Eigen::VectorXd scale(n);
  for (int i = 0; i < n; ++i) {
    const double d = information.unreduced_diagonal[i];
    scale[i] = d > 0.0 ? 1.0 / std::sqrt(d) : 0.0;
  }
  const Eigen::MatrixXd S = scale.asDiagonal() * information.reduced * scale.asDiagonal();
  for (const double tolerance : {kDefaultRankTolerance, kWeakInformationTolerance}) {
    std::vector<int> kept, dropped;
    std::vector<double> fraction;
    for (int i = 0; i < n; ++i) {
      std::vector<int> trial = kept;
      trial.push_back(i);
      Eigen::MatrixXd principal(trial.size(), trial.size());
      for (std::size_t a = 0; a < trial.size(); ++a) {
        for (std::size_t b = 0; b < trial.size(); ++b) principal(a, b) = S(trial[a], trial[b]);
      }
      const double smallest =
          Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(principal).eigenvalues().minCoeff();
      if (S(i, i) > 0.0 && smallest > tolerance) {
        kept = trial;
      } else {
        dropped.push_back(i);
        fraction.push_back(S(i, i) > 0.0 ? std::max(smallest, 0.0) : 0.0);
      }
    }
    const CalibratedSetChoice choice = chooseIdentifiableSet(information, tolerance);
    EXPECT_EQ(choice.kept, kept) << tolerance;
    ASSERT_EQ(choice.dropped, dropped) << tolerance;
    for (std::size_t d = 0; d < dropped.size(); ++d) {
      EXPECT_NEAR(choice.dropped_fraction[d], fraction[d], 1e-12) << tolerance;
    }
    ASSERT_EQ(choice.ties.size(), dropped.size());
  }
  // The near-combination is held only by the weak rule.
  EXPECT_EQ(chooseIdentifiableSet(information, kDefaultRankTolerance).dropped,
            (std::vector<int>{7, 9}));
  EXPECT_EQ(chooseIdentifiableSet(information, kWeakInformationTolerance).dropped,
            (std::vector<int>{3, 7, 9}));
}

// The pivoted choice (choosePivotedSet) on hand-made columns of a scaled Jacobian: a = (0.5, 0, 0),
// b = (0.9, 5e-4, 0), c = (0, 0, 1). a and b are nearly parallel: S over {a, b} has determinant
// 0.25 * 0.81 + 0.25 * 2.5e-7 - 0.45^2 = 6.25e-8 and trace 1.06, so its smallest eigenvalue is
// about 5.9e-8, under the weak tolerance. Listed first, a is kept and b held; QR with column
// pivoting takes b first (|b|^2 = 0.81 > 0.25) and holds a, in whichever order they are listed.
PlanInformation informationOfColumns(const Eigen::MatrixXd& J, const Eigen::VectorXd& unreduced) {
  PlanInformation information;
  information.reduced = J.transpose() * J;
  information.unreduced_diagonal = unreduced;
  return information;
}

TEST(PivotedChoice, KeepsTheStrongerOfTwoNearlyParallelColumnsInAnyOrder) {
  Eigen::Matrix3d J;
  J.col(0) << 0.5, 0.0, 0.0;
  J.col(1) << 0.9, 5e-4, 0.0;
  J.col(2) << 0.0, 0.0, 1.0;
  // The unreduced norms are 1: S is J^T J itself.
  const PlanInformation abc = informationOfColumns(J, Eigen::Vector3d::Ones());
  EXPECT_EQ(chooseIdentifiableSet(abc, kWeakInformationTolerance).kept, (std::vector<int>{0, 2}));
  const CalibratedSetChoice pivoted = choosePivotedSet(abc, kWeakInformationTolerance);
  EXPECT_EQ(pivoted.kept, (std::vector<int>{1, 2}));
  ASSERT_EQ(pivoted.dropped, (std::vector<int>{0}));
  // The dropped one's surviving fraction: the smallest eigenvalue over {a, b}, by hand.
  const double trace = 0.25 + 0.81 + 2.5e-7, det = 0.25 * (0.81 + 2.5e-7) - 0.45 * 0.45;
  const double smallest = 0.5 * (trace - std::sqrt(trace * trace - 4.0 * det));
  EXPECT_NEAR(pivoted.dropped_fraction[0], smallest, 1e-12);
  // Listed as c, b, a: the same parameters kept (positions 0 and 1 now), a held.
  Eigen::Matrix3d reversed;
  reversed << J.col(2), J.col(1), J.col(0);
  const PlanInformation cba = informationOfColumns(reversed, Eigen::Vector3d::Ones());
  EXPECT_EQ(choosePivotedSet(cba, kWeakInformationTolerance).kept, (std::vector<int>{0, 1}));
  EXPECT_EQ(choosePivotedSet(cba, kWeakInformationTolerance).dropped, (std::vector<int>{2}));
  // At the structural tolerance both are kept whatever the order.
  EXPECT_EQ(choosePivotedSet(abc, kDefaultRankTolerance).kept, (std::vector<int>{0, 1, 2}));
}

// On the made-up Jacobian of the greedy test, shuffled: the pivoted choice holds the same
// parameters whatever the order, and as many as the greedy rule (the count of directions under
// the tolerance does not depend on the order).
TEST(PivotedChoice, TheSetDoesNotDependOnTheListedOrder) {
  std::mt19937_64 rng(18);
  const Eigen::MatrixXd A = madeUpJacobian(rng);
  const auto n = static_cast<int>(A.cols());
  const auto held = [&](const std::vector<int>& order) {
    Eigen::MatrixXd B(A.rows(), n);
    Eigen::VectorXd unreduced(n);  // each column's own, larger than what survives (no ties)
    for (int k = 0; k < n; ++k) {
      const int column = order[static_cast<std::size_t>(k)];
      B.col(k) = A.col(column);
      unreduced[k] = (1.2 + 0.07 * column) * A.col(column).squaredNorm();
    }
    const PlanInformation information = informationOfColumns(B, unreduced);
    const CalibratedSetChoice choice = choosePivotedSet(information, kWeakInformationTolerance);
    EXPECT_EQ(choice.dropped.size(),
              chooseIdentifiableSet(information, kWeakInformationTolerance).dropped.size());
    std::vector<int> out;
    for (const int d : choice.dropped) out.push_back(order[static_cast<std::size_t>(d)]);
    std::sort(out.begin(), out.end());
    return out;
  };
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  const std::vector<int> listed = held(order);
  EXPECT_EQ(listed.size(), 2u);  // one of 0, 1, 3, and the unobserved 9
  EXPECT_EQ(listed.back(), 9);
  for (int shuffle = 0; shuffle < 5; ++shuffle) {
    std::shuffle(order.begin(), order.end(), rng);
    EXPECT_EQ(held(order), listed);
  }
}

}  // namespace identifiability_test
}  // namespace artcal
