// Readings as other tools export them (issue 43 point 5, issue 44's CSV findings;
// docs/plan-format.md "Files whose header names the columns"): numbered and axis-first marker
// columns, every family's joints by name, columns naming nothing ignored with a word, a joint or
// marker named twice refused, rx, ry, rz as roll-pitch-yaw, ';' and tab separated files with
// decimal commas, quoted headers, one CSV file as one station, unknown unit words, and the
// import's options read as decimal numbers with conflicts refused.
//
// The oracle throughout: the same readings written in the plain form (no header, columns in the
// machine's order, units given as options) import to the same readings bit for bit.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "artcal/artcal.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/readings_import.hpp"
#include "cli_runner.hpp"
#include "temp_folder.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace exported_readings_test {

namespace fs = std::filesystem;
using nlohmann::json;
using test_support::CliRun;
using test_support::planFile;
using test_support::runCli;
using test_support::Stderr;
using test_support::testDataFile;

class ExportedReadings : public test_support::TempFolder {
 protected:
  ExportedReadings() : TempFolder("exported") {}
  /// import-readings ARGS -o FOLDER/OUT; stderr captured.
  CliRun import(const std::string& args, const std::string& out) const {
    return runCli("import-readings " + args + " -o " + path(out), Stderr::Only);
  }
};

std::string number(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

/// `text` with every '.' a ',' (a decimal comma).
std::string decimalComma(std::string text) {
  std::replace(text.begin(), text.end(), '.', ',');
  return text;
}

/// Fields joined by `separator`.
std::string joined(const std::vector<std::string>& fields, const std::string& separator = ",") {
  std::string out;
  for (std::size_t i = 0; i < fields.size(); ++i) out += (i ? separator : "") + fields[i];
  return out;
}

/// The readings of a plan file, every placement's, in order (parsed without plausibility).
std::vector<Measurement> readingsOf(const std::string& file) {
  const Plan plan = parsePlan(readJsonFile(file), file, true, /*check_plausibility=*/false);
  std::vector<Measurement> out;
  for (const Placement& placement : plan.placements)
    out.insert(out.end(), placement.measurements.begin(), placement.measurements.end());
  return out;
}

/// The two plans' readings are the same, bit for bit (joints, and an instrument's point and
/// orientation).
void expectSameReadings(const std::string& a, const std::string& b) {
  const std::vector<Measurement> first = readingsOf(a), second = readingsOf(b);
  ASSERT_EQ(first.size(), second.size()) << a << " " << b;
  ASSERT_FALSE(first.empty());
  for (std::size_t k = 0; k < first.size(); ++k) {
    EXPECT_EQ(first[k].joints, second[k].joints) << a << " reading " << k;
    EXPECT_EQ(first[k].point, second[k].point) << a << " reading " << k;
    EXPECT_EQ(first[k].orientation, second[k].orientation) << a << " reading " << k;
  }
}

std::size_t lines(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

// ---- the readings used: a UR5 (tests/data/urdf/ur5-ball.urdf) and a small arm with a slide and
// a continuous wrist (arm3-slide.urdf, joints j1 .. j4)

const std::string kUr5 = " --urdf " + testDataFile("urdf/ur5-ball.urdf") +
                         " --base base_link --tip ball_link --instrument 0.015";

/// Joint k of row r of the UR5, deg: inside its limits, distinct per row and joint.
double ur5Joint(int r, int k) {
  return -60.0 + 17.25 * k + 3.125 * r + 0.001 * r * k;
}
/// Coordinate c of marker m (1 or 2) in row r, mm.
double markerCoordinate(int r, int m, int c) {
  return 100.0 * m + 250.5 * c - 7.75 * r + 0.0625 * c * r;
}
/// Orientation component c of row r, deg (small: a rotation vector or roll-pitch-yaw alike).
double angle(int r, int c) {
  return 5.0 + 3.5 * c - 1.25 * r;
}

constexpr int kRows = 6;

/// The UR5's rows in the plain form: joints (deg), the point (mm) of marker `m`, and with
/// `pose` the 3 angles (deg).
std::string ur5Plain(int m, bool pose) {
  std::string text;
  for (int r = 0; r < kRows; ++r) {
    std::vector<std::string> row;
    for (int k = 0; k < 6; ++k) row.push_back(number(ur5Joint(r, k)));
    for (int c = 0; c < 3; ++c) row.push_back(number(markerCoordinate(r, m, c)));
    if (pose)
      for (int c = 0; c < 3; ++c) row.push_back(number(angle(r, c)));
    text += joined(row) + "\n";
  }
  return text;
}

const std::string kPlainUnits = " --unit deg --point-unit mm";

// FIGAROH's and mocap tools' numbered markers (x1, y1, z1, x2, ...), the tracker export's
// axis-first ones (x_t, y_t, z_t as the UR5 tracker data writes them), the joints as joint_1 ..
// joint_6 (a chain whose URDF names them otherwise): each marker's readings are the plain form's.
TEST_F(ExportedReadings, NumberedAndAxisFirstMarkerColumnsReadAsThePlainForm) {
  std::string numbered =
      "step_order,x1,y1,z1,x2,y2,z2,joint_1,joint_2,joint_3,joint_4,joint_5,"
      "joint_6\n";
  std::string axis_first =
      "step_order,x_t,y_t,z_t,x_dif,y_dif,z_dif,joint_1,joint_2,joint_3,"
      "joint_4,joint_5,joint_6\n";
  for (int r = 0; r < kRows; ++r) {
    std::vector<std::string> row = {std::to_string(r)};
    for (int m : {1, 2})
      for (int c = 0; c < 3; ++c) row.push_back(number(markerCoordinate(r, m, c)));
    for (int k = 0; k < 6; ++k) row.push_back(number(ur5Joint(r, k)));
    numbered += joined(row) + "\n";
    axis_first += joined(row) + "\n";
  }
  write("numbered/s1.csv", numbered);
  write("axis/s1.csv", axis_first);
  write("plain1/s1.csv", ur5Plain(1, false));
  write("plain2/s1.csv", ur5Plain(2, false));
  for (const char* plain : {"plain1", "plain2"})
    ASSERT_EQ(import(path(plain) + kUr5 + kPlainUnits, std::string(plain) + ".json").status, 0);
  for (const auto& [marker, plain] : {std::pair{"1", "plain1"}, std::pair{"2", "plain2"}}) {
    const CliRun run = import(path("numbered") + kUr5 + kPlainUnits + " --marker " + marker,
                              std::string("numbered") + marker + ".json");
    ASSERT_EQ(run.status, 0) << run.out;
    EXPECT_NE(run.out.find("warning: columns not read (not a joint of the machine nor the "
                           "marker's): step_order, "),
              std::string::npos)
        << run.out;
    expectSameReadings(path(std::string("numbered") + marker + ".json"),
                       path(std::string(plain) + ".json"));
  }
  const CliRun axis = import(path("axis") + kUr5 + kPlainUnits + " --marker t", "axis.json");
  ASSERT_EQ(axis.status, 0) << axis.out;
  expectSameReadings(path("axis.json"), path("plain1.json"));
  // Two markers and none chosen: refused naming both.
  const CliRun unsaid = import(path("numbered") + kUr5 + kPlainUnits, "unsaid.json");
  EXPECT_EQ(unsaid.status, 2);
  EXPECT_NE(unsaid.out.find("the header names several markers (\"1\", \"2\")"), std::string::npos)
      << unsaid.out;
  EXPECT_EQ(lines(unsaid.out), 1u) << unsaid.out;
}

// FIGAROH's pose columns phix1, phiy1, phiz1 are roll-pitch-yaw (the documented rule), a rotation
// vector with --orientation rotation_vector; rx, ry, rz are a rotation vector, roll-pitch-yaw
// with --orientation rpy. Each reads as the plain form in the form said.
TEST_F(ExportedReadings, OrientationColumnsReadInTheFormTheRuleOrTheOptionSays) {
  std::string phi = "x1,y1,z1,phix1,phiy1,phiz1,joint_1,joint_2,joint_3,joint_4,joint_5,joint_6\n";
  std::string rx =
      "hand_x,hand_y,hand_z,hand_rx,hand_ry,hand_rz,shoulder_pan_joint,"
      "shoulder_lift_joint,elbow_joint,wrist_1_joint,wrist_2_joint,wrist_3_joint\n";
  for (int r = 0; r < kRows; ++r) {
    std::vector<std::string> row;
    for (int c = 0; c < 3; ++c) row.push_back(number(markerCoordinate(r, 1, c)));
    for (int c = 0; c < 3; ++c) row.push_back(number(angle(r, c)));
    for (int k = 0; k < 6; ++k) row.push_back(number(ur5Joint(r, k)));
    phi += joined(row) + "\n";
    rx += joined(row) + "\n";
  }
  write("phi/s1.csv", phi);
  write("rx/s1.csv", rx);
  write("plain/s1.csv", ur5Plain(1, true));
  const std::string pose = kUr5 + kPlainUnits + " --instrument-angle 0.01 --orientation-unit deg";
  ASSERT_EQ(import(path("plain") + pose + " --orientation rpy", "plain-rpy.json").status, 0);
  ASSERT_EQ(import(path("plain") + pose, "plain-rotvec.json").status, 0);
  const CliRun phi_rpy = import(path("phi") + pose, "phi-rpy.json");
  ASSERT_EQ(phi_rpy.status, 0) << phi_rpy.out;
  EXPECT_EQ(readJsonFile(path("phi-rpy.json"))["placements"][0]["measurements"][0]["orientation"],
            "rpy");
  expectSameReadings(path("phi-rpy.json"), path("plain-rpy.json"));
  ASSERT_EQ(import(path("phi") + pose + " --orientation rotation_vector", "phi-rotvec.json").status,
            0);
  expectSameReadings(path("phi-rotvec.json"), path("plain-rotvec.json"));
  ASSERT_EQ(import(path("rx") + pose, "rx-rotvec.json").status, 0);
  expectSameReadings(path("rx-rotvec.json"), path("plain-rotvec.json"));
  const CliRun rx_rpy = import(path("rx") + pose + " --orientation rpy", "rx-rpy.json");
  ASSERT_EQ(rx_rpy.status, 0) << rx_rpy.out;
  expectSameReadings(path("rx-rpy.json"), path("plain-rpy.json"));
  // The two forms differ for these angles: the option is not ignored.
  EXPECT_NE(readingsOf(path("rx-rpy.json"))[1].orientation,
            readingsOf(path("rx-rotvec.json"))[1].orientation);
}

/// The small arm's rows: j1, j2 (deg), j3 (mm), j4 (deg, continuous), row r.
std::vector<double> armRow(int r) {
  return {10.0 + 7.5 * r, -20.0 + 4.25 * r, 50.0 + 12.5 * r, 30.0 - 9.75 * r};
}

const std::string kArm =
    " --urdf " + testDataFile("urdf/arm3-slide.urdf") + " --base world --tip probe --ball-bar 100";

/// The arm's rows in the plain form, no header (--unit deg: lengths in mm).
std::string armPlain() {
  std::string text;
  for (int r = 0; r < kRows; ++r) {
    std::vector<std::string> row;
    for (double v : armRow(r)) row.push_back(number(v));
    text += joined(row) + "\n";
  }
  return text;
}

// The serial-DH and machine-tool families, whose joints have no names of their own: a header
// naming them j1 .., joint_1 .., q1 .. (a machine tool's by its axis letters X, Y, Z, A, C, also
// A_deg, X_mm, C [deg]) is read by those names wherever they stand, beside columns naming nothing
// of the machine.
TEST_F(ExportedReadings, EveryFamilysJointsAreReadByTheirNames) {
  const std::string dh = " --machine " + testDataFile("ref-dh-beta-arm3.json") + " --ball-bar 100";
  std::string plain;
  const std::vector<std::vector<double>> dh_rows = {
      {10, 20, 30}, {-15.5, 42.25, 60}, {33, -70.125, 12}, {80, 5, -45}};
  for (const auto& row : dh_rows)
    plain += number(row[0]) + "," + number(row[1]) + "," + number(row[2]) + "\n";
  write("dh-plain/feature_0.csv", plain);
  ASSERT_EQ(import(path("dh-plain") + dh + " --unit deg", "dh-plain.json").status, 0);
  // Each header: the names, and which joint (from 0) each field reads (-1: none).
  const std::vector<std::pair<std::string, std::vector<int>>> headers = {
      {"timestamp,j3 [deg],j1 [deg],j2 [deg]", {-1, 2, 0, 1}},
      {"index,joint_2_deg,joint_1_deg,joint_3_deg", {-1, 1, 0, 2}},
      {"q2,time,q3,q1", {1, -1, 2, 0}},
      {"Joint1,JOINT2,joint3", {0, 1, 2}}};
  for (std::size_t h = 0; h < headers.size(); ++h) {
    const auto& [names, joint_of] = headers[h];
    std::string text = names + "\n";
    for (const auto& row : dh_rows) {
      std::vector<std::string> fields;
      for (const int j : joint_of)
        fields.push_back(j < 0 ? "7" : number(row[static_cast<std::size_t>(j)]));
      text += joined(fields) + "\n";
    }
    const std::string folder = "dh" + std::to_string(h);
    write(folder + "/feature_0.csv", text);
    const std::string unit = names.find("deg") == std::string::npos ? " --unit deg" : "";
    const CliRun run = import(path(folder) + dh + unit, folder + ".json");
    ASSERT_EQ(run.status, 0) << names << ": " << run.out;
    expectSameReadings(path(folder + ".json"), path("dh-plain.json"));
  }
  // A five-axis trunnion: X, Y, Z mm, A, C deg, in the export's order and units words.
  const json trunnion = readJsonFile(planFile("machine-tool-trunnion-2spheres.json"));
  write("mt.json", trunnion["machine"].dump());
  write("sphere.json", json{{"sphere1", trunnion["artifacts"]["sphere1"]}}.dump());
  const std::string mt = " --machine " + path("mt.json") + " --artifact " + path("sphere.json");
  const std::vector<std::vector<double>> mt_rows = {{10, 20, 30, 40, 50},
                                                    {-100.5, 7.25, 120, -30, 170},
                                                    {250, -80, 5, 95.5, -150},
                                                    {0.125, 300, 400, -100, 260}};
  std::string mt_plain, mt_export = "time,C [deg],X_mm,A_deg,Y_mm,Z_mm\n";
  for (const auto& q : mt_rows) {
    mt_plain +=
        joined({number(q[0]), number(q[1]), number(q[2]), number(q[3]), number(q[4])}) + "\n";
    mt_export +=
        joined({"0.5", number(q[4]), number(q[0]), number(q[3]), number(q[1]), number(q[2])}) +
        "\n";
  }
  write("mt-plain/feature_0.csv", mt_plain);
  write("mt-export/feature_0.csv", mt_export);
  ASSERT_EQ(import(path("mt-plain") + mt + " --unit deg", "mt-plain.json").status, 0);
  const CliRun run = import(path("mt-export") + mt, "mt-export.json");
  ASSERT_EQ(run.status, 0) << run.out;
  EXPECT_NE(run.out.find("warning: columns not read (not a joint of the machine nor the "
                         "marker's): time"),
            std::string::npos)
      << run.out;
  expectSameReadings(path("mt-export.json"), path("mt-plain.json"));
}

// Columns that name nothing of the machine: a timestamp, an index, an unnamed index column first
// or last (as pandas writes it) are ignored, named in one warning; a trailing unnamed column no
// longer shifts every joint by one.
TEST_F(ExportedReadings, ColumnsNamingNothingAreIgnoredWithOneWarning) {
  write("plain/feature_0.csv", armPlain());
  ASSERT_EQ(import(path("plain") + kArm + " --unit deg", "plain.json").status, 0);
  const std::string names = "j1 [deg],j2 [deg],j3 [mm],j4 [deg]";
  std::string trailing = names + ",\n", leading = "," + names + ",timestamp\n";
  for (int r = 0; r < kRows; ++r) {
    std::vector<std::string> row;
    for (double v : armRow(r)) row.push_back(number(v));
    trailing += joined(row) + "," + std::to_string(r) + "\n";
    leading += std::to_string(r) + "," + joined(row) + ",1700000000.5\n";
  }
  write("trailing/feature_0.csv", trailing);
  write("leading/feature_0.csv", leading);
  const CliRun last = import(path("trailing") + kArm, "trailing.json");
  ASSERT_EQ(last.status, 0) << last.out;
  EXPECT_NE(last.out.find("warning: columns not read (not a joint of the machine nor the "
                          "marker's): (unnamed column 5)\n"),
            std::string::npos)
      << last.out;
  expectSameReadings(path("trailing.json"), path("plain.json"));
  const CliRun first = import(path("leading") + kArm, "leading.json");
  ASSERT_EQ(first.status, 0) << first.out;
  EXPECT_NE(first.out.find("warning: columns not read (not a joint of the machine nor the "
                           "marker's): (unnamed column 1), timestamp\n"),
            std::string::npos)
      << first.out;
  expectSameReadings(path("leading.json"), path("plain.json"));
}

// A joint named twice (by the same name, or by two names of it), the same marker's coordinate
// named twice: exit 2, one line naming the file, line 1 and both columns.
TEST_F(ExportedReadings, AJointOrAMarkerNamedTwiceIsRefusedNamingBothColumns) {
  const std::string rows = "10,20,30,40,50\n";
  write("twice/feature_0.csv", "j1 [deg],j2 [deg],j3 [mm],j4 [deg],j2 [rad]\n" + rows);
  const CliRun twice = import(path("twice") + kArm, "twice.json");
  EXPECT_EQ(twice.status, 2);
  EXPECT_NE(twice.out.find("twice/feature_0.csv: line 1: joint \"j2\" is named twice, columns 2 "
                           "(\"j2 [deg]\") and 5 (\"j2 [rad]\"): keep one column per joint"),
            std::string::npos)
      << twice.out;
  EXPECT_EQ(lines(twice.out), 1u) << twice.out;
  write("alias/feature_0.csv", "j1,joint_1,j2,j3\n1,2,3,4\n");
  const CliRun alias =
      import(path("alias") + " --machine " + testDataFile("ref-dh-beta-arm3.json") +
                 " --ball-bar 100 --unit deg",
             "alias.json");
  EXPECT_EQ(alias.status, 2);
  EXPECT_NE(alias.out.find("alias/feature_0.csv: line 1: joint \"j1\" is named twice, columns 1 "
                           "(\"j1\") and 2 (\"joint_1\")"),
            std::string::npos)
      << alias.out;
  EXPECT_EQ(lines(alias.out), 1u) << alias.out;
  write("marker/s1.csv",
        "hand_x,hand_y,hand_z,hand_x [mm],joint_1,joint_2,joint_3,joint_4,joint_5,joint_6\n"
        "1,2,3,4,5,6,7,8,9,10\n");
  const CliRun marker = import(path("marker") + kUr5 + kPlainUnits, "marker.json");
  EXPECT_EQ(marker.status, 2);
  EXPECT_NE(marker.out.find("marker/s1.csv: line 1: marker \"hand\": its x is named twice, "
                            "columns 1 (\"hand_x\") and 4 (\"hand_x [mm]\")"),
            std::string::npos)
      << marker.out;
  EXPECT_EQ(lines(marker.out), 1u) << marker.out;
}

// The same readings with ';' and decimal commas, tabs with decimal commas or points, a quoted
// header and quoted fields: the comma file's readings bit for bit. A row whose separator is not
// the file's, and a quote not closed, are refused with a hint saying what was seen.
TEST_F(ExportedReadings, SemicolonTabAndQuotedFilesReadAsTheCommaFile) {
  write("plain/feature_0.csv", armPlain());
  ASSERT_EQ(import(path("plain") + kArm + " --unit deg", "plain.json").status, 0);
  const std::vector<std::string> names = {"j1 [deg]", "j2 [deg]", "j3 [mm]", "j4 [deg]"};
  struct Form {
    std::string name, separator;
    bool comma, quoted;
  };
  for (const Form& form :
       {Form{"semicolon", ";", true, false}, Form{"tab-comma", "\t", true, false},
        Form{"tab-point", "\t", false, false}, Form{"quoted", ",", false, true}}) {
    std::vector<std::string> header = names;
    if (form.quoted)
      for (std::string& n : header) n = "\"" + n + "\"";
    std::string text = joined(header, form.separator) + "\n";
    for (int r = 0; r < kRows; ++r) {
      std::vector<std::string> row;
      for (double v : armRow(r)) {
        const std::string field = form.comma ? decimalComma(number(v)) : number(v);
        row.push_back(form.quoted ? "\"" + field + "\"" : field);
      }
      text += joined(row, form.separator) + "\n";
    }
    write(form.name + "/feature_0.csv", text);
    const CliRun run = import(path(form.name) + kArm, form.name + ".json");
    ASSERT_EQ(run.status, 0) << form.name << ": " << run.out;
    expectSameReadings(path(form.name + ".json"), path("plain.json"));
  }
  // A comma header over a row separated by ';': the hint names what the row holds.
  write("mixed/feature_0.csv", joined(names) + "\n10;20;30;40\n");
  const CliRun mixed = import(path("mixed") + kArm, "mixed.json");
  EXPECT_EQ(mixed.status, 2);
  EXPECT_NE(mixed.out.find("mixed/feature_0.csv: line 2: expected 4 fields (as the header), got 1 "
                           "(the file's fields are split at ',', as its first line; this line "
                           "holds 3 ';'"),
            std::string::npos)
      << mixed.out;
  EXPECT_EQ(lines(mixed.out), 1u) << mixed.out;
  write("quote/feature_0.csv", "\"j1 [deg],j2 [deg],j3 [mm],j4 [deg]\n10,20,30,40\n");
  const CliRun quote = import(path("quote") + kArm, "quote.json");
  EXPECT_EQ(quote.status, 2);
  EXPECT_NE(quote.out.find("quote/feature_0.csv: line 1: column 1: a quoted field whose closing "
                           "quote is missing"),
            std::string::npos)
      << quote.out;
  EXPECT_EQ(lines(quote.out), 1u) << quote.out;
}

// One CSV file given as one instrument station (named after its stem): the readings of the same
// file in a folder of stations.
TEST_F(ExportedReadings, OneCsvFileIsOneInstrumentStation) {
  write("stations/s1.csv", ur5Plain(1, false));
  ASSERT_EQ(import(path("stations") + kUr5 + kPlainUnits, "folder.json").status, 0);
  const CliRun run = import(path("stations/s1.csv") + kUr5 + kPlainUnits, "file.json");
  ASSERT_EQ(run.status, 0) << run.out;
  const json plan = readJsonFile(path("file.json"));
  ASSERT_EQ(plan["placements"].size(), 1u);
  EXPECT_EQ(plan["placements"][0]["name"], "s1");
  EXPECT_EQ(plan["placements"][0]["artifact"], "instrument");
  expectSameReadings(path("file.json"), path("folder.json"));
}

// A unit word the import does not read is refused naming the column and the units read, not
// answered with "no column for joint, use --hold".
TEST_F(ExportedReadings, AnUnknownUnitWordIsRefusedNamingTheColumnAndTheUnitsRead) {
  write("grad/feature_0.csv", "j1 [grad],j2 [deg],j3 [mm],j4 [deg]\n10,20,30,40\n");
  const CliRun run = import(path("grad") + kArm, "grad.json");
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.out.find("grad/feature_0.csv: line 1: column 1 (\"j1 [grad]\"): unit \"grad\" is "
                         "not one read: a column's unit is deg, rad, mm or m"),
            std::string::npos)
      << run.out;
  EXPECT_EQ(lines(run.out), 1u) << run.out;
  // Another column's word in brackets (a timestamp in s) is a column not read, not an error.
  write("seconds/feature_0.csv", "time [s],j1 [deg],j2 [deg],j3 [mm],j4 [deg]\n0.5,10,20,30,40\n");
  const CliRun seconds = import(path("seconds") + kArm, "seconds.json");
  EXPECT_EQ(seconds.status, 0) << seconds.out;
}

// A continuous joint (arm3's j4, imported with limits [-180, 180]) read at 400 deg: its limits
// widen to the readings, with a warning, where a revolute joint's would be refused.
TEST_F(ExportedReadings, AContinuousJointAt400DegreesWidensItsLimits) {
  write("turn/feature_0.csv", "j1 [deg],j2 [deg],j3 [mm],j4 [deg]\n10,20,30,400\n11,21,31,-30\n");
  const CliRun run = import(path("turn") + kArm, "turn.json");
  ASSERT_EQ(run.status, 0) << run.out;
  EXPECT_NE(run.out.find("warning: joint 4: readings reach [-30.000, 400.000] deg, beyond its "
                         "limits [-180.000, 180.000] deg: joint_limits widened to the readings"),
            std::string::npos)
      << run.out;
  const json plan = readJsonFile(path("turn.json"));
  EXPECT_EQ(plan["machine"]["joint_limits"][3], json({-180.0, 400.0}));
  const std::vector<Measurement> readings = readingsOf(path("turn.json"));
  ASSERT_EQ(readings.size(), 2u);
  EXPECT_DOUBLE_EQ(readings[0].joints[3], 400.0 * std::numbers::pi / 180.0);
  // A revolute joint (j1, limits [-171.887, 171.887] deg) at 400 deg stays refused.
  write("revolute/feature_0.csv", "j1 [deg],j2 [deg],j3 [mm],j4 [deg]\n400,20,30,40\n");
  EXPECT_EQ(import(path("revolute") + kArm, "revolute.json").status, 2);
}

// The import's options: numbers are decimal numbers only (no hexadecimal, inf or nan); an option
// given twice is refused where the two conflict (the same value twice is one); --tip-of is
// checked whole, for a machine of one tip too.
TEST_F(ExportedReadings, OptionsTakeDecimalNumbersAndRefuseConflicts) {
  write("bar/feature_0.csv", "j1 [deg],j2 [deg],j3 [mm]\n10,20,30\n11,21,31\n");
  const std::string bar = path("bar") + kArm;
  const CliRun conflict = import(bar + " --hold j4=0 --hold j4=10", "a.json");
  EXPECT_EQ(conflict.status, 2);
  EXPECT_NE(conflict.out.find("--hold: j4=10: joint \"j4\" is held twice, at 0 and 10: give one "
                              "--hold per joint"),
            std::string::npos)
      << conflict.out;
  EXPECT_EQ(lines(conflict.out), 1u) << conflict.out;
  const CliRun same = import(bar + " --hold j4=5 --hold j4=5", "same.json");
  ASSERT_EQ(same.status, 0) << same.out;
  EXPECT_DOUBLE_EQ(readingsOf(path("same.json"))[0].joints[3], 5.0 * std::numbers::pi / 180.0);
  for (const char* bad :
       {" --hold j4=0x10", " --hold j4=inf", " --hold j4=1e400", " --hold j4=0 --prior 0x5,1",
        " --hold j4=0 --prior 5,nan", " --hold j4=0 --probe 0x10", " --hold j4=0 --encoder 0x10",
        " --hold j4=0 --u-length 0x1p-2", " --hold j4=0 --probe inf"}) {
    const CliRun run = import(bar + bad, "bad.json");
    EXPECT_EQ(run.status, 2) << bad << ": " << run.out;
    // Ours ("a decimal number"), or main's guard for every number option ("a finite number").
    EXPECT_TRUE(run.out.find("decimal number") != std::string::npos ||
                run.out.find("expected a finite number") != std::string::npos)
        << bad << ": " << run.out;
    EXPECT_EQ(lines(run.out), 1u) << bad << ": " << run.out;
    EXPECT_FALSE(fs::exists(path("bad.json"))) << bad;
  }
  // One tip: --tip-of naming it is honoured with a word; naming another is refused.
  const CliRun one = import(bar + " --hold j4=0 --tip-of bar=probe", "one.json");
  ASSERT_EQ(one.status, 0) << one.out;
  EXPECT_NE(one.out.find("warning: --tip-of: the machine has one tip, probe: every placement is "
                         "its"),
            std::string::npos)
      << one.out;
  const CliRun other = import(bar + " --hold j4=0 --tip-of bar=wrist", "other.json");
  EXPECT_EQ(other.status, 2);
  EXPECT_NE(other.out.find("--tip-of: bar=wrist: the machine has one tip (probe)"),
            std::string::npos)
      << other.out;
  // Several tips: a placement given two tips, a tip the machine does not have.
  write("hands/left.csv", "x\n");
  write("hands/right.csv", "x\n");
  const std::string hands = path("hands/left.csv") + " " + path("hands/right.csv") + " --urdf " +
                            testDataFile("urdf/humanoid-small.urdf") +
                            " --base left_sole_link --tip gripper_left_base_link --tip "
                            "gripper_right_base_link --ball-bar 100";
  const CliRun two = import(hands +
                                " --tip-of left=gripper_left_base_link --tip-of "
                                "left=gripper_right_base_link",
                            "two.json");
  EXPECT_EQ(two.status, 2);
  EXPECT_NE(two.out.find("--tip-of: left=gripper_right_base_link: placement left is given two "
                         "tips, gripper_left_base_link and gripper_right_base_link"),
            std::string::npos)
      << two.out;
  const CliRun nosuch = import(hands +
                                   " --tip-of left=gripper_left_base_link --tip-of "
                                   "left=nosuch",
                               "nosuch.json");
  EXPECT_EQ(nosuch.status, 2);
  EXPECT_NE(nosuch.out.find("--tip-of: left=nosuch: "), std::string::npos) << nosuch.out;
  const CliRun unknown = import(hands + " --tip-of right=nosuch", "unknown.json");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.out.find("--tip-of: right=nosuch: not a tip of the machine (its tips: "
                             "gripper_left_base_link, gripper_right_base_link)"),
            std::string::npos)
      << unknown.out;
}

}  // namespace exported_readings_test
}  // namespace artcal
