// Joint compliance calibrated (docs/compliance.md): a UR5 (Universal Robots' published DH, masses
// and centres) read by a laser tracker in three stations, one without a payload and two with
// different payloads, simulated with compliances of 1e-5 to 1e-4 rad/(N m): calibrate recovers
// every compliance and geometric parameter within 3 u; the plan file carries the payloads.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <random>

#include "artcal/calibration/calibrate_readings.hpp"
#include "artcal/internal.hpp"
#include "artcal/io/plan_file.hpp"
#include "artcal/model/joint_compliance.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace compliance_calibration_test {

/// The UR5 with compliance, a probe offset off the flange axis, three tracker stations of 40
/// random configurations each (payloads: none, 2 kg, 5 kg), every compliance but j1's (a
/// vertical first axis: tau_1 = 0) calibrated with the 21 identifiable geometric parameters.
nlohmann::json ur5Plan(std::uint64_t seed) {
  std::ifstream in(std::string(ARTCAL_TEST_DATA) + "/ur5-tracker/ur5-compliance.machine.json");
  nlohmann::json machine = nlohmann::json::parse(in);
  machine["probe"] = {60.0, 20.0, 40.0};
  machine["calibrate"] = {"j1.a",          "j1.alpha",      "j2.theta",      "j2.d",
                          "j2.a",          "j2.alpha",      "j3.theta",      "j3.d",
                          "j3.a",          "j3.alpha",      "j4.theta",      "j4.d",
                          "j4.a",          "j4.alpha",      "j5.theta",      "j5.d",
                          "j5.a",          "j5.alpha",      "probe.x",       "probe.y",
                          "probe.z",       "j2.compliance", "j3.compliance", "j4.compliance",
                          "j5.compliance", "j6.compliance"};
  machine["joint_limits"] = nlohmann::json::array();
  for (int i = 0; i < 6; ++i) machine["joint_limits"].push_back({-170.0, 170.0});
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> angle(-170.0, 170.0);
  const nlohmann::json payloads[3] = {nullptr,
                                      {{"mass", 2.0}, {"centre", {50.0, 0.0, 30.0}}},
                                      {{"mass", 5.0}, {"centre", {-40.0, 60.0, 80.0}}}};
  nlohmann::json placements = nlohmann::json::array();
  for (int s = 0; s < 3; ++s) {
    nlohmann::json readings = nlohmann::json::array();
    for (int r = 0; r < 40; ++r) {
      nlohmann::json q = nlohmann::json::array();
      for (int i = 0; i < 6; ++i) q.push_back(angle(rng));
      readings.push_back({{"joints", q}});
    }
    nlohmann::json placement = {{"artifact", "tracker"},
                                {"name", "station " + std::to_string(s + 1)},
                                {"measurements", readings}};
    if (!payloads[s].is_null()) placement["payload"] = payloads[s];
    placements.push_back(placement);
  }
  return {{"format", "artcal-plan/1"},
          {"name", "ur5-compliance"},
          {"machine", machine},
          {"noise", {{"probe", 0.01}, {"encoder", 0.0005}}},
          {"artifacts",
           {{"tracker", {{"type", "instrument"}, {"measures", "point"}, {"noise", 0.02}}}}},
          {"placements", placements},
          {"workspace", {{"samples", 256}, {"seed", 1}}}};
}

TEST(ComplianceCalibration, SimulatedTrackerReadingsRecoverTheComplianceWithin3u) {
  Plan plan = parsePlan(ur5Plan(11), "ur5-compliance.json");
  ASSERT_EQ(plan.placements[2].measurements[0].payload.mass, 5.0);
  Eigen::VectorXd truth = plan.machine.nominal;
  const Mechanism& mech = *plan.machine.mechanism;
  const double compliance[6] = {0.0, 3e-5, 6e-5, 1e-4, 8e-5, 5e-5};  // rad/(N m)
  for (int i = 0; i < 6; ++i)
    truth[mech.parameterIndex("j" + std::to_string(i + 1) + ".compliance")] = compliance[i];
  truth[mech.parameterIndex("j3.a")] += 0.3;
  truth[mech.parameterIndex("j2.theta")] += 0.002;
  NormalSource normal(5);
  plan.placements = Simulator(plan).simulate(truth, normal).placements;
  const Calibration calibration = calibratePlan(plan);
  ASSERT_TRUE(calibration.summary.converged());
  ASSERT_TRUE(calibration.covariance);
  const Eigen::VectorXd error =
      calibration.estimate(plan.machine) - plan.machine.calibratedValues(truth);
  for (int k = 0; k < error.size(); ++k) {
    EXPECT_LT(std::abs(error[k]), 3.0 * calibration.covariance->u[k])
        << plan.machine.calibratedInfo(k).name;
  }
  // The compliances are determined far better than their size (j2 to j5).
  for (int i = 2; i <= 5; ++i) {
    const int k = static_cast<int>(plan.machine.calibrated.size()) - 6 + i - 1;
    EXPECT_LT(calibration.covariance->u[k], 0.2 * compliance[i - 1])
        << plan.machine.calibratedInfo(k).name;
  }
  EXPECT_GT(calibration.chi2_per_dof, 0.5);
  EXPECT_LT(calibration.chi2_per_dof, 1.6);
}

// Geometric only against the same readings: the sag the compliance explains stays in the
// residuals (chi2/dof far above 1).
TEST(ComplianceCalibration, GeometryAloneCannotAbsorbTheSag) {
  Plan plan = parsePlan(ur5Plan(11), "ur5-compliance.json");
  Eigen::VectorXd truth = plan.machine.nominal;
  const Mechanism& mech = *plan.machine.mechanism;
  truth[mech.parameterIndex("j2.compliance")] = 3e-5;
  truth[mech.parameterIndex("j3.compliance")] = 6e-5;
  NormalSource normal(5);
  plan.placements = Simulator(plan).simulate(truth, normal).placements;
  plan.machine.calibrated.resize(21);
  const Calibration geometric = calibratePlan(plan);
  ASSERT_TRUE(geometric.summary.converged());
  EXPECT_GT(geometric.chi2_per_dof, 5.0);
}

TEST(ComplianceCalibration, PayloadsRoundTripThroughThePlanFile) {
  const Plan plan = parsePlan(ur5Plan(3), "ur5-compliance.json");
  nlohmann::json document = ur5Plan(3);
  document["machine"] = machineToJson(plan.machine, plan.machine.nominal);
  document["placements"] = placementsToJson(plan);
  const Plan reread = parsePlan(document, "again.json");
  ASSERT_EQ(reread.placements.size(), 3u);
  EXPECT_EQ(reread.placements[0].measurements[3].payload.mass, 0.0);
  EXPECT_EQ(reread.placements[2].measurements[3].payload.mass, 5.0);
  EXPECT_EQ(reread.placements[2].measurements[3].payload.centre, Eigen::Vector3d(-40, 60, 80));
  EXPECT_EQ(reread.machine.nominal, plan.machine.nominal);
}

TEST(ComplianceCalibration, APayloadNeedsAMachineWithCompliance) {
  nlohmann::json document = ur5Plan(3);
  document["machine"].erase("compliance");
  document["machine"]["calibrate"] = "identifiable";
  try {
    parsePlan(document, "p.json");
    FAIL() << "a payload without compliance was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(e.describe().find("/placements/1/payload"), std::string::npos) << e.describe();
  }
}

/// tests/data/compliance-ur5-tracker.json simulated from `truth` (named values, file units).
Plan simulatedTrackerPlan(const std::map<std::string, double>& truth_values, std::uint64_t seed) {
  Plan plan = loadPlan(std::string(ARTCAL_TEST_DATA) + "/compliance-ur5-tracker.json");
  Eigen::VectorXd truth = plan.machine.nominal;
  const Mechanism& mech = *plan.machine.mechanism;
  for (const auto& [name, value] : truth_values) {
    const int k = mech.parameterIndex(name);
    truth[k] = fromFileUnit(mech.parameters()[static_cast<std::size_t>(k)].quantity, value);
  }
  NormalSource normal(seed);
  plan.placements = Simulator(plan).simulate(truth, normal).placements;
  return plan;
}

int compliancesKept(const CalibrationRun& run) {
  int n = 0;
  for (const int k : run.kept()) n += isComplianceParameter(*run.decided.machine.mechanism, k);
  return n;
}

// The held-out choice (docs/compliance.md section 5): with a compliance in the truth, geometric +
// compliance holds far better than geometric only and is kept; without one, it is left out.
TEST(ComplianceCalibration, TheHeldOutChoiceKeepsComplianceOnlyWhereItHelps) {
  const std::map<std::string, double> sag = {{"j2.compliance", 0.0017}, {"j3.compliance", 0.0034}};
  const CalibrationRun with = calibrateReadings(simulatedTrackerPlan(sag, 3));
  ASSERT_TRUE(with.calibration.model_choice);
  const ModelChoice& chosen_with = *with.calibration.model_choice;
  const auto geometric =
      std::find_if(chosen_with.candidates.begin(), chosen_with.candidates.end(),
                   [](const ModelChoiceCandidate& c) { return c.geometric_only; });
  ASSERT_NE(geometric, chosen_with.candidates.end());
  EXPECT_FALSE(geometric->chosen);
  EXPECT_GT(geometric->observed, 10.0 * chosen_with.candidates.front().observed);
  EXPECT_EQ(compliancesKept(with), 5);  // j2 .. j6 (j1: vertical axis, not observed)
  for (std::uint64_t seed : {1u, 2u}) {
    const CalibrationRun without = calibrateReadings(simulatedTrackerPlan({}, seed));
    ASSERT_TRUE(without.calibration.model_choice);
    EXPECT_EQ(compliancesKept(without), 0) << "seed " << seed;
    EXPECT_TRUE(without.calibration.model_choice
                    ->candidates[static_cast<std::size_t>(without.calibration.model_choice->chosen)]
                    .geometric_only);
  }
}

TEST(ComplianceCalibration, CheckNamesAComplianceWithoutTorqueNotObserved) {
  const Plan plan = loadPlan(std::string(ARTCAL_TEST_DATA) + "/compliance-ur5-tracker.json");
  ASSERT_TRUE(plan.calibrate_resolution);
  const int j1 = plan.machine.mechanism->parameterIndex("j1.compliance");
  EXPECT_EQ(plan.calibrate_resolution->unobserved, std::vector<int>{j1});
  const std::vector<int>& kept = plan.calibrate_resolution->kept;
  EXPECT_NE(
      std::find(kept.begin(), kept.end(), plan.machine.mechanism->parameterIndex("j2.compliance")),
      kept.end());
}

}  // namespace compliance_calibration_test
}  // namespace artcal
