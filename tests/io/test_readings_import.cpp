// `artcal import-readings` (docs/plan-format.md, "A plan from a folder of CSV files") on the real
// MUKCa readings of two robots, and the plan-file features it relies on: placement names, CSV
// readings checked against the joint limits with the file and row named.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <tuple>

#include "artcal/internal.hpp"
#include "artcal/io/readings_import.hpp"
#include "cli_runner.hpp"
#include "temp_folder.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace readings_import_test {

namespace fs = std::filesystem;
using nlohmann::json;
using test_support::runCli;
using test_support::Stderr;
using test_support::testDataFile;

class ImportFolder : public test_support::TempFolder {
 protected:
  ImportFolder() : TempFolder("import") {}
};

std::string mukca(const std::string& name) {
  return testDataFile("mukca/mukca/" + name);
}

/// Non-blank lines of a file: MUKCa's CSV files have no header, one posture per line.
std::size_t rowsOf(const fs::path& file) {
  std::ifstream in(file);
  std::size_t rows = 0;
  for (std::string line; std::getline(in, line);)
    rows += line.find_first_not_of(" \t\r") != std::string::npos;
  return rows;
}

/// The tool positions of a MUKCa robot folder, in name order, and its hole_<k>.csv rows.
std::pair<std::vector<std::string>, std::size_t> positionsAndRows(const std::string& robot) {
  std::set<std::string> names;
  std::size_t rows = 0;
  for (const auto& entry : fs::directory_iterator(mukca(robot))) {
    names.insert(entry.path().filename().string());
    for (const char* hole : {"hole_0.csv", "hole_1.csv"}) rows += rowsOf(entry.path() / hole);
  }
  return {{names.begin(), names.end()}, rows};
}

/// `import-readings` of a MUKCa robot into dir/NAME.json; the exit status.
int importRobot(const ImportFolder& folder, const std::string& robot, const std::string& urdf,
                const std::string& base, const std::string& extra = "") {
  return runCli("import-readings " + mukca(robot) + " --urdf " + mukca("urdf/" + urdf) +
                " --base " + base + " --tip ball_link --ball-bar 50 -o " +
                folder.path(robot + ".json") + " " + extra)
      .status;
}

/// The plan with only the named placements kept, written to `out`.
std::string keepPlacements(const std::string& plan_path, const std::set<std::string>& names,
                           const std::string& out) {
  json plan = readJsonFile(plan_path);
  json kept = json::array();
  for (const json& p : plan["placements"])
    if (names.count(p["name"].get<std::string>())) kept.push_back(p);
  plan["placements"] = kept;
  std::ofstream(out) << plan.dump(1);
  return out;
}

TEST_F(ImportFolder, PandaFolderBecomesAPlanNamedAfterItsPositions) {
  ASSERT_EQ(importRobot(*this, "panda_2", "panda.urdf", "panda_link0"), 0);
  const auto [positions, rows] = positionsAndRows("panda_2");
  const json document = readJsonFile(path("panda_2.json"));
  EXPECT_EQ(document["machine"]["calibrate"], "identifiable");
  EXPECT_EQ(document["noise"]["probe"], 0.1);
  EXPECT_EQ(document["artifacts"]["bar"]["length"], 50.0);
  // Loads as a plan (the nominal machine's plausibility is check's and calibrate's to judge).
  const Plan plan = parsePlan(document, path("panda_2.json"), true, false);
  ASSERT_EQ(plan.placements.size(), positions.size());
  std::size_t readings = 0;
  for (std::size_t j = 0; j < positions.size(); ++j) {
    EXPECT_EQ(plan.placements[j].name, positions[j]);
    EXPECT_EQ(placementLabel(plan.placements, j), positions[j]);
    readings += plan.placements[j].measurements.size();
  }
  EXPECT_EQ(readings, rows);  // every posture of every hole file, the pose files ignored
  EXPECT_EQ(plan.machine.jointCount(), 7);
  // A reading is the CSV row in rad: row 1 of front_center/hole_0.csv, read here independently.
  std::ifstream first(mukca("panda_2/front_center/hole_0.csv"));
  std::string line;
  std::getline(first, line);
  const std::size_t fc = static_cast<std::size_t>(
      std::find(positions.begin(), positions.end(), "front_center") - positions.begin());
  const Measurement& m = plan.placements[fc].measurements.front();
  EXPECT_EQ(m.feature, 0);
  EXPECT_EQ(m.csv_row, 1);
  EXPECT_NEAR(m.joints[0], std::stod(line.substr(0, line.find(','))), 1e-15);
}

// The readings are of the ball, 30 mm below panda_hand_tcp and some 130 mm beyond the flange:
// imported to the flange (--tip panda_link8) the nominal machine misses the bar by the tool.
// check names the cause a URDF user meets besides units: the tip link is not the ball's centre.
// A planar arm's plan in the wrong units gets no such hint (it has no URDF tip).
TEST_F(ImportFolder, ATipAtTheFlangeIsNamedAsAPossibleCauseWhenTheReadingsMissTheBar) {
  const std::string plan = path("panda-flange.json");
  ASSERT_EQ(runCli("import-readings " + mukca("panda_2") + " --urdf " + mukca("urdf/panda.urdf") +
                   " --base panda_link0 --tip panda_link8 --ball-bar 50 -o " + plan)
                .status,
            0);
  const auto check = runCli("check " + plan, Stderr::Only);
  EXPECT_EQ(check.status, 2);
  EXPECT_NE(check.out.find("off the artifact's features after the best rigid fit"),
            std::string::npos)
      << check.out;
  EXPECT_NE(check.out.find("and that the machine's tip is the ball's centre (a URDF chain's --tip "
                           "link: a tool beyond the flange needs a fixed joint of its own in the "
                           "URDF; serial-dh: its probe)"),
            std::string::npos)
      << check.out;
  // The same readings to the ball pass check.
  ASSERT_EQ(importRobot(*this, "panda_2", "panda.urdf", "panda_link0"), 0);
  EXPECT_EQ(runCli("check " + path("panda_2.json"), Stderr::Only).status, 0);
  // Degrees read as radians on the planar arm: the units, and no word of a tip link.
  json twor = readJsonFile(testDataFile("ref-2r-5bars.json"));
  for (json& placement : twor["placements"])
    for (json& m : placement["measurements"])
      for (json& q : m["joints"]) q = q.get<double>() * 3.0;
  std::ofstream(path("2r-scaled.json")) << twor.dump();
  const auto scaled = runCli("check " + path("2r-scaled.json"), Stderr::Only);
  EXPECT_EQ(scaled.status, 2);
  EXPECT_NE(scaled.out.find("check the units"), std::string::npos) << scaled.out;
  EXPECT_EQ(scaled.out.find("tip"), std::string::npos) << scaled.out;
}

TEST_F(ImportFolder, CalibrateRunsOnTheImportedPandaPlan) {
  ASSERT_EQ(importRobot(*this, "panda_2", "panda.urdf", "panda_link0"), 0);
  const std::string plan =
      keepPlacements(path("panda_2.json"), {"front_center"}, path("panda-fc.json"));
  const auto run = runCli("calibrate --json " + plan);
  ASSERT_TRUE(run.status == 0 || run.status == 1) << run.status;  // ran: converged or not
  const json out = json::parse(run.out);
  EXPECT_TRUE(out.contains("converged"));
  EXPECT_FALSE(out["parameters"].empty());
  for (const json& g : out["gross_errors"]) EXPECT_EQ(g["name"], "front_center");
}

TEST_F(ImportFolder, Gen3LiteReadingsPastTheUrdfLimitsWidenThemWithAWarning) {
  const auto run = runCli(
      "import-readings " + mukca("dinova_1") + " --urdf " + mukca("urdf/gen3lite.urdf") +
          " --base kinova_base_link --tip ball_link --ball-bar 50 -o " + path("dinova_1.json"),
      Stderr::Only);
  ASSERT_EQ(run.status, 0) << run.out;
  // Joint 6 reads up to 157.128 deg (front, left) against the URDF's 2.09 rad = 119.748 deg.
  EXPECT_NE(run.out.find("warning: joint 6: readings reach"), std::string::npos) << run.out;
  const json document = readJsonFile(path("dinova_1.json"));
  const auto [positions, rows] = positionsAndRows("dinova_1");
  const Plan plan = parsePlan(document, path("dinova_1.json"), true, false);
  ASSERT_EQ(plan.placements.size(), positions.size());
  std::size_t readings = 0;
  for (const Placement& p : plan.placements) readings += p.measurements.size();
  EXPECT_EQ(readings, rows);
  const double limit = document["machine"]["joint_limits"][5][1].get<double>();
  EXPECT_GT(limit, 152.0);
  EXPECT_LT(limit, 158.0);
  EXPECT_NEAR(document["machine"]["joint_limits"][0][1].get<double>(),
              2.68 * 180.0 / std::numbers::pi, 1e-9);  // the others as the URDF says
}

TEST_F(ImportFolder, CalibrateRunsOnTheImportedGen3LitePlan) {
  ASSERT_EQ(importRobot(*this, "dinova_1", "gen3lite.urdf", "kinova_base_link"), 0);
  const std::string plan =
      keepPlacements(path("dinova_1.json"), {"front", "left", "lower_left"}, path("dinova-3.json"));
  const auto run = runCli("calibrate --json " + plan);
  ASSERT_TRUE(run.status == 0 || run.status == 1) << run.status;
  const json out = json::parse(run.out);
  EXPECT_TRUE(out.contains("converged"));
  // The residuals and gross errors name the placements by their folders.
  std::set<std::string> named;
  for (const json& r : out["residuals"]) named.insert(r["name"].get<std::string>());
  EXPECT_EQ(named, (std::set<std::string>{"front", "left", "lower_left"}));
  const auto table = runCli("calibrate " + plan);
  EXPECT_NE(table.out.find("    front        0        0"), std::string::npos);
}

TEST_F(ImportFolder, KeptLimitsRefuseTheReadingNamingTheCsvFileAndRow) {
  const auto run =
      runCli("import-readings " + mukca("dinova_1") + " --urdf " + mukca("urdf/gen3lite.urdf") +
                 " --base kinova_base_link --tip ball_link --ball-bar 50 --keep-limits "
                 "-o " +
                 path("dinova_1.json"),
             Stderr::Only);
  EXPECT_EQ(run.status, 2);
  // front/hole_0.csv row 13, joint 6: 2.43 rad = 139.23 deg > 119.75 deg (read from the file).
  EXPECT_NE(run.out.find("dinova_1/front/hole_0.csv: line 13 (row 13): reading 139.23"),
            std::string::npos)
      << run.out;
  EXPECT_EQ(run.out.find("/placements/"), std::string::npos) << run.out;
  EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1) << run.out;
  EXPECT_FALSE(fs::exists(path("dinova_1.json")));
}

/// A planar 2R machine file and the 2R reference plan's first placement as readings.
struct TwoArm {
  json plan = readJsonFile(testDataFile("ref-2r-5bars.json"));
  std::vector<std::vector<double>> readings(int placement, int feature) const {
    std::vector<std::vector<double>> out;
    for (const json& m : plan["placements"][placement]["measurements"])
      if (m["feature"] == feature) out.push_back(m["joints"].get<std::vector<double>>());
    return out;
  }
};

std::string csvText(const std::vector<std::vector<double>>& rows, double scale,
                    const std::string& header) {
  std::ostringstream out;
  out.precision(17);
  if (!header.empty()) out << header << "\n";
  for (const auto& row : rows) out << row[0] * scale << "," << row[1] * scale << "\n";
  return out.str();
}

TEST_F(ImportFolder, GeneralLayoutTakesTheUnitsFromTheHeader) {
  const TwoArm arm;
  json machine = arm.plan["machine"];
  machine["joint_limits"] = {{-180, 180}, {-170, 170}};
  write("machine.json", machine.dump());
  const double rad = std::numbers::pi / 180.0;
  write("readings/b/feature_0.csv", csvText(arm.readings(0, 0), rad, "t1 [rad], t2 [rad]"));
  write("readings/b/feature_1.csv", csvText(arm.readings(0, 1), 1.0, "t1_deg,t2_deg"));
  write("readings/a/feature_0.csv", csvText(arm.readings(1, 0), 1.0, "t1 (deg), t2 (deg)"));
  write("readings/a/feature_1.csv", csvText(arm.readings(1, 1), 1.0, "t1_deg,t2_deg"));
  write("readings/a/notes.txt", "not a feature file\n");
  const auto run =
      runCli("import-readings " + path("readings") + " --machine " + path("machine.json") +
             " --ball-bar 80 --probe 0.005 --encoder 0.001" + " -o " + path("plan.json"));
  ASSERT_EQ(run.status, 0);
  const Plan plan = loadPlan(path("plan.json"));
  ASSERT_EQ(plan.placements.size(), 2u);
  EXPECT_EQ(plan.placements[0].name, "a");  // folders in name order
  EXPECT_EQ(plan.placements[1].name, "b");
  EXPECT_TRUE(plan.machine.calibrate_identifiable);
  EXPECT_DOUBLE_EQ(plan.noise.probe, 0.005);
  // Placement "b" holds the reference's placement 0: the same readings, whatever the file unit.
  const Plan reference = loadPlan(testDataFile("ref-2r-5bars.json"));
  const auto& expected = reference.placements[0].measurements;
  const auto& actual = plan.placements[1].measurements;
  ASSERT_EQ(actual.size(), expected.size());
  for (const Measurement& e : expected) {
    const bool found = std::any_of(actual.begin(), actual.end(), [&](const Measurement& a) {
      return a.feature == e.feature && (a.joints - e.joints).cwiseAbs().maxCoeff() < 1e-14;
    });
    EXPECT_TRUE(found);
  }
  // A header without units is refused, naming the file.
  write("bare/p/feature_0.csv", csvText(arm.readings(0, 0), 1.0, "t1,t2"));
  const auto bare = runCli("import-readings " + path("bare") + " --machine " +
                               path("machine.json") + " --ball-bar 80 -o " + path("bare.json"),
                           Stderr::Only);
  EXPECT_EQ(bare.status, 2);
  EXPECT_NE(bare.out.find("feature_0.csv: line 1: expected a header naming each column's unit"),
            std::string::npos)
      << bare.out;
}

// One file takes one angle unit and one length unit (docs/plan-format.md): a header naming deg
// beside rad, or mm beside m, is refused (exit 2, the file and line 1 named), since no single
// conversion reads it; the same file with one unit per kind is accepted.
TEST_F(ImportFolder, AHeaderInMixedUnitsIsRefused) {
  const TwoArm arm;
  json machine = arm.plan["machine"];
  machine["joint_limits"] = {{-180, 180}, {-170, 170}};
  write("machine.json", machine.dump());
  const auto import = [&](const std::string& folder, const std::string& header) {
    write(folder + "/p/feature_0.csv", csvText(arm.readings(0, 0), 1.0, header));
    write(folder + "/p/feature_1.csv", csvText(arm.readings(0, 1), 1.0, "t1_deg,t2_deg"));
    return runCli("import-readings " + path(folder) + " --machine " + path("machine.json") +
                      " --ball-bar 80 -o " + path(folder + ".json"),
                  Stderr::Only);
  };
  EXPECT_EQ(import("same", "t1_deg,t2_deg").status, 0);
  for (const std::string header : {"t1_deg,t2_rad", "t1 [mm],t2 [m]", "t1_m,t2_mm"}) {
    const auto run = import("mixed", header);
    EXPECT_EQ(run.status, 2) << header;
    EXPECT_NE(run.out.find("feature_0.csv: line 1: columns in mixed units"), std::string::npos)
        << header << ": " << run.out;
  }
}

/// A station's readings of the instrument reference plan as CSV text: the joints times
/// `joint_scale`, the point times `point_scale` (a pose's orientation, its last 3 of 6
/// coordinates, times `orientation_scale`), under `header`.
std::string stationCsv(const json& station, double joint_scale, double point_scale,
                       const std::string& header, double orientation_scale = 1.0) {
  std::string text = header.empty() ? "" : header + "\n";
  char number[40];
  for (const json& m : station["measurements"]) {
    std::string row;
    for (const json& q : m["joints"]) {
      std::snprintf(number, sizeof number, "%.17g,", q.get<double>() * joint_scale);
      row += number;
    }
    const json& point = m["point"];
    for (std::size_t k = 0; k < point.size(); ++k) {
      const double scale = k < 3 ? point_scale : orientation_scale;
      std::snprintf(number, sizeof number, "%.17g,", point[k].get<double>() * scale);
      row += number;
    }
    row.back() = '\n';
    text += row;
  }
  return text;
}

// An instrument's export: one CSV file per station, each row the joints then x, y, z; the units
// from the header or from --unit / --point-unit. The plan holds the reference plan's readings.
TEST_F(ImportFolder, InstrumentStationsFromOneCsvFileEach) {
  const json reference = readJsonFile(testDataFile("ref-instrument-arm6-2stations.json"));
  write("machine.json", reference["machine"].dump());
  const double rad = std::numbers::pi / 180.0;
  write("tracker/station_a.csv",
        stationCsv(reference["placements"][0], 1.0, 1e-3,
                   "j1_deg,j2_deg,j3_deg,j4_deg,j5_deg,j6_deg,x_m,y_m,z_m"));
  write("tracker/station_b.csv",
        stationCsv(reference["placements"][1], rad, 1.0,
                   "j1 [rad],j2 [rad],j3 [rad],j4 [rad],j5 [rad],j6 [rad],x (mm),y (mm),z (mm)"));
  write("tracker/notes.txt", "not a station\n");
  const auto run = runCli("import-readings " + path("tracker") + " --machine " +
                          path("machine.json") + " --instrument 0.02 -o " + path("plan.json"));
  ASSERT_EQ(run.status, 0) << run.out;
  const Plan plan = loadPlan(path("plan.json"));
  const Plan expected = loadPlan(testDataFile("ref-instrument-arm6-2stations.json"));
  ASSERT_EQ(plan.placements.size(), 2u);
  EXPECT_EQ(plan.placements[0].name, "station_a");  // files in name order, named by their stem
  EXPECT_EQ(plan.placements[1].name, "station_b");
  EXPECT_EQ(artifactTypeName(plan.artifacts.at(0)), "instrument");
  EXPECT_TRUE(plan.machine.calibrate_identifiable);
  EXPECT_TRUE(plan.noise.estimate_probe);  // beside the instrument, the robot's scatter estimated
  for (std::size_t j = 0; j < 2; ++j) {
    const auto& mine = plan.placements[j].measurements;
    const auto& theirs = expected.placements[j].measurements;
    ASSERT_EQ(mine.size(), theirs.size());
    for (std::size_t i = 0; i < mine.size(); ++i) {
      EXPECT_LT((mine[i].joints - theirs[i].joints).cwiseAbs().maxCoeff(), 1e-14);
      EXPECT_LT((mine[i].point - theirs[i].point).cwiseAbs().maxCoeff(), 1e-9);
    }
  }
  // Nominal points: the calibration fits them to rounding.
  const auto calibrated = runCli("calibrate --json " + path("plan.json"));
  ASSERT_EQ(calibrated.status, 0);
  EXPECT_LT(json::parse(calibrated.out)["chi2"].get<double>(), 1e-12);

  // A file without units and none given: refused, naming it; --unit and --point-unit state them.
  write("bare/s1.csv", stationCsv(reference["placements"][0], 1.0, 1e-3, ""));
  const std::string bare = "import-readings " + path("bare") + " --machine " +
                           path("machine.json") + " --instrument 0.02 -o " + path("bare.json");
  const auto refused = runCli(bare, Stderr::Only);
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.out.find("s1.csv: line 1: expected a header naming each column's unit"),
            std::string::npos)
      << refused.out;
  ASSERT_EQ(runCli(bare + " --unit deg --point-unit m").status, 0);
  const Plan stated = loadPlan(path("bare.json"));
  ASSERT_EQ(stated.placements.size(), 1u);
  EXPECT_LT(
      (stated.placements[0].measurements[3].point - expected.placements[0].measurements[3].point)
          .cwiseAbs()
          .maxCoeff(),
      1e-9);
}

// A 6-DOF tracker's export (--instrument-angle): each row the joints, then x, y, z and the
// orientation as a rotation vector, in the units the header names (rx_rad) or --orientation-unit
// states. The simulated pose plan's readings, exported per station and imported, calibrate as
// the plan itself does.
TEST_F(ImportFolder, PoseStationsRoundTripToTheSameCalibration) {
  const auto simulated = runCli("simulate " + test_support::planFile("tracker-arm6-pose.json") +
                                " --truth " + test_support::planFile("tracker-arm6/truth.json") +
                                " --seed 5 -o " + path("sim.json"));
  ASSERT_EQ(simulated.status, 0) << simulated.out;
  json original = readJsonFile(path("sim.json"));
  original["noise"]["probe"] = "estimate";  // as import-readings writes it beside an instrument
  std::ofstream(path("sim.json")) << original.dump(1);
  write("machine.json", original["machine"].dump());
  const double rad = std::numbers::pi / 180.0;
  const std::string angles = "j1_deg,j2_deg,j3_deg,j4_deg,j5_deg,j6_deg";
  write("poses/station_a.csv", stationCsv(original["placements"][0], 1.0, 1e-3,
                                          angles + ",x_m,y_m,z_m,rx_rad,ry_rad,rz_rad", rad));
  write("poses/station_b.csv", stationCsv(original["placements"][1], rad, 1.0,
                                          "j1 [rad],j2 [rad],j3 [rad],j4 [rad],j5 [rad],j6 [rad],"
                                          "x (mm),y (mm),z (mm),rx (deg),ry (deg),rz (deg)"));
  const std::string noise =
      " --encoder " + std::to_string(original["noise"]["encoder"].get<double>());
  const std::string import = "import-readings " + path("poses") + " --machine " +
                             path("machine.json") + " --instrument 0.02 --keep-calibrate" + noise;
  const auto imported = runCli(import + " --instrument-angle 0.005 -o " + path("plan.json"));
  ASSERT_EQ(imported.status, 0) << imported.out;
  const json plan = readJsonFile(path("plan.json"));
  EXPECT_EQ(
      plan["artifacts"]["instrument"],
      json(
          {{"type", "instrument"}, {"measures", "pose"}, {"noise", 0.02}, {"noise_angle", 0.005}}));
  EXPECT_EQ(plan["placements"][0]["measurements"][0]["orientation_unit"], "rad");
  EXPECT_EQ(plan["placements"][1]["measurements"][0]["orientation_unit"], "deg");
  EXPECT_EQ(plan["noise"]["probe"], "estimate");

  const auto mine = runCli("calibrate --json " + path("plan.json"));
  const auto theirs = runCli("calibrate --json " + path("sim.json"));
  ASSERT_EQ(mine.status, 0) << mine.out;
  ASSERT_EQ(theirs.status, 0) << theirs.out;
  const json a = json::parse(mine.out), b = json::parse(theirs.out);
  EXPECT_EQ(a["dof"], b["dof"]);
  EXPECT_EQ(a["dof"].get<int>(), 2 * 25 * 6 - 6 * 2 - static_cast<int>(b["parameters"].size()));
  EXPECT_NEAR(a["chi2"].get<double>(), b["chi2"].get<double>(), 1e-9 * b["chi2"].get<double>());
  EXPECT_NEAR(a["noise_estimate"]["probe"].get<double>(),
              b["noise_estimate"]["probe"].get<double>(), 1e-12);
  ASSERT_EQ(a["parameters"].size(), b["parameters"].size());
  for (std::size_t k = 0; k < a["parameters"].size(); ++k) {
    const json &p = a["parameters"][k], &q = b["parameters"][k];
    EXPECT_EQ(p["name"], q["name"]);
    EXPECT_NEAR(p["estimate"].get<double>(), q["estimate"].get<double>(), 1e-9) << p["name"];
    EXPECT_NEAR(p["u"].get<double>(), q["u"].get<double>(), 1e-12) << p["name"];
  }

  // Pose rows without --instrument-angle, and point rows with it: refused, naming the file.
  const auto no_angle = runCli(import + " -o " + path("bad.json"), Stderr::Only);
  EXPECT_EQ(no_angle.status, 2);
  EXPECT_EQ(no_angle.out.find("station_a.csv: line 1: 6 joint readings then 6 coordinates: a pose"),
            no_angle.out.find("station_a.csv"))
      << no_angle.out;
  EXPECT_NE(no_angle.out.find("give --instrument-angle"), std::string::npos) << no_angle.out;
  EXPECT_EQ(std::count(no_angle.out.begin(), no_angle.out.end(), '\n'), 1);
  const json reference = readJsonFile(testDataFile("ref-instrument-arm6-2stations.json"));
  write("points/s1.csv", stationCsv(reference["placements"][0], 1.0, 1.0, ""));
  const auto points =
      runCli("import-readings " + path("points") + " --machine " + path("machine.json") +
                 " --instrument 0.02 --instrument-angle 0.005 --unit deg -o " + path("bad.json"),
             Stderr::Only);
  EXPECT_EQ(points.status, 2);
  EXPECT_NE(points.out.find("s1.csv: line 1: 6 joint readings then 3 coordinates: a point"),
            std::string::npos)
      << points.out;
  EXPECT_FALSE(fs::exists(path("bad.json")));
  // The plan's orientation_unit: only a pose instrument's, deg or rad; exit 2 at its pointer.
  for (const auto& [measures, unit, message] :
       {std::tuple{"point", "rad", "only a \"pose\" instrument's readings have an orientation"},
        std::tuple{"pose", "grad", "unknown orientation_unit \"grad\" (expected deg or rad)"}}) {
    json bad = plan;
    bad["artifacts"]["instrument"]["measures"] = measures;
    bad["placements"][0]["measurements"][0]["orientation_unit"] = unit;
    // The header names its columns: the entry says "orientation" too; the unit alone is tested.
    bad["placements"][0]["measurements"][0].erase("orientation");
    std::ofstream(path("bad.json")) << bad.dump(1);
    const auto refused = runCli("check " + path("bad.json"), Stderr::Only);
    EXPECT_EQ(refused.status, 2) << measures;
    EXPECT_NE(refused.out.find("bad.json: /placements/0/measurements/0/orientation_unit: " +
                               std::string(message)),
              std::string::npos)
        << refused.out;
  }

  // Without a header the units are stated: --orientation-unit rad reads the first station's rad.
  write("bare/s1.csv", stationCsv(original["placements"][0], 1.0, 1.0, "", rad));
  const std::string bare =
      "import-readings " + path("bare") + " --machine " + path("machine.json") +
      " --instrument 0.02 --instrument-angle 0.005 --unit deg -o " + path("bare.json");
  const auto unstated = runCli(bare);  // the orientation then in deg, as in a plan
  ASSERT_EQ(unstated.status, 0) << unstated.out;
  EXPECT_EQ(readJsonFile(path("bare.json"))["placements"][0]["measurements"][0]["orientation_unit"],
            "deg");
  const auto stated = runCli(bare + " --orientation-unit rad");
  ASSERT_EQ(stated.status, 0) << stated.out;
  const Plan bare_plan = loadPlan(path("bare.json"));
  const Plan expected = loadPlan(path("sim.json"));
  ASSERT_EQ(bare_plan.placements.size(), 1u);
  for (std::size_t i : {0u, 7u, 24u}) {
    const Measurement& m = bare_plan.placements[0].measurements[i];
    const Measurement& e = expected.placements[0].measurements[i];
    EXPECT_LT((m.point - e.point).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT((m.orientation - e.orientation).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST_F(ImportFolder, CsvReadingOutsideTheJointLimitsNamesFileAndRow) {
  const TwoArm arm;
  json plan = arm.plan;
  plan["machine"]["joint_limits"] = {{-180, 180}, {-170, 170}};
  write("p/hole_0.csv", "# t1, t2\n\n10,20\n10,175\n");
  plan["placements"][0]["measurements"] = {{{"feature", 0}, {"csv", "p/hole_0.csv"}}};
  write("plan.json", plan.dump());
  try {
    loadPlan(path("plan.json"));
    FAIL() << "a reading of 175 deg passed joint 2's limits of 170 deg";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path("p/hole_0.csv"));
    EXPECT_EQ(e.pointer(), "line 4 (row 2)");
    EXPECT_NE(std::string(e.what()).find("reading 175 deg of joint 2 is outside its joint_limits"),
              std::string::npos)
        << e.what();
  }
  // Excluded, the row no longer counts.
  plan["placements"][0]["measurements"][0]["exclude_rows"] = {2};
  write("plan.json", plan.dump());
  EXPECT_NO_THROW(parsePlan(readJsonFile(path("plan.json")), path("plan.json"), false, false));
}

TEST_F(ImportFolder, PlacementNamesAreOptionalUniqueAndUsedByVerify) {
  json plan = readJsonFile(testDataFile("ref-2r-5bars.json"));
  plan["placements"][0]["name"] = "near";
  plan["placements"][2]["name"] = "far";
  write("named.json", plan.dump());
  const Plan named = loadPlan(path("named.json"));
  EXPECT_EQ(placementLabel(named.placements, 0), "near");
  EXPECT_EQ(placementLabel(named.placements, 1), "1");
  EXPECT_EQ(placementLabel(named.placements, 2), "far");
  EXPECT_EQ(placementsToJson(named)[2]["name"], "far");
  const auto verify = runCli("verify --json " + path("named.json"));
  ASSERT_EQ(verify.status, 0);
  const json v = json::parse(verify.out)["verify"];
  EXPECT_EQ(v["placements"][0]["name"], "near");
  EXPECT_FALSE(v["placements"][1].contains("name"));
  const auto table = runCli("verify " + path("named.json"));
  EXPECT_NE(table.out.find("\n     near       0"), std::string::npos) << table.out;
  const auto procedure = runCli("procedure " + path("named.json"));
  EXPECT_NE(procedure.out.find("Placement far: "), std::string::npos);
  plan["placements"][1]["name"] = "far";
  write("twice.json", plan.dump());
  const auto twice = runCli("check " + path("twice.json"), Stderr::Only);
  EXPECT_EQ(twice.status, 2);
  EXPECT_NE(twice.out.find("/placements/2/name: placement name \"far\" is also placement 1's"),
            std::string::npos)
      << twice.out;
}

}  // namespace readings_import_test
}  // namespace artcal

namespace artcal {
namespace readings_import_test {

// A probing log of two spheres in one file, a sphere column naming each row's sphere (rows of
// the two interleaved, the column between the axes, a unit-less header word): one placement per
// sphere, named by the column's value in the order they first appear, each reading exactly the
// rows written for it, in file order, each row numbered as in the file (exclude_rows and gross
// errors name the file's rows); the column is not reported as unread; the plan calibrates.
TEST_F(ImportFolder, AProbingLogWithASphereColumnIsOnePlacementPerSphere) {
  const json trunnion = readJsonFile(test_support::planFile("machine-tool-trunnion-2spheres.json"));
  write("mt.json", trunnion["machine"].dump());
  write("sphere.json", json{{"sphere1", trunnion["artifacts"]["sphere1"]}}.dump());
  std::map<std::string, std::vector<std::vector<double>>> written;
  std::vector<std::string> row_sphere;
  std::string log = "X_mm,Y_mm,Sphere,Z_mm,A_deg,C_deg\n";
  const std::size_t n0 = trunnion["placements"][0]["measurements"].size();
  const std::size_t n1 = trunnion["placements"][1]["measurements"].size();
  for (std::size_t r = 0; r < n0 + n1; ++r) {
    // Alternating while both last: s2 first, then s1, ...
    const int j = (r < 2 * std::min(n0, n1)) ? static_cast<int>((r + 1) % 2) : (n0 > n1 ? 0 : 1);
    const std::string name = j == 0 ? "front sphere" : "s2";
    const std::size_t k = written[name].size();
    const json& q =
        trunnion["placements"][static_cast<std::size_t>(j)]["measurements"][k]["joints"];
    written[name].push_back(q.get<std::vector<double>>());
    row_sphere.push_back(name);
    char line[256];
    std::snprintf(line, sizeof line, "%.17g,%.17g,%s,%.17g,%.17g,%.17g\n", q[0].get<double>(),
                  q[1].get<double>(), name.c_str(), q[2].get<double>(), q[3].get<double>(),
                  q[4].get<double>());
    log += line;
  }
  write("probing.csv", log);
  const test_support::CliRun run =
      runCli("import-readings " + path("probing.csv") + " --machine " + path("mt.json") +
                 " --artifact " + path("sphere.json") + " --probe 0.001 -o " + path("plan.json"),
             Stderr::Merge);
  ASSERT_EQ(run.status, 0) << run.out;
  EXPECT_EQ(run.out.find("columns not read"), std::string::npos) << run.out;
  const Plan plan = loadPlan(path("plan.json"));
  ASSERT_EQ(plan.placements.size(), 2u);
  EXPECT_EQ(plan.placements[0].name, "s2");
  EXPECT_EQ(plan.placements[1].name, "front sphere");
  for (const Placement& placement : plan.placements) {
    const auto& rows = written.at(placement.name);
    ASSERT_EQ(placement.measurements.size(), rows.size()) << placement.name;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const Measurement& m = placement.measurements[k];
      EXPECT_EQ(row_sphere[static_cast<std::size_t>(m.csv_row - 1)], placement.name);
      const Eigen::VectorXd expected = jointsFromFile(
          *plan.machine.mechanism, Eigen::Map<const Eigen::VectorXd>(rows[k].data(), 5));
      EXPECT_LT((m.joints - expected).norm(), 1e-12) << placement.name << " " << k;
    }
  }
  EXPECT_EQ(runCli("calibrate " + path("plan.json")).status, 0);
  // A value no row holds is refused at its pointer.
  json document = readJsonFile(path("plan.json"));
  document["placements"][1]["measurements"][0]["rows"]["value"] = "s3";
  write("s3.json", document.dump());
  const test_support::CliRun s3 = runCli("check " + path("s3.json"), Stderr::Only);
  EXPECT_EQ(s3.status, 2);
  EXPECT_NE(s3.out.find("s3.json: /placements/1/measurements/0/rows/value: no row of "),
            std::string::npos)
      << s3.out;
  // A value missing in the column is refused naming the file and line.
  write("gap.csv", "sphere,X_mm,Y_mm,Z_mm,A_deg,C_deg\ns1,1,2,3,4,5\n,1,2,3,4,6\n");
  const test_support::CliRun gap =
      runCli("import-readings " + path("gap.csv") + " --machine " + path("mt.json") +
                 " --artifact " + path("sphere.json") + " -o " + path("gap.json"),
             Stderr::Only);
  EXPECT_EQ(gap.status, 2);
  EXPECT_NE(gap.out.find("gap.csv: line 3: no value in column \"sphere\""), std::string::npos)
      << gap.out;
}

}  // namespace readings_import_test
}  // namespace artcal
