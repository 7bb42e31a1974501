// The rank policy (method.md section 5, "Rank policy") against a dense oracle written in the test
// (tests/support/rank_plans.hpp): placements whose measurements leave rigid directions unseen
// (2-D and 3-D step gauges, a bar with one ball read in 3 postures, a plate with only its origin
// ball, a plate with only features on its X axis) beside well-spread bars, and a 3-axis arm with
// j1.theta calibrated. Then the same plans moved rigidly: nothing decided on rounding noise.

#include <gtest/gtest.h>

#include <functional>

#include "artcal/internal.hpp"
#include "rank_plans.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace rank_policy_test {

using namespace testing;

struct RankCase {
  const char* name;
  std::function<Plan()> build;
  int effective_rigid_of_last;  ///< the rank of the last placement's rigid block
};

const std::vector<RankCase>& rankCases() {
  static const std::vector<RankCase> cases = {
      {"step gauge 2-D", stepGauge2DPlan, 1}, {"step gauge 3-D", stepGauge3DPlan, 1},
      {"one ball of a bar", oneBallPlan, 3},  {"plate origin ball", plateOriginPlan, 3},
      {"plate X axis", plateXAxisPlan, 5},
  };
  return cases;
}

// The plans are built once (inverse kinematics of the 6-axis arm takes a moment).
const Plan& cachedPlan(std::size_t index) {
  static std::vector<Plan> plans = [] {
    std::vector<Plan> out;
    for (const RankCase& c : rankCases()) out.push_back(c.build());
    return out;
  }();
  return plans[index];
}

TEST(RankPolicy, UnseenRigidDirectionsMatchTheDenseOracle) {
  for (std::size_t c = 0; c < rankCases().size(); ++c) {
    SCOPED_TRACE(rankCases()[c].name);
    const Plan& plan = cachedPlan(c);
    const DenseInformation oracle = denseOracle(plan);
    const Evaluation evaluation = evaluatePlan(plan);
    ASSERT_EQ(oracle.rank, plan.machine.calibratedCount());
    ASSERT_TRUE(evaluation.identifiable());
    EXPECT_EQ(evaluation.identifiability.deficiency, 0);
    for (int i = 0; i < oracle.u.size(); ++i) {
      EXPECT_NEAR(evaluation.covariance->u[i], oracle.u[i], 1e-8 * oracle.u[i])
          << "parameter " << i;
    }
    // Effective N(r_j): the rank of each placement's rigid block, as the oracle counts it.
    const CountingCondition& count = evaluation.identifiability.counting;
    EXPECT_EQ(count.N_r, oracle.nuisance_rank);
    EXPECT_EQ(count.rigid_effective.back(), rankCases()[c].effective_rigid_of_last);
    EXPECT_LT(count.N_r, count.N_r_table);
  }
}

TEST(RankPolicy, ThreeAxisArmWithJ1ThetaIsDeficientByOne) {
  const Plan plan = arm3ThetaPlan();
  const DenseInformation oracle = denseOracle(plan);
  EXPECT_EQ(oracle.rank, plan.machine.calibratedCount() - 1);
  const Evaluation evaluation = evaluatePlan(plan);
  EXPECT_FALSE(evaluation.identifiable());
  EXPECT_EQ(evaluation.identifiability.deficiency, 1);

  ASSERT_EQ(evaluation.identifiability.unidentifiable.size(), 1u);
  EXPECT_EQ(evaluation.identifiability.unidentifiable[0].names,
            std::vector<std::string>{"j1.theta"});
  EXPECT_EQ(evaluation.identifiability.to_fix, std::vector<std::string>{"j1.theta"});
  // Without j1.theta the rest is identifiable and matches the oracle.
  Plan fixed = plan;
  fixed.machine.calibrated.erase(fixed.machine.calibrated.begin());
  const DenseInformation reduced = denseOracle(fixed);
  const Evaluation rest = evaluatePlan(fixed);
  ASSERT_TRUE(rest.identifiable());
  ASSERT_EQ(reduced.rank, fixed.machine.calibratedCount());
  for (int i = 0; i < reduced.u.size(); ++i) {
    EXPECT_NEAR(rest.covariance->u[i], reduced.u[i], 1e-8 * reduced.u[i]) << "parameter " << i;
  }
}

// ---------------------------------------------------------------------------------------------
// Rigid motions of the whole plan. The machines' symmetries move the plan without changing what
// it measures: a rotation about the first joint's axis (its readings shifted by the angle; the
// planar arm's base, the serial arm's z axis) and, for the serial arm, a translation along that
// axis (the nominal j1.d, not calibrated). A plate's features may also be given in any frame of
// the plate: rotated and translated in the artifact frame, the plate is the same object.

Plan movedPlan(const Plan& plan, double angle, double shift) {
  Plan moved = plan;
  for (Placement& placement : moved.placements) {
    for (Measurement& m : placement.measurements) m.joints[0] += angle;
  }
  if (plan.machine.dimension() == 3) {
    const int j1_d = plan.machine.mechanism->parameterIndex("j1.d");
    moved.machine.nominal[j1_d] += shift;
  }
  for (Artifact& artifact : moved.artifacts) {
    if (artifactTypeName(artifact) != "ball_plate" || artifact.dimension != 3) continue;
    const Eigen::Matrix3d R =
        (Eigen::AngleAxisd(angle, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
    artifact.features = (R * artifact.features).colwise() + Eigen::Vector3d(shift, -shift, 2.0);
  }
  return moved;
}

void expectSameResults(const Plan& plan, const Evaluation& reference) {
  for (double degrees : {1e-9, 1.0, 40.0}) {
    SCOPED_TRACE(degrees);
    const Plan moved = movedPlan(plan, degrees * kDeg, 37.0);
    const Evaluation evaluation = evaluatePlan(moved);
    EXPECT_EQ(evaluation.identifiable(), reference.identifiable());
    EXPECT_EQ(evaluation.identifiability.deficiency, reference.identifiability.deficiency);
    EXPECT_EQ(evaluation.identifiability.counting.N_r, reference.identifiability.counting.N_r);
    if (!reference.covariance || !evaluation.covariance) continue;
    for (int i = 0; i < reference.covariance->u.size(); ++i) {
      const double u = reference.covariance->u[i];
      EXPECT_NEAR(evaluation.covariance->u[i], u, 1e-9 * u) << "parameter " << i;
    }
  }
}

TEST(RankPolicy, RigidMotionsOfThePlanChangeNoUncertaintyAndNoVerdict) {
  for (std::size_t c = 0; c < rankCases().size(); ++c) {
    SCOPED_TRACE(rankCases()[c].name);
    const Plan& plan = cachedPlan(c);
    expectSameResults(plan, evaluatePlan(plan));
  }
  const Plan arm3 = arm3ThetaPlan();
  expectSameResults(arm3, evaluatePlan(arm3));
}

// ---------------------------------------------------------------------------------------------
// "calibrate": "identifiable" (models.md section 1)

std::vector<std::string> namesOf(const Plan& plan, const std::vector<int>& indices) {
  std::vector<std::string> names;
  for (int i : indices) {
    names.push_back(plan.machine.mechanism->parameters()[static_cast<std::size_t>(i)].name);
  }
  return names;
}

TEST(CalibrateIdentifiable, SerialArmWithAllParametersDropsTheKnownSix) {
  Plan plan = aacmmPlan();
  plan.placements = randomSpatialBars(plan, 8, 3, 31);
  plan.machine.calibrated.clear();
  for (int i = 0; i < plan.machine.mechanism->parameterCount(); ++i) {
    plan.machine.calibrated.push_back(i);
  }
  plan.machine.calibrate_identifiable = true;
  resolveCalibratedSet(plan);
  ASSERT_TRUE(plan.calibrate_resolution.has_value());
  EXPECT_EQ(plan.machine.calibratedCount(), 21);
  // In the model's order the greedy rule keeps j6.theta .. j6.alpha and lets the probe offset
  // carry what they cannot separate: the dropped ones are j1.theta, j1.d, j6.alpha and three of
  // the probe offset's, six in all (models.md section 1, method.md section 5).
  const std::vector<std::string> dropped = namesOf(plan, plan.calibrate_resolution->dropped);
  ASSERT_EQ(dropped.size(), 6u);
  EXPECT_EQ(dropped[0], "j1.theta");
  EXPECT_EQ(dropped[1], "j1.d");
  EXPECT_TRUE(evaluatePlan(plan).identifiable());
  // Each tie starts with its dropped parameter, coefficient +1 or largest.
  for (std::size_t d = 0; d < dropped.size(); ++d) {
    const auto& tie = plan.calibrate_resolution->ties[d];
    ASSERT_FALSE(tie.empty());
    EXPECT_EQ(tie.front().first, plan.calibrate_resolution->dropped[d]);
    EXPECT_GT(tie.front().second, 0.0);
  }
}

TEST(CalibrateIdentifiable, PreferredOrderKeepsTheSeedsTwentyOne) {
  // The reference arm listed with its seed's 21 first and the six known ones last.
  Plan plan = loadTestPlan("ref-aacmm-3bars-3postures");
  const std::vector<int> seed21 = plan.machine.calibrated;
  const Mechanism& arm = *plan.machine.mechanism;
  for (int i = 0; i < arm.parameterCount(); ++i) {
    if (std::find(seed21.begin(), seed21.end(), i) == seed21.end()) {
      plan.machine.calibrated.push_back(i);
    }
  }
  ASSERT_EQ(plan.machine.calibratedCount(), 27);
  plan.machine.calibrate_identifiable = true;
  resolveCalibratedSet(plan);
  EXPECT_EQ(plan.machine.calibrated, seed21);
  EXPECT_EQ(plan.calibrate_resolution->dropped.size(), 6u);
}

TEST(CalibrateIdentifiable, DegenerateRingKeepsOneParameter) {
  // Every bar at the same pair of radii: rank 1 (l1, l2 and dt2 tie), the first is kept.
  Plan plan = loadTestPlan("ref-2r-ring-degenerate");
  plan.machine.calibrate_identifiable = true;
  resolveCalibratedSet(plan);
  EXPECT_EQ(namesOf(plan, plan.machine.calibrated), std::vector<std::string>{"l1"});
  EXPECT_EQ(namesOf(plan, plan.calibrate_resolution->dropped),
            (std::vector<std::string>{"l2", "dt2"}));
  EXPECT_TRUE(evaluatePlan(plan).identifiable());
}

TEST(CalibrateIdentifiable, ParsedFromThePlanFile) {
  const std::string path = test_support::testDataFile("ref-aacmm-3bars-3postures.json");
  nlohmann::json doc = readJsonFile(path);
  doc["machine"]["calibrate"] = "identifiable";
  const Plan plan = parsePlan(doc, path, true);
  ASSERT_TRUE(plan.calibrate_resolution.has_value());
  EXPECT_EQ(plan.machine.calibratedCount(), 21);
  EXPECT_EQ(plan.calibrate_resolution->dropped.size(), 6u);
  doc["machine"]["calibrate"] = {{"identifiable", {"l9"}}};
  EXPECT_THROW(parsePlan(doc, path, true), InputError);
  doc["machine"]["calibrate"] = "everything";
  EXPECT_THROW(parsePlan(doc, path, true), InputError);
}

}  // namespace rank_policy_test
}  // namespace artcal
