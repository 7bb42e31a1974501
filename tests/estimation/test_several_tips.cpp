// One machine, several tips (docs/urdf.md): the humanoid from its left sole to both grippers,
// the torso and the left leg shared. Expected values computed independently of the two-tip
// code: each arm's own single-tip machine (the ordinary chain import), embedded by parameter
// name; parameters moved by no tip read (identically zero columns); a known truth.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <set>
#include <string>

#include "artcal/calibration/calibrator.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/io/urdf.hpp"
#include "several_tips.hpp"

namespace artcal {
namespace several_tips_test {

using test_support::humanoidUrdf;
using test_support::tipPlan;
using test_support::TipPlanOptions;

const std::string kLeft = "gripper_left_base_link";
const std::string kRight = "gripper_right_base_link";

nlohmann::json twoArms(const nlohmann::json& calibrate) {
  nlohmann::json machine =
      importUrdf(humanoidUrdf(), "left_sole_link", std::vector<std::string>{kLeft, kRight});
  machine["calibrate"] = calibrate;
  return machine;
}

nlohmann::json oneArm(const std::string& tip, const nlohmann::json& calibrate) {
  nlohmann::json machine = importUrdf(humanoidUrdf(), "left_sole_link", tip);
  machine["calibrate"] = calibrate;
  return machine;
}

// `plan`'s placements as readings of `single` (a machine whose readings are a subset of the
// plan's by name; the tip dropped).
Plan asSingleTip(const Plan& plan, const nlohmann::json& single) {
  nlohmann::json document = {{"format", "artcal-plan/1"},
                             {"name", "one-arm"},
                             {"machine", single},
                             {"noise", {{"probe", 0.02}, {"encoder", 0.002}}},
                             {"artifacts", {{"bar", {{"type", "ball_bar"}, {"length", 100.0}}}}},
                             {"placements", nlohmann::json::array()}};
  const Plan bare = parsePlan(document, "one-arm", false);
  const auto& to = static_cast<const Chain&>(*bare.machine.mechanism);
  const auto& from = static_cast<const Chain&>(*plan.machine.mechanism);
  nlohmann::json placements = nlohmann::json::array();
  for (const Placement& placement : plan.placements) {
    nlohmann::json measurements = nlohmann::json::array();
    for (const Measurement& m : placement.measurements) {
      nlohmann::json joints = nlohmann::json::array();
      for (const ChainReading& reading : to.readings()) {
        for (int r = 0; r < from.jointCount(); ++r)
          if (from.readings()[static_cast<std::size_t>(r)].name == reading.name)
            joints.push_back(radToDeg(m.joints[r]));
      }
      measurements.push_back({{"feature", m.feature}, {"joints", joints}});
    }
    placements.push_back({{"artifact", "bar"}, {"measurements", measurements}});
  }
  document["placements"] = placements;
  return parsePlan(document, "one-arm");
}

// Every parameter calibrated (rank-deficient information is fine for a sum).
void calibrateAll(Plan& plan) {
  plan.machine.calibrated.clear();
  for (int i = 0; i < plan.machine.mechanism->parameterCount(); ++i)
    plan.machine.calibrated.push_back(i);
}

// N of `plan` (every parameter) embedded into `into`'s parameters by name.
Eigen::MatrixXd embeddedInformation(Plan plan, const Mechanism& into) {
  calibrateAll(plan);
  const Eigen::MatrixXd N = placementsInformation(plan, plan.placements, plan.machine.nominal);
  const Mechanism& mech = *plan.machine.mechanism;
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(into.parameterCount(), into.parameterCount());
  std::vector<int> at;
  for (const ParameterInfo& info : mech.parameters()) at.push_back(into.parameterIndex(info.name));
  for (int i = 0; i < N.rows(); ++i)
    for (int j = 0; j < N.cols(); ++j) out(at[i], at[j]) += N(i, j);
  return out;
}

TEST(SeveralTips, ImportListsTheSharedJointsOnceAndEachTipsPath) {
  const nlohmann::json machine = twoArms("identifiable");
  // 7 leg joints up, 2 torso joints, 5 joints per arm: 19, not 28.
  EXPECT_EQ(machine["joints"].size(), 19u);
  ASSERT_EQ(machine["tips"].size(), 2u);
  EXPECT_EQ(machine["tips"][0]["name"], kLeft);
  EXPECT_EQ(machine["tips"][0]["joints"].size(), 14u);
  EXPECT_EQ(machine["tips"][1]["joints"].size(), 14u);
  EXPECT_EQ(machine["tips"][1]["joints"][8], "torso_2_joint");
  EXPECT_EQ(machine["tips"][1]["joints"][9], "arm_right_1_joint");
  const Plan plan = tipPlan(machine, {.placements_per_tip = 1, .postures = 1, .truth = {}});
  EXPECT_EQ(plan.machine.mechanism->stylusCount(), 2);
  // The written plan names each reading's tip.
  const nlohmann::json written = placementsToJson(plan);
  EXPECT_EQ(written[0]["measurements"][0]["tip"], kLeft);
  EXPECT_EQ(written[1]["measurements"][0]["tip"], kRight);
}

// Placements each read by one arm: the two-tip machine's information is the sum of each arm's
// single-tip information, embedded by name (the shared torso and leg entries add up).
TEST(SeveralTips, InformationIsTheSumOfEachArmsOwnChain) {
  Plan plan = tipPlan(twoArms("identifiable"), {.placements_per_tip = 3, .truth = {}});
  const Mechanism& mech = *plan.machine.mechanism;
  ASSERT_EQ(plan.placements.size(), 6u);
  Plan left_readings = plan, right_readings = plan;
  left_readings.placements.assign(plan.placements.begin(), plan.placements.begin() + 3);
  right_readings.placements.assign(plan.placements.begin() + 3, plan.placements.end());
  const Eigen::MatrixXd expected =
      embeddedInformation(asSingleTip(left_readings, oneArm(kLeft, "identifiable")), mech) +
      embeddedInformation(asSingleTip(right_readings, oneArm(kRight, "identifiable")), mech);
  calibrateAll(plan);
  const Eigen::MatrixXd N = placementsInformation(plan, plan.placements, plan.machine.nominal);
  ASSERT_EQ(N.rows(), expected.rows());
  EXPECT_LT((N - expected).norm(), 1e-9 * expected.norm());
  // A shared parameter gets information from both arms, an arm's own from that arm alone.
  const int torso = mech.parameterIndex("torso_2_joint.offset");
  const int right = mech.parameterIndex("arm_right_2_joint.offset");
  EXPECT_GT(N(torso, torso), 0.0);
  EXPECT_GT(N(right, right), 0.0);
}

// Per tip: with the left arm's readings alone, the identifiable set of the two-tip machine is
// the left arm's own chain's (no parameter of the right arm kept), and the rank deficiency of
// every parameter calibrated grows by exactly the right arm's own parameters (their columns
// are zero).
TEST(SeveralTips, IdentifiabilityPerTipIsEachArmsOwn) {
  const Plan left_only =
      tipPlan(twoArms("identifiable"), {.placements_per_tip = 3, .tips_read = {0}, .truth = {}});
  const Plan single = asSingleTip(left_only, oneArm(kLeft, "identifiable"));
  const Mechanism& mech = *left_only.machine.mechanism;
  std::set<std::string> kept, kept_single;
  for (const int i : left_only.machine.calibrated)
    kept.insert(mech.parameters()[static_cast<std::size_t>(i)].name);
  for (const int i : single.machine.calibrated)
    kept_single.insert(single.machine.mechanism->parameters()[static_cast<std::size_t>(i)].name);
  EXPECT_EQ(kept, kept_single);
  for (const std::string& name : kept) EXPECT_EQ(name.find("right"), std::string::npos) << name;

  Plan all = left_only, all_single = single;
  calibrateAll(all);
  calibrateAll(all_single);
  const PlanInformation info = planInformation(all, all.placements, all.machine.nominal);
  const PlanInformation info_single =
      planInformation(all_single, all_single.placements, all_single.machine.nominal);
  const Identifiability id = analyseIdentifiability(all, all.placements, info);
  const Identifiability id_single =
      analyseIdentifiability(all_single, all_single.placements, info_single);
  const int right_own = mech.parameterCount() - all_single.machine.mechanism->parameterCount();
  EXPECT_EQ(right_own, 5 * 6 + 4);  // 5 joints' origins, 4 movable joints' offsets
  EXPECT_EQ(id.deficiency, id_single.deficiency + right_own);
}

}  // namespace several_tips_test
}  // namespace artcal
