// Readings as other tools export them (issue 29 point 4; docs/plan-format.md "Columns by name"):
// a CSV whose header names its columns (the joints by their URDF names, a marker's x, y, z, other
// columns ignored), orientations as roll-pitch-yaw and quaternions beside rotation vectors,
// prismatic limits widened like revolute ones, and a joint no file reads held at a value.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

#include "artcal/artcal.hpp"
#include "artcal/io/readings_import.hpp"
#include "cli_runner.hpp"
#include "temp_folder.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace named_columns_test {

namespace fs = std::filesystem;
using nlohmann::json;
using test_support::runCli;
using test_support::Stderr;
using test_support::testDataFile;

class NamedColumns : public test_support::TempFolder {
 protected:
  NamedColumns() : TempFolder("named-columns") {}
  /// The MUKCa Panda's chain to its ball (`import-urdf`), written to FOLDER/machine.json.
  nlohmann::json pandaMachine() const {
    const std::string urdf = testDataFile("mukca/mukca/urdf/panda.urdf");
    const auto run = runCli("import-urdf " + urdf + " --base panda_link0 --tip ball_link -o " +
                            path("machine.json"));
    EXPECT_EQ(run.status, 0) << run.out;
    return readJsonFile(path("machine.json"));
  }
};

constexpr double kPi = std::numbers::pi;

/// The plan at `file`, parsed without the nominal machine's plausibility check (readings chosen
/// for their columns, not for a bar's length).
Plan parsed(const std::string& file) {
  return parsePlan(readJsonFile(file), file, true, /*check_plausibility=*/false);
}

std::string number(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

// ---- closed forms, written out here independently of the code under test

using Quaternion = std::array<double, 4>;  // w, x, y, z

Quaternion hamilton(const Quaternion& a, const Quaternion& b) {
  return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
          a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
          a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
          a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}

/// The quaternion of roll, pitch, yaw (rad) about the fixed x, y, z axes: q = qz(yaw) qy(pitch)
/// qx(roll).
Quaternion quaternionOfRpy(double roll, double pitch, double yaw) {
  const Quaternion qx = {std::cos(roll / 2), std::sin(roll / 2), 0, 0};
  const Quaternion qy = {std::cos(pitch / 2), 0, std::sin(pitch / 2), 0};
  const Quaternion qz = {std::cos(yaw / 2), 0, 0, std::sin(yaw / 2)};
  return hamilton(qz, hamilton(qy, qx));
}

/// The rotation vector (rad) of a unit quaternion: angle 2 atan2(|v|, w) about v / |v|.
Eigen::Vector3d rotationVectorOf(const Quaternion& q) {
  const Eigen::Vector3d v(q[1], q[2], q[3]);
  const double s = v.norm();
  if (s == 0.0) return Eigen::Vector3d::Zero();
  const double sign = q[0] < 0 ? -1.0 : 1.0;  // the shorter way round
  return 2.0 * std::atan2(s, sign * q[0]) * sign * v / s;
}

/// The quaternion of a rotation vector (rad).
Quaternion quaternionOf(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle == 0.0) return {1, 0, 0, 0};
  const Eigen::Vector3d axis = w / angle;
  const double s = std::sin(angle / 2);
  return {std::cos(angle / 2), s * axis[0], s * axis[1], s * axis[2]};
}

/// Roll, pitch, yaw (rad) of a unit quaternion, R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Vector3d rpyOf(const Quaternion& q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double r21 = 2 * (y * z + w * x), r22 = 1 - 2 * (x * x + y * y);
  const double r20 = 2 * (x * z - w * y);
  const double r10 = 2 * (x * y + w * z), r00 = 1 - 2 * (y * y + z * z);
  return {std::atan2(r21, r22), std::asin(-r20), std::atan2(r10, r00)};
}

// A known rotation: roll 10, pitch 20, yaw 30 deg. By hand (half angles 5, 10, 15 deg):
// q = qz qy qx = (0.951549, 0.038135, 0.189308, 0.239298) to 6 digits.
TEST(OrientationClosedForms, RollPitchYawOfAKnownRotationMatchesItsQuaternion) {
  const double d = kPi / 180;
  const Quaternion q = quaternionOfRpy(10 * d, 20 * d, 30 * d);
  EXPECT_NEAR(q[0], 0.951549, 1e-6);
  EXPECT_NEAR(q[1], 0.038135, 1e-6);
  EXPECT_NEAR(q[2], 0.189308, 1e-6);
  EXPECT_NEAR(q[3], 0.239298, 1e-6);
  const Eigen::Vector3d rpy = rpyOf(q);
  EXPECT_NEAR(rpy[0], 10 * d, 1e-12);
  EXPECT_NEAR(rpy[1], 20 * d, 1e-12);
  EXPECT_NEAR(rpy[2], 30 * d, 1e-12);
}

/// A plan of the Panda (its URDF's chain to ball_link) and a pose instrument, the readings given
/// by their joints alone (deg): the plan parser sets each to the nominal tip pose.
json pandaPosePlan(const json& machine, const std::vector<Eigen::VectorXd>& joints) {
  json measurements = json::array();
  for (const Eigen::VectorXd& q : joints) {
    json row = json::array();
    for (int i = 0; i < q.size(); ++i) row.push_back(q[i] * 180 / kPi);
    measurements.push_back({{"joints", row}});
  }
  return {
      {"format", "artcal-plan/1"},
      {"name", "panda-pose"},
      {"machine", machine},
      {"noise", {{"probe", 0.1}, {"encoder", 0.0}}},
      {"artifacts",
       {{"instrument",
         {{"type", "instrument"}, {"measures", "pose"}, {"noise", 0.05}, {"noise_angle", 0.01}}}}},
      {"placements",
       json::array(
           {{{"name", "session"}, {"artifact", "instrument"}, {"measurements", measurements}}})}};
}

std::vector<Eigen::VectorXd> pandaPostures(int count) {
  std::mt19937 random(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::VectorXd> out;
  const double range[7] = {2.5, 1.5, 2.5, 1.0, 2.5, 1.5, 2.5};  // rad, inside the limits
  for (int k = 0; k < count; ++k) {
    Eigen::VectorXd q(7);
    for (int i = 0; i < 7; ++i) q[i] = range[i] * u(random);
    q[3] = -1.5 + q[3];       // joint 4 reads [-3.07, -0.07] rad
    q[5] = 1.8 + 0.8 * q[5];  // joint 6 reads [-0.02, 3.75] rad
    out.push_back(q);
  }
  return out;
}

// The same readings exported three ways (orientation as a rotation vector, as roll-pitch-yaw, as
// a quaternion), the marker columns first, the joints by their URDF names in another order than
// the chain's, extra columns and a second marker: each imports to the readings the plan itself
// holds (points to 1e-9 mm, orientations to 1e-9 rad), and the three plans read identically.
TEST_F(NamedColumns, RotationVectorRpyAndQuaternionExportsGiveIdenticalReadings) {
  const std::string urdf = testDataFile("mukca/mukca/urdf/panda.urdf");
  const json machine = pandaMachine();
  const std::vector<Eigen::VectorXd> joints = pandaPostures(20);
  std::ofstream(path("reference.json")) << pandaPosePlan(machine, joints).dump(1);
  const Plan reference = loadPlan(path("reference.json"));
  const auto& readings = reference.placements.at(0).measurements;
  ASSERT_EQ(readings.size(), 20u);

  const std::vector<std::pair<std::string, std::string>> forms = {
      {"rotvec", "hand_rx [deg],hand_ry [deg],hand_rz [deg]"},
      {"rpy", "hand_roll [deg],hand_pitch [deg],hand_yaw [deg]"},
      {"quat", "hand_qw,hand_qx,hand_qy,hand_qz"}};
  for (const auto& [form, orientation] : forms) {
    // Markers first (metres), then the joints in reverse order (rad), a time column, a second
    // marker.
    std::string text = "time,hand_x [m],hand_y [m],hand_z [m]," + orientation;
    for (int i = 7; i >= 1; --i) text += ",panda_joint" + std::to_string(i) + " [rad]";
    text += ",base_x,base_y,base_z\n";
    for (std::size_t k = 0; k < readings.size(); ++k) {
      const Measurement& m = readings[k];
      text += number(0.01 * static_cast<double>(k));
      for (int c = 0; c < 3; ++c) text += "," + number(m.point[c] / 1000);
      const Quaternion q = quaternionOf(m.orientation);
      if (form == "rotvec") {
        for (int c = 0; c < 3; ++c) text += "," + number(m.orientation[c] * 180 / kPi);
      } else if (form == "rpy") {
        const Eigen::Vector3d rpy = rpyOf(q);
        for (int c = 0; c < 3; ++c) text += "," + number(rpy[c] * 180 / kPi);
      } else {
        for (double c : q) text += "," + number(c);
      }
      for (int i = 6; i >= 0; --i) text += "," + number(m.joints[i]);
      text += ",1,2,3\n";
    }
    write(form + "/session.csv", text);
    const auto run = runCli("import-readings " + path(form) + " --urdf " + urdf +
                                " --base panda_link0 --tip ball_link --instrument 0.05 "
                                "--instrument-angle 0.01 --marker hand -o " +
                                path(form + ".json"),
                            Stderr::Only);
    ASSERT_EQ(run.status, 0) << run.out;
    // The columns not read are named in a warning.
    EXPECT_NE(run.out.find("warning: columns not read (not a joint of the machine nor the "
                           "marker's): base_x, base_y, base_z, time"),
              std::string::npos)
        << run.out;
    const json plan = readJsonFile(path(form + ".json"));
    const json& entry = plan["placements"][0]["measurements"][0];
    EXPECT_EQ(entry["orientation"], form == "rotvec" ? "rotation_vector"
                                    : form == "rpy"  ? "rpy"
                                                     : "quaternion");
    EXPECT_EQ(entry["columns"][0], "panda_joint1 [rad]");
    const Plan imported = loadPlan(path(form + ".json"));
    const auto& mine = imported.placements.at(0).measurements;
    ASSERT_EQ(mine.size(), readings.size()) << form;
    for (std::size_t k = 0; k < mine.size(); ++k) {
      EXPECT_LT((mine[k].joints - readings[k].joints).cwiseAbs().maxCoeff(), 1e-15) << form;
      EXPECT_LT((mine[k].point - readings[k].point).cwiseAbs().maxCoeff(), 1e-9) << form;
      EXPECT_LT((mine[k].orientation - readings[k].orientation).cwiseAbs().maxCoeff(), 1e-9)
          << form << " reading " << k;
    }
  }
  // Several markers and none chosen: refused, naming the file and the markers.
  const auto ambiguous = runCli("import-readings " + path("rpy") + " --urdf " + urdf +
                                    " --base panda_link0 --tip ball_link --instrument 0.05 "
                                    "--instrument-angle 0.01 -o " +
                                    path("bad.json"),
                                Stderr::Only);
  EXPECT_EQ(ambiguous.status, 2);
  EXPECT_NE(ambiguous.out.find("session.csv: line 1: the header names several markers (\"hand\", "
                               "\"base\"): select the machine's tip with --marker NAME"),
            std::string::npos)
      << ambiguous.out;
  EXPECT_EQ(std::count(ambiguous.out.begin(), ambiguous.out.end(), '\n'), 1);
}

// A known rotation read three ways in one plan: roll 10, pitch 20, yaw 30 deg; the quaternion of
// the same rotation (the hand-computed product qz qy qx); the rotation vector of that quaternion.
// Each reading's orientation is the rotation vector computed here; a quaternion whose norm is not
// 1 is refused naming the file and line.
TEST_F(NamedColumns, KnownRotationReadAsRpyAndQuaternion) {
  const std::string urdf = testDataFile("mukca/mukca/urdf/panda.urdf");
  ASSERT_EQ(runCli("import-urdf " + urdf + " --base panda_link0 --tip ball_link -o " +
                   path("machine.json"))
                .status,
            0);
  const json machine = readJsonFile(path("machine.json"));
  const double d = kPi / 180;
  const Quaternion q = quaternionOfRpy(10 * d, 20 * d, 30 * d);
  const Eigen::Vector3d expected = rotationVectorOf(q);
  // Positions of three non-collinear readings: the plan checks them against the nominal machine
  // only through a rigid fit, so any joints do; the orientations are what is tested.
  const std::vector<Eigen::VectorXd> joints = pandaPostures(4);
  std::ofstream(path("reference.json")) << pandaPosePlan(machine, joints).dump(1);
  const Plan reference = parsed(path("reference.json"));
  std::string rpy_rows, quat_rows;
  for (const Measurement& m : reference.placements[0].measurements) {
    std::string row;
    for (int i = 0; i < 7; ++i) row += number(m.joints[i]) + ",";
    for (int c = 0; c < 3; ++c) row += number(m.point[c]) + ",";
    rpy_rows += row + "10,20,30\n";
    quat_rows +=
        row + number(q[0]) + "," + number(q[1]) + "," + number(q[2]) + "," + number(q[3]) + "\n";
  }
  write("rpy.csv", rpy_rows);
  write("quat.csv", quat_rows);
  json plan = pandaPosePlan(machine, {});
  plan["placements"][0]["measurements"] =
      json::array({{{"csv", "rpy.csv"}, {"unit", "rad"}, {"orientation", "rpy"}},
                   {{"csv", "quat.csv"}, {"unit", "rad"}, {"orientation", "quaternion"}}});
  std::ofstream(path("plan.json")) << plan.dump(1);
  const Plan plan_read = parsed(path("plan.json"));
  ASSERT_EQ(plan_read.placements[0].measurements.size(), 8u);
  for (const Measurement& m : plan_read.placements[0].measurements)
    EXPECT_LT((m.orientation - expected).cwiseAbs().maxCoeff(), 1e-12) << m.csv;
  // (0.5, 0.5, 0.5, 0.6): norm 1.054, not a rotation.
  std::string bad = quat_rows;
  const std::string first = quat_rows.substr(0, quat_rows.find('\n'));
  std::size_t cut = first.size();
  for (int k = 0; k < 4; ++k) cut = first.rfind(',', cut - 1);
  bad.replace(bad.find('\n') + 1, 0, first.substr(0, cut) + ",0.5,0.5,0.5,0.6\n");
  write("quat.csv", bad);
  const auto refused = runCli("check " + path("plan.json"), Stderr::Only);
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.out.find("quat.csv: line 2 (row 2): the quaternion (w, x, y, z) has norm "
                             "1.053565"),
            std::string::npos)
      << refused.out;
}

/// A lifting column and a 6-axis arm (tests/data/urdf/lifting-column-arm6.urdf): the column's
/// prismatic master reads [0, 1412] mm by its URDF limits.
struct ColumnExport {
  std::string header;
  std::string rows;
};

ColumnExport columnExport(double column_mm, bool with_joint6) {
  ColumnExport out;
  out.header =
      "frame,column_prismatic_joint [mm],joint1 [deg],joint2 [deg],joint3 [deg],"
      "joint4 [deg],joint5 [deg]";
  if (with_joint6) out.header += ",joint6 [deg]";
  out.header += ",note\n";
  const double base[6] = {10, -20, 30, 40, -50, 0};
  for (int k = 0; k < 4; ++k) {
    std::string row = std::to_string(k) + "," + number(k == 2 ? column_mm : 300.0 + 100 * k);
    for (int i = 0; i < (with_joint6 ? 6 : 5); ++i) row += "," + number(base[i] + 3 * k * (i + 1));
    out.rows += row + ",ok\n";
  }
  return out;
}

// A prismatic joint's reading a little past its URDF limit (1412.18 mm against 1412) widens the
// limit with the same warning as a revolute joint's; a reading a thousand times off is refused.
// A joint no file reads (joint6) is held at the value --hold states, in every reading.
TEST_F(NamedColumns, PrismaticLimitsWidenAndAHeldJointReadsItsValue) {
  const std::string urdf = testDataFile("urdf/lifting-column-arm6.urdf");
  const ColumnExport columns = columnExport(1412.18, false);
  write("bar/feature_0.csv", columns.header + columns.rows);
  write("bar/feature_1.csv", columns.header + columns.rows);
  const std::string import = "import-readings " + path("bar") + " --urdf " + urdf +
                             " --base base_link --tip prism_link --ball-bar 100 -o " +
                             path("plan.json");
  const auto unheld = runCli(import, Stderr::Only);
  EXPECT_EQ(unheld.status, 2);
  EXPECT_NE(unheld.out.find("feature_0.csv: line 1: no column for joint \"joint6\": the header "
                            "names other joints of the machine; a joint no file reads is held at "
                            "a value with --hold joint6=VALUE"),
            std::string::npos)
      << unheld.out;
  const auto run = runCli(import + " --hold joint6=12.5", Stderr::Only);
  ASSERT_EQ(run.status, 0) << run.out;
  EXPECT_NE(run.out.find("warning: joint 1: readings reach [300.000, 1412.180] mm, beyond its "
                         "limits [0.000, 1412.000] mm: joint_limits widened to the readings"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("warning: columns not read (not a joint of the machine nor the "
                         "marker's): frame, note"),
            std::string::npos)
      << run.out;
  const json document = readJsonFile(path("plan.json"));
  EXPECT_EQ(document["machine"]["joint_limits"][0], json({0.0, 1412.18}));
  const Plan plan = parsed(path("plan.json"));
  ASSERT_EQ(plan.placements.at(0).measurements.size(), 8u);  // 4 rows of each feature
  for (std::size_t k = 0; k < 4; ++k) {
    const Eigen::VectorXd& q = plan.placements[0].measurements[k].joints;
    EXPECT_DOUBLE_EQ(q[0], k == 2 ? 1412.18 : 300.0 + 100.0 * static_cast<double>(k));
    EXPECT_NEAR(q[1], (10 + 3 * static_cast<double>(k)) * kPi / 180, 1e-15);
    EXPECT_NEAR(q[6], 12.5 * kPi / 180, 1e-15);  // held
  }
  // The same readings with joint6 read at 12.5 deg: the same plan's readings.
  ColumnExport read6 = columnExport(1412.18, true);
  std::string rows;
  for (int k = 0; k < 4; ++k) {
    std::string row = std::to_string(k) + "," + number(k == 2 ? 1412.18 : 300.0 + 100 * k);
    const double base[6] = {10, -20, 30, 40, -50, 0};
    for (int i = 0; i < 5; ++i) row += "," + number(base[i] + 3 * k * (i + 1));
    rows += row + ",12.5,ok\n";
  }
  write("read/feature_0.csv", read6.header + rows);
  write("read/feature_1.csv", read6.header + rows);
  ASSERT_EQ(runCli("import-readings " + path("read") + " --urdf " + urdf +
                   " --base base_link --tip prism_link --ball-bar 100 -o " + path("read.json"))
                .status,
            0);
  const Plan read_plan = parsed(path("read.json"));
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_LT(
        (read_plan.placements[0].measurements[k].joints - plan.placements[0].measurements[k].joints)
            .cwiseAbs()
            .maxCoeff(),
        1e-15);
  }
  // A column read in m as if mm: 1412180 mm, a thousand times its range: refused at its row.
  const ColumnExport wrong = columnExport(1412180.0, false);
  write("wrong/feature_0.csv", wrong.header + wrong.rows);
  const auto refused = runCli("import-readings " + path("wrong") + " --urdf " + urdf +
                                  " --base base_link --tip prism_link --ball-bar 100 --hold "
                                  "joint6=0 -o " +
                                  path("wrong.json"),
                              Stderr::Only);
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.out.find("feature_0.csv: line 4 (row 3)"), std::string::npos) << refused.out;
  EXPECT_FALSE(fs::exists(path("wrong.json")));
  // A field that is not a number names the file, the line and the column by its header name.
  std::string broken = columns.header + columns.rows;
  broken.replace(broken.find(",-20,"), 5, ",abc,");
  write("broken/feature_0.csv", broken);
  const auto named = runCli("import-readings " + path("broken") + " --urdf " + urdf +
                                " --base base_link --tip prism_link --ball-bar 100 --hold "
                                "joint6=0 -o " +
                                path("broken.json"),
                            Stderr::Only);
  EXPECT_EQ(named.status, 2);
  EXPECT_NE(named.out.find("feature_0.csv: line 2: column 4 (\"joint2 [deg]\"): not a number: "
                           "\"abc\""),
            std::string::npos)
      << named.out;
  EXPECT_EQ(std::count(named.out.begin(), named.out.end(), '\n'), 1);
  // --hold of a joint the machine does not read.
  const auto unknown = runCli(import + " --hold joint7=0", Stderr::Only);
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.out.find("--hold: joint7: not a joint the machine reads"), std::string::npos)
      << unknown.out;
}

// Several markers per row (a motion-capture export with two markers on the hand): each row is
// one reading of each marker, each marker a tip of its own (a fixed joint marker_<name> after the
// chain's tip, nominal offset 0, calibrated). The import maps every column to its reading; then
// readings simulated of a machine whose markers sit 30-50 mm off the flange calibrate to tips
// that reproduce the true markers' points to 0.05 mm (noise 0.01 mm per coordinate), where the
// nominal machine is tens of mm off.
TEST_F(NamedColumns, SeveralMarkersPerRowAreOneReadingOfEachMarkersOwnTip) {
  const std::string urdf = testDataFile("mukca/mukca/urdf/panda.urdf");
  const std::vector<Eigen::VectorXd> joints = pandaPostures(40);
  json reference_document = pandaPosePlan(pandaMachine(), joints);
  reference_document["artifacts"]["instrument"] = {
      {"type", "instrument"}, {"measures", "point"}, {"noise", 0.01}};
  std::ofstream(path("reference.json")) << reference_document.dump(1);
  const Plan reference = loadPlan(path("reference.json"));
  const auto& nominal = reference.placements.at(0).measurements;
  // Markers first (mm), a frame counter, the joints (rad); B's columns a fixed shift of A's.
  std::string text = "frame,A_x [mm],A_y [mm],A_z [mm],B_x [mm],B_y [mm],B_z [mm]";
  for (int i = 1; i <= 7; ++i) text += ",panda_joint" + std::to_string(i) + " [rad]";
  text += "\n";
  const Eigen::Vector3d shift(10.0, -5.0, 20.0);
  for (std::size_t k = 0; k < nominal.size(); ++k) {
    text += std::to_string(k);
    for (int c = 0; c < 3; ++c) text += "," + number(nominal[k].point[c]);
    for (int c = 0; c < 3; ++c) text += "," + number(nominal[k].point[c] + shift[c]);
    for (int i = 0; i < 7; ++i) text += "," + number(joints[k][i]);
    text += "\n";
  }
  write("mocap/take.csv", text);
  const std::string import = "import-readings " + path("mocap") + " --urdf " + urdf +
                             " --base panda_link0 --tip ball_link --instrument 0.01 --probe 0.001";
  const auto run = runCli(import + " --marker A --marker B -o " + path("plan.json"), Stderr::Only);
  ASSERT_EQ(run.status, 0) << run.out;
  EXPECT_NE(run.out.find("warning: columns not read (not a joint of the machine nor the "
                         "marker's): frame"),
            std::string::npos)
      << run.out;
  const json document = readJsonFile(path("plan.json"));
  const json& tips = document["machine"]["tips"];
  ASSERT_EQ(tips.size(), 2u);
  EXPECT_EQ(tips[0]["name"], "A");
  EXPECT_EQ(tips[1]["joints"].back(), "marker_B");
  const json& entries = document["placements"][0]["measurements"];
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(entries[0]["tip"], "A");
  EXPECT_EQ(entries[1]["columns"].back(), "B_z [mm]");
  const Plan plan = loadPlan(path("plan.json"));
  const auto& readings = plan.placements.at(0).measurements;
  ASSERT_EQ(readings.size(), 2 * nominal.size());
  for (std::size_t k = 0; k < nominal.size(); ++k) {
    const Measurement& a = readings[k];
    const Measurement& b = readings[nominal.size() + k];
    EXPECT_EQ(a.stylus, 0);
    EXPECT_EQ(b.stylus, 1);
    EXPECT_LT((a.joints - joints[k]).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LT((b.joints - joints[k]).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LT((a.point - nominal[k].point).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT((b.point - nominal[k].point - shift).cwiseAbs().maxCoeff(), 1e-9);
  }
  // One marker of several, or a marker the header does not name: refused at the file.
  const auto unknown =
      runCli(import + " --marker A --marker C -o " + path("bad.json"), Stderr::Only);
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.out.find("take.csv: line 1: no marker \"C\""), std::string::npos)
      << unknown.out;

  // The true machine: the markers off the flange; readings of it, calibrated.
  const json truth = {{"parameters",
                       {{"marker_A.x", 30.0},
                        {"marker_A.y", -15.0},
                        {"marker_A.z", 40.0},
                        {"marker_B.x", -20.0},
                        {"marker_B.y", 35.0},
                        {"marker_B.z", 25.0}}}};
  std::ofstream(path("truth.json")) << truth.dump();
  const auto simulated = runCli("simulate " + path("plan.json") + " --truth " + path("truth.json") +
                                    " --seed 5 -o " + path("simulated.json"),
                                Stderr::Only);
  ASSERT_EQ(simulated.status, 0) << simulated.out;
  const Plan loaded = loadPlan(path("simulated.json"));
  const Eigen::VectorXd p_true = loadTruth(path("truth.json"), loaded);
  const Eigen::VectorXd p_nominal = loaded.machine.nominal;
  const CalibrationRun calibrated = calibrateReadings(loaded, CalibrationOptions{});
  const Plan& measured = calibrated.decided;  // its kept set
  const Calibration& calibration = calibrated.calibration;
  ASSERT_TRUE(calibration.summary.converged());
  const Mechanism& mech = *measured.machine.mechanism;
  double worst = 0.0, nominal_worst = 0.0;
  for (const Eigen::VectorXd& q : joints) {
    for (int tip = 0; tip < 2; ++tip) {
      Eigen::VectorXd x_true, x_est, x_nominal;
      ASSERT_EQ(mech.forwardStylus(tip, p_true, q, x_true), ForwardStatus::Ok);
      ASSERT_EQ(mech.forwardStylus(tip, calibration.parameters, q, x_est), ForwardStatus::Ok);
      ASSERT_EQ(mech.forwardStylus(tip, p_nominal, q, x_nominal), ForwardStatus::Ok);
      worst = std::max(worst, (x_est - x_true).norm());
      nominal_worst = std::max(nominal_worst, (x_nominal - x_true).norm());
    }
  }
  EXPECT_GT(nominal_worst, 30.0);
  EXPECT_LT(worst, 0.05);
  // The markers' offsets are kept first (their directions not given to the flange's frame) and
  // each is within 3 u of its true value.
  const Eigen::VectorXd u = calibration.posteriorU();
  const auto& names = mech.parameters();
  for (std::size_t k = 0; k < measured.machine.calibrated.size(); ++k) {
    const int i = measured.machine.calibrated[k];
    const std::string& name = names[static_cast<std::size_t>(i)].name;
    if (!name.starts_with("marker_")) continue;
    EXPECT_LT(std::abs(calibration.parameters[i] - p_true[i]),
              3.0 * u[static_cast<Eigen::Index>(k)])
        << name;
  }
  EXPECT_EQ(std::count_if(measured.machine.calibrated.begin(), measured.machine.calibrated.end(),
                          [&](int i) {
                            return names[static_cast<std::size_t>(i)].name.starts_with("marker_");
                          }),
            6);
  EXPECT_TRUE(calibration.warnings.empty());
}

// A marker the motion-capture system did not see in some frames (its cells empty, or NaN as some
// exports write): that marker's reading of those rows is left out, with a warning naming the file,
// the marker and the lines; the other marker's readings of the same rows are kept, each reading
// still lands on its own row. A row with only some of a marker's coordinates is refused at its
// line and column.
TEST_F(NamedColumns, AMarkerNotSeenInSomeRowsLeavesOutItsReadingsOfThoseRowsAlone) {
  const std::string urdf = testDataFile("mukca/mukca/urdf/panda.urdf");
  const std::vector<Eigen::VectorXd> joints = pandaPostures(12);
  std::string header = "A_x [mm],A_y [mm],A_z [mm],B_x [mm],B_y [mm],B_z [mm]";
  for (int i = 1; i <= 7; ++i) header += ",panda_joint" + std::to_string(i) + " [rad]";
  // Row k's coordinates: A at (k, 2k, 3k) mm, B 100 mm beyond along x; B not seen in rows 3 and
  // 7 (empty), A not seen in row 5 (NaN).
  auto row = [&](std::size_t k, const std::string& b_y) {
    std::string text;
    const double a[3] = {1.0 * k, 2.0 * k, 3.0 * k};
    const bool a_seen = k != 5, b_seen = k != 3 && k != 7;
    for (int c = 0; c < 3; ++c) text += (c ? "," : "") + (a_seen ? number(a[c]) : "NaN");
    for (int c = 0; c < 3; ++c) {
      const std::string value = c == 1 && !b_y.empty() ? b_y : number(a[c] + (c == 0 ? 100 : 0));
      text += "," + (b_seen ? value : std::string());
    }
    for (int i = 0; i < 7; ++i) text += "," + number(joints[k][i]);
    return text + "\n";
  };
  std::string text = header + "\n";
  for (std::size_t k = 0; k < joints.size(); ++k) text += row(k, "");
  write("mocap/take.csv", text);
  const std::string import = "import-readings " + path("mocap") + " --urdf " + urdf +
                             " --base panda_link0 --tip ball_link --instrument 0.01 --probe 0.001" +
                             " --marker A --marker B -o ";
  const auto run = runCli(import + path("plan.json"), Stderr::Only);
  ASSERT_EQ(run.status, 0) << run.out;
  EXPECT_NE(run.out.find("warning: " + path("mocap/take.csv") +
                         ": 2 row(s) without a reading of marker \"B\""),
            std::string::npos)
      << run.out;
  Plan plan = parsed(path("plan.json"));
  const auto& readings = plan.placements.at(0).measurements;
  ASSERT_EQ(readings.size(), 2 * joints.size() - 3);
  EXPECT_EQ(std::count_if(readings.begin(), readings.end(),
                          [](const Measurement& m) { return m.stylus == 0; }),
            static_cast<long>(joints.size()) - 1);
  // Each kept reading is its row's: the joints say which row, the point must be that row's.
  for (const Measurement& m : readings) {
    std::size_t k = 0;
    while (k < joints.size() && (m.joints - joints[k]).cwiseAbs().maxCoeff() > 1e-15) ++k;
    ASSERT_LT(k, joints.size());
    EXPECT_NE(k, m.stylus == 0 ? 5u : 3u);
    if (m.stylus == 1) {
      EXPECT_NE(k, 7u);
    }
    const Eigen::Vector3d expected(1.0 * k + (m.stylus == 1 ? 100.0 : 0.0), 2.0 * k, 3.0 * k);
    EXPECT_LT((m.point - expected).cwiseAbs().maxCoeff(), 1e-12) << "row " << k;
  }
  const std::string all = [&] {
    std::string joined;
    for (const std::string& w : plan.warnings) joined += w + "\n";
    return joined;
  }();
  EXPECT_NE(all.find("take.csv: 1 row(s) without a reading of marker \"A\""), std::string::npos)
      << all;
  EXPECT_NE(all.find("take.csv: 2 row(s) without a reading of marker \"B\""), std::string::npos)
      << all;
  EXPECT_NE(all.find("line(s) 5, 9"), std::string::npos) << all;  // rows 3 and 7 after the header

  // Only B_y missing in row 4 (line 6): not a marker unseen, a damaged row.
  text = header + "\n";
  for (std::size_t k = 0; k < joints.size(); ++k) text += row(k, k == 4 ? " " : "");
  write("mocap/take.csv", text);
  const auto damaged = runCli(import + path("damaged.json"), Stderr::Only);
  EXPECT_EQ(damaged.status, 2);
  EXPECT_NE(damaged.out.find("take.csv: line 6: column 5 (\"B_y [mm]\"): empty while the row's "
                             "other measured coordinates are given"),
            std::string::npos)
      << damaged.out;
  EXPECT_FALSE(fs::exists(path("damaged.json")));
}

// A unit given as an option where the header names another (docs/hardening.md): refused naming
// the file and both units, never silently preferred (a file in mm read as m is 1000 times off);
// the same unit given both ways is accepted. Header-named and general-layout files alike.
TEST_F(NamedColumns, AnOptionsUnitContradictingTheHeadersIsRefused) {
  const std::string urdf = testDataFile("mukca/mukca/urdf/panda.urdf");
  const std::vector<Eigen::VectorXd> joints = pandaPostures(4);
  std::string named = "hand_x [mm],hand_y [mm],hand_z [mm]";
  std::string general;
  for (int i = 1; i <= 7; ++i) {
    named += ",panda_joint" + std::to_string(i) + " [rad]";
    general += "q" + std::to_string(i) + "_rad,";
  }
  named += "\n";
  general += "x_mm,y_mm,z_mm\n";
  for (const Eigen::VectorXd& q : joints) {
    std::string angles;
    for (int i = 0; i < 7; ++i) angles += "," + number(q[i]);
    named += "100,200,300" + angles + "\n";
    general += angles.substr(1) + ",100,200,300\n";
  }
  write("named/take.csv", named);
  write("general/take.csv", general);
  for (const std::string folder : {"named", "general"}) {
    const std::string import = "import-readings " + path(folder) + " --urdf " + urdf +
                               " --base panda_link0 --tip ball_link --instrument 0.01 -o ";
    const auto refused =
        runCli(import + path(folder + "-m.json") + " --point-unit m", Stderr::Only);
    EXPECT_EQ(refused.status, 2) << folder;
    EXPECT_NE(refused.out.find("take.csv: line 1: the header names the point's unit mm and "
                               "--point-unit says m"),
              std::string::npos)
        << refused.out;
    EXPECT_FALSE(fs::exists(path(folder + "-m.json")));
    const auto agreed =
        runCli(import + path(folder + "-mm.json") + " --point-unit mm", Stderr::Only);
    EXPECT_EQ(agreed.status, 0) << agreed.out;
    const Plan plan = parsed(path(folder + "-mm.json"));
    EXPECT_EQ(plan.placements.at(0).measurements.at(0).point, Eigen::Vector3d(100, 200, 300))
        << folder;
  }
}

}  // namespace named_columns_test
}  // namespace artcal
