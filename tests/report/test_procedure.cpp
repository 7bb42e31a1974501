// artcal procedure (docs/plan-format.md "artcal procedure"): for every plan in plans/ each reading
// is listed with target joint values on which the nominal forward kinematics lands on the
// feature, placed by the listed pose, to 1e-9 mm. The placed features are computed here from the
// artifact's coordinates and the pose (centre, angle / direction, roll), not by the library.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <sstream>

#include "artcal/calibration/verification.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/planning/procedure.hpp"
#include "artcal/report/procedure.hpp"
#include "artcal/report/verification_report.hpp"
#include "cli_runner.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace procedure_test {

namespace fs = std::filesystem;
using nlohmann::json;
using test_support::runCli;

/// Artifact-frame point W placed by a pose: x = R W + centre, R's columns the artifact's axes.
Eigen::VectorXd placeByPose(const json& pose, const Eigen::VectorXd& W) {
  const std::vector<double> c = pose.at("center");
  if (W.size() == 2) {
    const double a = degToRad(pose.at("angle").get<double>());
    return Eigen::Vector2d(std::cos(a) * W[0] - std::sin(a) * W[1] + c[0],
                           std::sin(a) * W[0] + std::cos(a) * W[1] + c[1]);
  }
  const std::vector<double> d = pose.at("direction");
  const Eigen::Vector3d ex = Eigen::Vector3d(d[0], d[1], d[2]).normalized();
  // Zero roll: Y horizontal (z x X), or the machine's y for a vertical X (plan-format.md).
  Eigen::Vector3d ey0 = Eigen::Vector3d::UnitZ().cross(ex);
  ey0 = ey0.norm() < 1e-9 ? Eigen::Vector3d::UnitY() : ey0.normalized();
  const double roll = degToRad(pose.at("roll").get<double>());
  // Rodrigues: ey0 turned by roll about ex.
  const Eigen::Vector3d ey = ey0 * std::cos(roll) + ex.cross(ey0) * std::sin(roll) +
                             ex * ex.dot(ey0) * (1 - std::cos(roll));
  const Eigen::Vector3d ez = ex.cross(ey);
  return ex * W[0] + ey * W[1] + ez * W[2] + Eigen::Vector3d(c[0], c[1], c[2]);
}

Eigen::VectorXd jointsFromFile(const Machine& machine, const json& joints) {
  Eigen::VectorXd q(machine.jointCount());
  for (int i = 0; i < q.size(); ++i) {
    q[i] = fromFileUnit(jointQuantity(machine.mechanism->jointKind(i)), joints.at(i).get<double>());
  }
  return q;
}

std::vector<std::string> plansWithReadings() {
  std::vector<std::string> out;
  for (const auto& entry : fs::directory_iterator(ARTCAL_PLANS_DIR)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".json" || name.ends_with(".spec.json") ||
        name.ends_with(".machine.json")) {
      continue;
    }
    out.push_back(entry.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The drawing's skeleton (Mechanism::skeleton) starts at the machine origin and, for the arms,
// ends at the probe; a CMM's ends at its quill, each segment along one axis.
void expectSkeletonEndsAtTheProbe(const Machine& machine, const Eigen::VectorXd& q,
                                  const Eigen::VectorXd& x) {
  const std::vector<Eigen::VectorXd> skeleton = machine.mechanism->skeleton(machine.nominal, q);
  const std::string model = machine.mechanism->modelName();
  if (model == "hexapod") return;  // legs and platform: not a path to the probe
  ASSERT_GE(skeleton.size(), 2u) << model;
  EXPECT_LT(skeleton.front().norm(), 1e-12) << model;
  if (model == "cartesian") {
    ASSERT_EQ(skeleton.size(), static_cast<std::size_t>(machine.jointCount()) + 1);
    for (int k = 0; k < machine.jointCount(); ++k) {
      EXPECT_NEAR((skeleton[k + 1] - skeleton[k]).norm(), std::abs(q[k]), 1e-9);
    }
    return;
  }
  EXPECT_LT((skeleton.back() - x).norm(), 1e-9) << model;
}

void expectReadingsOnFeatures(const std::string& path) {
  SCOPED_TRACE(path);
  const Plan plan = loadPlan(path);
  const json document = readJsonFile(path);
  const auto run = runCli("procedure --json " + path);
  ASSERT_EQ(run.status, 0);
  const json procedure = json::parse(run.out);
  const Machine& machine = plan.machine;
  ASSERT_EQ(procedure.at("placements").size(), plan.placements.size());
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const Placement& placement = plan.placements[j];
    const json& listed = procedure["placements"][j];
    const json& pose = listed.at("pose");
    if (placement.pose) {  // the plan's own pose, as written
      const json& written = document["placements"][j]["pose"];
      EXPECT_EQ(pose.at("source"), "plan");
      EXPECT_EQ(pose.at("center"), written.at("center"));
    }
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    EXPECT_EQ(listed.at("artifact"), artifact.id);
    ASSERT_EQ(listed.at("readings").size(), placement.measurements.size());
    for (std::size_t k = 0; k < placement.measurements.size(); ++k) {
      const json& reading = listed["readings"][k];
      const Measurement& m = placement.measurements[k];
      ASSERT_EQ(reading.at("feature").get<int>(), m.feature);
      ASSERT_EQ(reading.at("stylus").get<int>(), m.stylus);
      const Eigen::VectorXd feature = placeByPose(pose, artifact.features.col(m.feature));
      const Eigen::VectorXd q = jointsFromFile(machine, reading.at("joints"));
      EXPECT_TRUE(machine.withinLimits(q)) << "placement " << j << " reading " << k;
      Eigen::VectorXd x;
      ASSERT_EQ(machine.mechanism->forwardStylus(m.stylus, machine.nominal, q, x),
                ForwardStatus::Ok);
      // A table-spindle ball bar's spindle ball is the bar's length from the table ball.
      const double off = artifact.plane.shape == PlaneShape::TableBall ? artifact.plane.length : 0.0;
      EXPECT_LT(std::abs((x - feature).norm() - off), 1e-9) << "placement " << j << " reading " << k;
      expectSkeletonEndsAtTheProbe(machine, q, x);
    }
  }
}

TEST(Procedure, EveryReadingOfEveryPlanLandsOnItsPlacedFeature) {
  const std::vector<std::string> plans = plansWithReadings();
  ASSERT_GE(plans.size(), 20u);
  for (const std::string& path : plans) expectReadingsOnFeatures(path);
}

// A machine tool's probing cycle commands the rotary axes: the procedure keeps them where the
// plan has them (C at 240 deg stays 240, not its -120 deg twin) and solves the slides; the table
// names the axes X, Y, Z, A, C and a sphere's placement by its centre alone.
TEST(Procedure, AMachineToolsRotaryPositionsAreThePlannedOnes) {
  const std::string path = test_support::planFile("machine-tool-trunnion-2spheres.json");
  const json document = readJsonFile(path);
  const auto run = runCli("procedure --json " + path);
  ASSERT_EQ(run.status, 0);
  const json procedure = json::parse(run.out);
  int at240 = 0;
  for (std::size_t j = 0; j < document["placements"].size(); ++j) {
    const json& planned = document["placements"][j]["measurements"];
    const json& listed = procedure["placements"][j]["readings"];
    ASSERT_EQ(listed.size(), planned.size());
    for (std::size_t k = 0; k < planned.size(); ++k) {
      for (int axis = 0; axis < 5; ++axis) {
        EXPECT_NEAR(listed[k]["joints"][axis].get<double>(),
                    planned[k]["joints"][axis].get<double>(), 1e-9)
            << j << " " << k << " " << axis;
      }
      at240 += planned[k]["joints"][4].get<double>() == 240.0;
    }
  }
  EXPECT_EQ(at240, 6);
  const auto text = runCli("procedure " + path);
  ASSERT_EQ(text.status, 0);
  EXPECT_NE(text.out.find("         X mm          Y mm          Z mm          A deg         C deg"),
            std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("centre [150.000, 0.000, 50.000] mm (the sphere's centre in the "
                          "workpiece frame)"),
            std::string::npos);
  EXPECT_EQ(text.out.find("direction"), std::string::npos);
  EXPECT_EQ(text.out.find("nan"), std::string::npos);
}

// A reading off its feature sends the procedure through the inverse kinematics, which must put
// the reading's OWN stylus on the feature: the CMM plan with two styli, every reading moved by
// 0.02 mm along each axis. The target and the planned offset are checked against the forward
// kinematics of that stylus and the feature placed here by the plan file's pose.
TEST(Procedure, TheInverseKinematicsPutsTheReadingsOwnStylusOnTheFeature) {
  const std::string path = test_support::planFile("cmm-plate-2styli-optimized.json");
  Plan plan = loadPlan(path);
  const json document = readJsonFile(path);
  const Machine& machine = plan.machine;
  ASSERT_EQ(machine.mechanism->stylusCount(), 2);
  for (Placement& placement : plan.placements) {
    for (Measurement& m : placement.measurements) m.joints.array() += 0.02;
  }
  const Procedure procedure = operatorProcedure(plan);
  ASSERT_EQ(procedure.placements.size(), plan.placements.size());
  int second_stylus = 0;
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const Placement& placement = plan.placements[j];
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    const json& pose = document["placements"][j]["pose"];
    for (std::size_t k = 0; k < placement.measurements.size(); ++k) {
      SCOPED_TRACE("placement " + std::to_string(j) + " reading " + std::to_string(k));
      const Measurement& m = placement.measurements[k];
      const ProcedureReading& r = procedure.placements[j].readings[k];
      ASSERT_EQ(r.stylus, m.stylus);
      second_stylus += m.stylus == 1;
      const Eigen::VectorXd feature = placeByPose(pose, artifact.features.col(m.feature));
      EXPECT_LT((r.position - feature).norm(), 1e-9);
      Eigen::VectorXd x;
      ASSERT_EQ(machine.mechanism->forwardStylus(m.stylus, machine.nominal, m.joints, x),
                ForwardStatus::Ok);
      EXPECT_NEAR(r.planned_offset, (x - feature).norm(), 1e-9);
      EXPECT_GT(r.planned_offset, 1e-3);  // the inverse kinematics ran
      ASSERT_EQ(machine.mechanism->forwardStylus(m.stylus, machine.nominal, r.target, x),
                ForwardStatus::Ok);
      EXPECT_LT((x - feature).norm(), 1e-8);
    }
  }
  EXPECT_GE(second_stylus, 9);
}

TEST(Procedure, PosturesCountTheReadingsOfEachFeature) {
  // The 6-axis arm reads each ball of each bar in 3 postures: 0, 1, 2 per feature.
  const std::string path = test_support::planFile("aacmm-6axis-3bars.json");
  const json procedure = json::parse(runCli("procedure --json " + path).out);
  for (const json& placement : procedure.at("placements")) {
    std::map<int, std::vector<int>> postures;
    for (const json& r : placement.at("readings")) {
      postures[r.at("feature").get<int>()].push_back(r.at("posture").get<int>());
    }
    EXPECT_EQ(postures.size(), 2u);
    for (const auto& [feature, seen] : postures) EXPECT_EQ(seen, (std::vector<int>{0, 1, 2}));
  }
}

// One numbering (issue 20): verify's largest deviations name a reading's posture as the procedure
// does (from 0, the k-th reading of the feature in its placement), for the same reading.
TEST(Procedure, VerifyNamesThePostureTheProcedureGivesTheReading) {
  const Plan plan = loadPlan(test_support::planFile("aacmm-6axis-3bars.json"));
  const Procedure procedure = operatorProcedure(plan);
  Eigen::VectorXd p = plan.machine.nominal;
  for (int i = 0; i < p.size(); ++i) p[i] += 1e-3 * std::sin(1.0 + i);  // deviations differ
  const json verify = verificationToJson(plan, verifyMachine(plan, p, std::nullopt));
  const json& largest = verify.at("verify").at("largest_deviations");
  ASSERT_FALSE(largest.empty());
  std::set<int> postures;
  for (const json& entry : largest) {
    const auto j = entry.at("placement").get<std::size_t>();
    const auto k = entry.at("measurement").get<std::size_t>();
    const ProcedureReading& reading = procedure.placements.at(j).readings.at(k);
    EXPECT_EQ(entry.at("posture").get<int>(), reading.posture) << j << " " << k;
    EXPECT_EQ(entry.at("feature").get<int>(), reading.feature) << j << " " << k;
    postures.insert(reading.posture);
  }
  EXPECT_EQ(*postures.begin(), 0);
}

TEST(Procedure, CsvHasOneRowPerReadingWithUnitsInTheHeader) {
  const std::string path = test_support::planFile("paper-2r-5bars.json");
  const auto run = runCli("procedure --csv " + path);
  ASSERT_EQ(run.status, 0);
  std::istringstream lines(run.out);
  std::string header, line;
  std::getline(lines, header);
  EXPECT_EQ(header, "placement,artifact,reading,feature,posture,stylus,x_mm,y_mm,q1_deg,q2_deg");
  int rows = 0;
  while (std::getline(lines, line)) ++rows;
  EXPECT_EQ(rows, 10);
  const auto table = runCli("procedure " + path);
  EXPECT_EQ(table.status, 0);
  EXPECT_NE(table.out.find("Placement 4: bar80 (ball_bar) at centre"), std::string::npos);
}

// An instrument's station: each reading is a target position of its own, without the feature
// and posture columns of an artifact; one row per reading, the joints those of the plan.
TEST(Procedure, AStationListsEachReadingsTargetPosition) {
  const std::string path = test_support::planFile("tracker-arm6-2stations.json");
  const auto table = runCli("procedure " + path);
  ASSERT_EQ(table.status, 0);
  EXPECT_NE(table.out.find("Placement station 1: tracker (instrument station) at centre"),
            std::string::npos)
      << table.out;
  EXPECT_NE(table.out.find("\n  reading  target position mm "), std::string::npos) << table.out;
  EXPECT_EQ(table.out.find("feature  posture"), std::string::npos) << table.out;
  std::istringstream lines(table.out);
  int rows = 0;
  for (std::string line; std::getline(lines, line);)
    rows += line.find("  [") != std::string::npos && line.find("Placement") == std::string::npos;
  EXPECT_EQ(rows, 50);
  const Plan plan = loadPlan(path);
  const json procedure = json::parse(runCli("procedure --json " + path).out);
  const json& first = procedure["placements"][0]["readings"][0]["joints"];
  for (int i = 0; i < 6; ++i)
    EXPECT_NEAR(first[static_cast<std::size_t>(i)].get<double>(),
                plan.placements[0].measurements[0].joints[i] * 180.0 / std::numbers::pi, 1e-6);
}

TEST(Procedure, BadInputIsExitStatusTwoWithOneLine) {
  const auto run = runCli("procedure /nonexistent/plan.json", test_support::Stderr::Only);
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.out.rfind("error: /nonexistent/plan.json", 0), 0u) << run.out;
}

}  // namespace procedure_test
}  // namespace artcal
