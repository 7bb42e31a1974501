// One machine, several tips (docs/urdf.md): the humanoid from its left sole to both grippers,
// the torso and the left leg shared. Expected values computed independently of the two-tip
// code: each arm's own single-tip machine (the ordinary chain import), embedded by parameter
// name; parameters moved by no tip read (identically zero columns); a known truth; a dense
// Gauss-Newton over both arms' own chains and every placement (no reduction, no two-tip code).

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <map>
#include <random>
#include <set>
#include <string>

#include "artcal/calibration/calibrator.hpp"
#include "artcal/calibration/simulation.hpp"
#include "artcal/estimation/design_matrix.hpp"
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

// ---- tip uncertainty per tip -----------------------------------------------------------------

// `names` (a JSON array) less those `chain` does not have.
nlohmann::json namesOn(const nlohmann::json& names, const Mechanism& chain) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& name : names)
    if (chain.parameterIndex(name.get<std::string>()) >= 0) out.push_back(name);
  return out;
}

// The calibrated parameters' names of `machine`, in its order.
nlohmann::json calibratedNames(const Machine& machine) {
  nlohmann::json names = nlohmann::json::array();
  for (int k = 0; k < machine.calibratedCount(); ++k)
    names.push_back(machine.calibratedInfo(k).name);
  return names;
}

// A plan document with `machine` and no placements (parsed without the plan checks).
Plan bareMachine(const nlohmann::json& machine) {
  const nlohmann::json document = {
      {"format", "artcal-plan/1"},
      {"name", "bare"},
      {"machine", machine},
      {"noise", {{"probe", 0.02}, {"encoder", 0.002}}},
      {"artifacts", {{"bar", {{"type", "ball_bar"}, {"length", 100.0}}}}},
      {"placements", nlohmann::json::array()}};
  return parsePlan(document, "bare", false);
}

// Each tip's uncertainty over the workspace is that of its own arm's single-tip chain (the
// ordinary import from the sole to that gripper, no "tips"), with the two-tip V_p's rows and
// columns of that chain's parameters (found by name) and at the same configurations (its readings
// picked by name): computed point by point, then the worst, the mean and the rms.
TEST(SeveralTips, TipUncertaintyPerTipIsEachArmsOwnChainsWithItsRowsOfTheCovariance) {
  const Plan plan = tipPlan(twoArms("identifiable"), {.placements_per_tip = 4, .truth = {}});
  const Evaluation ev = evaluatePlan(plan);
  ASSERT_TRUE(ev.identifiable());
  ASSERT_TRUE(ev.tip);
  ASSERT_EQ(ev.tips.size(), 2u);
  EXPECT_EQ(ev.tips[0].tip.worst.total, ev.tip->worst.total);
  EXPECT_EQ(ev.tips[0].tip.rms, ev.tip->rms);
  const Machine& machine = plan.machine;
  const auto& two = static_cast<const Chain&>(*machine.mechanism);
  const nlohmann::json calibrated = calibratedNames(machine);
  int shared = 0;
  for (std::size_t t = 0; t < 2; ++t) {
    const std::string tip = t == 0 ? kLeft : kRight;
    EXPECT_EQ(ev.tips[t].name, tip);
    nlohmann::json cut = oneArm(tip, "identifiable");
    cut["calibrate"] = namesOn(calibrated, *bareMachine(cut).machine.mechanism);
    const Plan arm = bareMachine(cut);
    const Machine& m = arm.machine;
    const auto& chain = static_cast<const Chain&>(*m.mechanism);
    // The parameters that move the tip are the calibrated ones of its own chain.
    std::vector<int> at;  // two-tip calibrated index of each of the arm's calibrated parameters
    for (int k = 0; k < m.calibratedCount(); ++k) {
      for (int j = 0; j < machine.calibratedCount(); ++j)
        if (machine.calibratedInfo(j).name == m.calibratedInfo(k).name) at.push_back(j);
    }
    ASSERT_EQ(at.size(), static_cast<std::size_t>(m.calibratedCount()));
    std::vector<int> sorted = at;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(ev.tips[t].calibrated, sorted);
    for (const int j : at) shared += machine.calibratedInfo(j).name.find("torso") == 0 ? 1 : 0;
    Eigen::MatrixXd V(at.size(), at.size());
    for (std::size_t a = 0; a < at.size(); ++a)
      for (std::size_t b = 0; b < at.size(); ++b) V(a, b) = ev.covariance->V(at[a], at[b]);
    std::vector<int> reading;  // two-tip reading index of each of the arm's readings
    for (const ChainReading& r : chain.readings()) {
      for (std::size_t i = 0; i < two.readings().size(); ++i)
        if (two.readings()[i].name == r.name) reading.push_back(static_cast<int>(i));
    }
    ASSERT_EQ(reading.size(), chain.readings().size());
    double worst = -1.0, sum = 0.0, sum2 = 0.0;
    TipPoint worst_point;
    for (const Eigen::VectorXd& q : ev.workspace) {
      Eigen::VectorXd q_arm(static_cast<int>(reading.size()));
      for (std::size_t i = 0; i < reading.size(); ++i) q_arm[static_cast<int>(i)] = q[reading[i]];
      const TipPoint point = tipUncertainty(m, arm.noise, q_arm, V);
      sum += point.total;
      sum2 += point.total * point.total;
      if (point.total > worst) {
        worst = point.total;
        worst_point = point;
      }
    }
    const double n = static_cast<double>(ev.workspace.size());
    const TipSummary& got = ev.tips[t].tip;
    EXPECT_NEAR(got.worst.total, worst_point.total, 1e-9 * worst_point.total) << tip;
    EXPECT_NEAR(got.worst.kinematic, worst_point.kinematic, 1e-9 * worst_point.total) << tip;
    EXPECT_NEAR(got.worst.encoder, worst_point.encoder, 1e-9 * worst_point.total) << tip;
    EXPECT_NEAR(got.mean, sum / n, 1e-9 * got.mean) << tip;
    EXPECT_NEAR(got.rms, std::sqrt(sum2 / n), 1e-9 * got.rms) << tip;
  }
  EXPECT_EQ(shared % 2, 0);
  EXPECT_GT(shared, 0);  // the torso's parameters move both tips
  // The two arms differ: their figures are not one number reported twice.
  EXPECT_NE(ev.tips[0].tip.worst.total, ev.tips[1].tip.worst.total);
}

// The optimizer's criterion (PlanEvaluator, what `optimize` plans by) on a machine with several
// tips: the worst over every tip, which are each arm's own (the test above), its worst
// configuration one of the workspace's; the workspace evaluated once per tip.
TEST(SeveralTips, TheOptimizersWorstIsTheWorstOverEveryTip) {
  const Plan plan = tipPlan(twoArms("identifiable"), {.placements_per_tip = 4, .truth = {}});
  const Evaluation ev = evaluatePlan(plan);
  ASSERT_TRUE(ev.identifiable());
  ASSERT_EQ(ev.tips.size(), 2u);
  PlanEvaluator evaluator(plan, ev.workspace);
  EXPECT_EQ(evaluator.workspaceSize(), static_cast<int>(ev.workspace.size()));
  EXPECT_EQ(evaluator.workspace().size(), 2 * static_cast<int>(ev.workspace.size()));
  const auto summary = evaluator.tip(plan.placements);
  ASSERT_TRUE(summary.has_value());
  const double worst = std::max(ev.tips[0].tip.worst.total, ev.tips[1].tip.worst.total);
  EXPECT_NEAR(summary->worst.total, worst, 1e-9 * worst);
  ASSERT_GE(summary->worst_index, 0);
  EXPECT_LT(summary->worst_index, static_cast<int>(ev.workspace.size()));
}

// A pose instrument (a 6-DOF tracker) reads any tip (it read the first only): two stations, one
// reading each hand's frame, on the two-tip machine carry the information of the two arms' own
// single-tip chains, each with its station, embedded by name (independent of the two-tip code).
TEST(SeveralTips, APoseInstrumentReadsEachTipsFrame) {
  const nlohmann::json tracker = {{"type", "instrument"},
                                  {"measures", "pose"},
                                  {"noise", 0.05},
                                  {"noise_angle", 0.01}};
  // Configurations by joint name (deg): every joint of the two-tip machine.
  const nlohmann::json two = twoArms("identifiable");
  const Plan bare_two = parsePlan({{"format", "artcal-plan/1"},
                                   {"name", "two"},
                                   {"machine", two},
                                   {"noise", {{"probe", 0.01}, {"encoder", 0.002}}},
                                   {"artifacts", {{"tracker", tracker}}},
                                   {"placements", nlohmann::json::array()}},
                                  "two", false);
  const auto& chain = static_cast<const Chain&>(*bare_two.machine.mechanism);
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> within(0.1, 0.9);
  std::vector<std::map<std::string, double>> postures(8);
  for (auto& posture : postures) {
    for (std::size_t i = 0; i < chain.readings().size(); ++i) {
      const auto [lo, hi] = bare_two.machine.joint_limits[i];
      posture[chain.readings()[i].name] = radToDeg(lo + within(rng) * (hi - lo));
    }
  }
  auto planOf = [&](const nlohmann::json& machine, const std::vector<std::string>& tips) {
    nlohmann::json document = {{"format", "artcal-plan/1"},
                               {"name", "pose"},
                               {"machine", machine},
                               {"noise", {{"probe", 0.01}, {"encoder", 0.002}}},
                               {"artifacts", {{"tracker", tracker}}},
                               {"placements", nlohmann::json::array()}};
    const Plan bare = parsePlan(document, "pose", false);
    const auto& c = static_cast<const Chain&>(*bare.machine.mechanism);
    for (const std::string& tip : tips) {
      nlohmann::json measurements = nlohmann::json::array();
      for (const auto& posture : postures) {
        nlohmann::json joints = nlohmann::json::array();
        for (const ChainReading& r : c.readings()) joints.push_back(posture.at(r.name));
        nlohmann::json entry = {{"joints", joints}};
        if (tips.size() > 1) entry["tip"] = tip;
        measurements.push_back(entry);
      }
      document["placements"].push_back({{"artifact", "tracker"}, {"measurements", measurements}});
    }
    return parsePlan(document, "pose", true, false);
  };
  const Plan both = planOf(two, {kLeft, kRight});
  Plan all = both;
  calibrateAll(all);
  const Eigen::MatrixXd N = placementsInformation(all, all.placements, all.machine.nominal);
  const Eigen::MatrixXd expected =
      embeddedInformation(planOf(oneArm(kLeft, "identifiable"), {kLeft}),
                          *both.machine.mechanism) +
      embeddedInformation(planOf(oneArm(kRight, "identifiable"), {kRight}),
                          *both.machine.mechanism);
  EXPECT_LT((N - expected).cwiseAbs().maxCoeff(), 1e-9 * expected.cwiseAbs().maxCoeff());
  EXPECT_GT(expected.cwiseAbs().maxCoeff(), 0.0);
}

// ---- two arms calibrated together ------------------------------------------------------------

// A truth off nominal (the calibrated parameters moved by +-2 u, signs from a fixed seed),
// readings of both arms simulated from it with noise (fixed seed), calibrated together on the
// two-tip machine with an explicit calibrate list (what check keeps on the nominal readings less
// its weak directions, so that the set estimated is the one the truth's readings are judged on):
// - the shared parameters (left leg, torso) appear once and, like every other, recover the truth
//   within 3 u;
// - the estimate is the optimum of an independent dense problem: both arms' own single-tip
//   chains (no "tips"), their parameters embedded by name into one vector, every placement's
//   counted rigid motions (a ball bar's five) unknowns of their own, solved by plain Gauss-Newton
//   with each reading re-whitened at the current estimate (no reduction, no two-tip code): equal to
//   1e-5 u (the calibration run to steps of 1e-6 u; measured 6e-6 u at most).
TEST(SeveralTips, TwoArmsCalibratedTogetherRecoverTheTruthAndAreTheDenseOptimumOfBothChains) {
  // The set check keeps on the nominal readings, less its weak directions (u above 1 mm or
  // 0.1 deg: the left leg's, seen through few leg postures), held at nominal in the truth too.
  const Plan nominal = tipPlan(twoArms("identifiable"), {.placements_per_tip = 4, .truth = {}});
  const Evaluation check = evaluatePlan(nominal);
  ASSERT_TRUE(check.identifiable());
  const auto weak = [](const ParameterInfo& info, double u) {
    return u > (info.quantity == Quantity::Angle ? 0.1 * kDegree : 1.0);
  };
  nlohmann::json calibrated = nlohmann::json::array();
  for (int k = 0; k < nominal.machine.calibratedCount(); ++k) {
    const ParameterInfo& info = nominal.machine.calibratedInfo(k);
    if (!weak(info, check.covariance->u[k])) calibrated.push_back(info.name);
  }
  ASSERT_GT(calibrated.size(), 30u);
  Plan plan = tipPlan(twoArms(calibrated), {.placements_per_tip = 4, .truth = {}});
  const Machine& machine = plan.machine;
  ASSERT_TRUE(machine.prior_sigma.size() == 0 || machine.prior_sigma.isZero());
  const Evaluation prediction = evaluatePlan(plan);
  ASSERT_TRUE(prediction.identifiable());
  const Eigen::VectorXd& u = prediction.covariance->u;
  for (int k = 0; k < u.size(); ++k) ASSERT_FALSE(weak(machine.calibratedInfo(k), u[k]));

  // Shared parameters appear once.
  std::map<std::string, int> count;
  int shared = 0;
  for (int k = 0; k < machine.calibratedCount(); ++k) {
    const std::string& name = machine.calibratedInfo(k).name;
    ++count[name];
    if (name.find("torso") == 0 || name.find("leg_left") == 0 || name.find("left_sole") == 0)
      ++shared;
  }
  for (const auto& [name, n] : count) EXPECT_EQ(n, 1) << name;
  EXPECT_GT(shared, 0);

  std::mt19937_64 rng(17);
  Eigen::VectorXd shift(machine.calibratedCount());
  for (int k = 0; k < shift.size(); ++k) {
    shift[k] = (rng() % 2 ? 2.0 : -2.0) * u[k];
  }
  const Eigen::VectorXd truth =
      machine.withCalibrated(machine.nominal, machine.calibratedValues(machine.nominal) + shift);
  NormalSource normal(23);
  plan.placements = Simulator(plan).simulate(truth, normal).placements;
  CalibrationOptions options;
  options.step_tolerance = 1e-6;
  options.function_tolerance = 1e-12;
  const Calibration cal = calibratePlan(plan, options);
  ASSERT_TRUE(cal.summary.converged()) << cal.summary.briefReport();
  ASSERT_TRUE(cal.covariance);
  ASSERT_EQ(cal.systematic.size(), 0);
  const Eigen::VectorXd estimate = cal.estimate(machine);
  const Eigen::VectorXd error = estimate - machine.calibratedValues(truth);
  for (int k = 0; k < error.size(); ++k) {
    EXPECT_LT(std::abs(error[k]), 3.0 * cal.covariance->u[k]) << machine.calibratedInfo(k).name;
  }
  EXPECT_GT(cal.chi2_per_dof, 0.5);
  EXPECT_LT(cal.chi2_per_dof, 1.6);

  // The dense problem: each placement's readings as readings of its arm's own chain.
  const int n_p = machine.calibratedCount();
  const int n_j = static_cast<int>(plan.placements.size());
  struct Arm {
    Plan plan;                ///< the placements its tip reads, as readings of its own chain
    std::vector<int> column;  ///< per calibrated parameter of the arm: its index in the estimate
  };
  std::vector<Arm> arms;
  std::vector<int> arm_placement(static_cast<std::size_t>(n_j));  // index in its arm's plan
  for (int t = 0; t < 2; ++t) {
    nlohmann::json cut = oneArm(t == 0 ? kLeft : kRight, "identifiable");
    cut["calibrate"] = namesOn(calibrated, *bareMachine(cut).machine.mechanism);
    Plan read = plan;
    read.placements.clear();
    for (int j = 0; j < n_j; ++j) {
      const Placement& placement = plan.placements[static_cast<std::size_t>(j)];
      if (placement.measurements.front().stylus != t) continue;
      arm_placement[static_cast<std::size_t>(j)] = static_cast<int>(read.placements.size());
      read.placements.push_back(placement);
    }
    Arm arm{asSingleTip(read, cut), {}};
    const Machine& m = arm.plan.machine;
    for (int k = 0; k < m.calibratedCount(); ++k) {
      for (int j = 0; j < n_p; ++j)
        if (machine.calibratedInfo(j).name == m.calibratedInfo(k).name) arm.column.push_back(j);
    }
    ASSERT_EQ(arm.column.size(), static_cast<std::size_t>(m.calibratedCount()));
    arms.push_back(std::move(arm));
  }
  // The full parameter vector of arm `a` for calibrated values `g` (its other parameters nominal).
  const auto armParameters = [&](const Arm& arm, const Eigen::VectorXd& g) {
    const Machine& m = arm.plan.machine;
    Eigen::VectorXd values(m.calibratedCount());
    for (int k = 0; k < values.size(); ++k) values[k] = g[arm.column[static_cast<std::size_t>(k)]];
    return m.withCalibrated(m.nominal, values);
  };
  Eigen::VectorXd g = machine.calibratedValues(machine.nominal);
  std::vector<RigidTransform> poses = fitPlacements(plan, plan.placements, machine.nominal);
  const Eigen::VectorXd no_c;
  ObservationBlock block;
  double step = 0.0;
  for (int iteration = 0; iteration < 30; ++iteration) {
    std::vector<Eigen::MatrixXd> rows_A;
    std::vector<Eigen::VectorXd> rows_e;
    int rows = 0;
    for (int j = 0; j < n_j; ++j) {
      const Placement& placement = plan.placements[static_cast<std::size_t>(j)];
      const int t = placement.measurements.front().stylus;
      const Arm& arm = arms[static_cast<std::size_t>(t)];
      for (const Measurement& m : placement.measurements) ASSERT_EQ(m.stylus, t);
      DesignMatrixBuilder builder(arm.plan.machine, arm.plan.noise);
      const Placement& as_arm =
          arm.plan.placements[static_cast<std::size_t>(arm_placement[static_cast<std::size_t>(j)])];
      builder.build(arm.plan.artifacts[static_cast<std::size_t>(as_arm.artifact)],
                    as_arm.measurements, armParameters(arm, g), poses[static_cast<std::size_t>(j)],
                    no_c, true, block);
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(block.rows(), n_p + 6 * n_j);
      for (std::size_t k = 0; k < arm.column.size(); ++k)
        A.col(arm.column[k]) = block.A_p.col(static_cast<int>(k));
      // The rigid motions the artifact's table counts (a ball bar's five: its roll about its
      // own line moves no ball), the others held.
      ASSERT_EQ(block.A_r.cols(), 6);
      A.middleCols(n_p + 6 * j, block.rigid_primary) = block.A_r.leftCols(block.rigid_primary);
      rows_A.push_back(A);
      rows_e.push_back(block.e);
      rows += block.rows();
    }
    Eigen::MatrixXd A(rows, n_p + 6 * n_j);
    Eigen::VectorXd e(rows);
    for (std::size_t b = 0, r = 0; b < rows_A.size(); r += rows_A[b].rows(), ++b) {
      A.middleRows(static_cast<int>(r), rows_A[b].rows()) = rows_A[b];
      e.segment(static_cast<int>(r), rows_e[b].size()) = rows_e[b];
    }
    // Columns scaled to unit norm (mm and rad); the held rigid motions are zero columns, left
    // out by the minimum-norm solution.
    Eigen::VectorXd scale = A.colwise().norm().transpose();
    for (double& s : scale) s = s > 1e-12 * scale.maxCoeff() ? 1.0 / s : 0.0;
    const Eigen::MatrixXd scaled = A * scale.asDiagonal();
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(scaled);
    cod.setThreshold(1e-10);
    const Eigen::VectorXd delta = -(scale.asDiagonal() * cod.solve(e)).eval();
    g += delta.head(n_p);
    for (int j = 0; j < n_j; ++j) {
      const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(
          plan.placements[static_cast<std::size_t>(j)].artifact)];
      poses[static_cast<std::size_t>(j)] = poses[static_cast<std::size_t>(j)].perturbed(
          artifact.expandFullRigidStep(delta.segment(n_p + 6 * j, 6)));
    }
    step = delta.head(n_p).cwiseQuotient(u).cwiseAbs().maxCoeff();
    if (step < 1e-10) break;
  }
  EXPECT_LT(step, 1e-10);
  for (int k = 0; k < n_p; ++k) {
    EXPECT_LT(std::abs(g[k] - estimate[k]), 1e-5 * cal.covariance->u[k])
        << machine.calibratedInfo(k).name << ": dense " << g[k] << ", two tips " << estimate[k];
  }
}

}  // namespace several_tips_test
}  // namespace artcal
