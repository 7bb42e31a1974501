// Readings from CSV files (models.md section 7): a plan whose measurements name CSV files reads
// the same readings as the plan that lists them, in every unit; every fault names the CSV file
// and its line (exit status 2 on the command line).

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "artcal/internal.hpp"
#include "artcal/io/csv_readings.hpp"
#include "cli_runner.hpp"
#include "temp_folder.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace csv_readings_test {

namespace fs = std::filesystem;
using nlohmann::json;

/// A fresh folder for one test's files, with a "front" folder in it.
class CsvFolder : public test_support::TempFolder {
 protected:
  CsvFolder() : TempFolder("csv") {}
  void SetUp() override {
    TempFolder::SetUp();
    fs::create_directories(dir_ / "front");
  }
};

/// The 6-axis example plan with its readings.
json examplePlan() {
  std::ifstream in(test_support::planFile("aacmm-6axis-3bars.json"));
  return json::parse(in);
}

/// The readings of feature `feature` of placement 0 as CSV rows, each value times `scale`.
std::string csvOf(const json& plan, int feature, double scale, const std::string& header = "") {
  std::ostringstream out;
  out.precision(17);
  if (!header.empty()) out << header << "\n";
  for (const json& m : plan["placements"][0]["measurements"]) {
    if (m["feature"].get<int>() != feature) continue;
    const auto& joints = m["joints"];
    for (std::size_t i = 0; i < joints.size(); ++i)
      out << (i ? "," : "") << joints[i].get<double>() * scale;
    out << "\n";
  }
  return out.str();
}

std::vector<Eigen::VectorXd> readingsOf(const Placement& placement, int feature) {
  std::vector<Eigen::VectorXd> out;
  for (const Measurement& m : placement.measurements)
    if (m.feature == feature) out.push_back(m.joints);
  return out;
}

TEST_F(CsvFolder, SameReadingsAsTheJsonListInDegreesAndRadians) {
  json plan = examplePlan();
  const Plan listed = parsePlan(plan, "listed.json");
  write("front/hole_0.csv", csvOf(plan, 0, std::numbers::pi / 180.0));
  write("front/hole_1.csv", csvOf(plan, 1, 1.0, "j1,j2,j3,j4,j5,j6"));
  plan["placements"][0]["measurements"] =
      json::array({{{"feature", 0}, {"csv", "front/hole_0.csv"}, {"unit", "rad"}},
                   {{"feature", 1}, {"csv", "front/hole_1.csv"}}});
  const std::string path = write("plan.json", plan.dump());
  const Plan fromCsv = loadPlan(path);
  EXPECT_TRUE(fromCsv.warnings.empty());
  for (int feature : {0, 1}) {
    const auto expected = readingsOf(listed.placements[0], feature);
    const auto actual = readingsOf(fromCsv.placements[0], feature);
    ASSERT_EQ(actual.size(), expected.size());
    ASSERT_FALSE(actual.empty());
    for (std::size_t i = 0; i < expected.size(); ++i)
      EXPECT_LT((actual[i] - expected[i]).cwiseAbs().maxCoeff(), 1e-14) << feature << " " << i;
  }
}

TEST_F(CsvFolder, PrismaticReadingsInMetres) {
  const std::string path = write("lin.csv", "10,0.25\n\n-5, 0.5\r\n");
  const auto units = readingUnitsFromName("m");
  ASSERT_TRUE(units);
  const auto rows = readJointCsv(path, {JointKind::Revolute, JointKind::Prismatic}, *units);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_NEAR(rows[0][0], 10.0 * std::numbers::pi / 180.0, 1e-15);  // revolute stays in deg
  EXPECT_DOUBLE_EQ(rows[0][1], 250.0);
  EXPECT_DOUBLE_EQ(rows[1][1], 500.0);
  EXPECT_FALSE(readingUnitsFromName("inch"));
}

// ROS's joint states: revolute joints in rad and prismatic ones in m, in one file ("rad+m").
TEST_F(CsvFolder, AngleAndLengthUnitsTogether) {
  const std::string path = write("ros.csv", "0.5,0.25\n-1,1.5\n");
  const auto units = readingUnitsFromName("rad+m");
  ASSERT_TRUE(units);
  const auto rows = readJointCsv(path, {JointKind::Revolute, JointKind::Prismatic}, *units);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_DOUBLE_EQ(rows[0][0], 0.5);
  EXPECT_DOUBLE_EQ(rows[0][1], 250.0);
  EXPECT_DOUBLE_EQ(rows[1][0], -1.0);
  EXPECT_DOUBLE_EQ(rows[1][1], 1500.0);
  const auto plain = readingUnitsFromName("deg+mm");
  ASSERT_TRUE(plain);
  EXPECT_DOUBLE_EQ(plain->angle_to_rad, std::numbers::pi / 180.0);
  EXPECT_DOUBLE_EQ(plain->length_to_mm, 1.0);
  for (const char* bad : {"rad+", "+m", "m+rad", "rad+m+", "rad+rad", "deg+inch"})
    EXPECT_FALSE(readingUnitsFromName(bad)) << bad;
}

/// The InputError of reading `text` as a 2-joint CSV file.
InputError faultOf(const std::string& path) {
  try {
    readJointCsv(path, {JointKind::Revolute, JointKind::Revolute}, ReadingUnits{});
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError for " << path;
  return InputError("", "", "");
}

TEST_F(CsvFolder, FaultsNameTheFileAndTheLine) {
  const InputError columns = faultOf(write("a.csv", "q1,q2\n1,2\n3,4,5\n"));
  EXPECT_EQ(columns.file(), (dir_ / "a.csv").string());
  EXPECT_EQ(columns.pointer(), "line 3");
  EXPECT_NE(std::string(columns.what()).find("expected 2 readings, got 3"), std::string::npos);
  const InputError word = faultOf(write("b.csv", "1,2\n1,x\n"));
  EXPECT_EQ(word.pointer(), "line 2");
  EXPECT_NE(std::string(word.what()).find("column 2: not a number"), std::string::npos);
  // A header is only the first line; a line of names later is an error.
  EXPECT_EQ(faultOf(write("c.csv", "1,2\nq1,q2\n")).pointer(), "line 2");
  EXPECT_EQ(faultOf(write("d.csv", "1,nan\n")).pointer(), "line 1");
  EXPECT_EQ(faultOf(write("e.csv", "1,2.5e999\n")).pointer(), "line 1");
  EXPECT_NE(std::string(faultOf(write("f.csv", "q1,q2\n\n")).what()).find("no readings"),
            std::string::npos);
  EXPECT_NE(std::string(faultOf((dir_ / "missing.csv").string()).what()).find("cannot be read"),
            std::string::npos);
}

// "exclude_rows" leaves data rows out (from 1, the header not counted); the readings kept know
// their file and row, which the listings of calibrate and verify name.
TEST_F(CsvFolder, ExcludedRowsAreLeftOutAndTheOthersKeepTheirRow) {
  json plan = examplePlan();
  const Plan listed = parsePlan(plan, "listed.json");
  write("front/hole_0.csv", csvOf(plan, 0, 1.0, "j1,j2,j3,j4,j5,j6"));
  write("front/hole_1.csv", csvOf(plan, 1, 1.0));
  plan["placements"][0]["measurements"] = json::array(
      {{{"feature", 0}, {"csv", "front/hole_0.csv"}, {"exclude_rows", json::array({2})}},
       {{"feature", 1}, {"csv", "front/hole_1.csv"}, {"exclude_rows", json::array()}}});
  const Plan fromCsv = loadPlan(write("plan.json", plan.dump()));
  EXPECT_TRUE(fromCsv.warnings.empty());
  const auto all0 = readingsOf(listed.placements[0], 0);
  ASSERT_EQ(all0.size(), 3u);
  std::vector<const Measurement*> kept0, kept1;
  for (const Measurement& m : fromCsv.placements[0].measurements)
    (m.feature == 0 ? kept0 : kept1).push_back(&m);
  ASSERT_EQ(kept0.size(), 2u);
  EXPECT_EQ(kept0[0]->csv_row, 1);
  EXPECT_EQ(kept0[1]->csv_row, 3);
  EXPECT_EQ(kept0[1]->csv, "front/hole_0.csv");
  EXPECT_LT((kept0[1]->joints - all0[2]).cwiseAbs().maxCoeff(), 1e-14);
  ASSERT_EQ(kept1.size(), 3u);
  EXPECT_EQ(kept1[2]->csv_row, 3);
  // Inline readings have no CSV row.
  EXPECT_EQ(listed.placements[0].measurements[0].csv_row, 0);
}

TEST_F(CsvFolder, WrongExcludedRowsNameTheirPointer) {
  json plan = examplePlan();
  write("front/hole_0.csv", csvOf(plan, 0, 1.0));
  write("front/hole_1.csv", csvOf(plan, 1, 1.0));
  const std::vector<std::pair<json, std::string>> cases = {
      {json::array({0}), "/exclude_rows/0"},
      {json::array({4}), "/exclude_rows/0"},
      {json::array({1, 1}), "/exclude_rows/1: row 1 is excluded twice"},
      {json::array({1, 2, 3}), "/exclude_rows: every row is excluded"},
      {json::array({"2"}), "/exclude_rows/0"},
      {json(2), "/exclude_rows"}};
  for (const auto& [rows, expected] : cases) {
    plan["placements"][0]["measurements"] =
        json::array({{{"feature", 0}, {"csv", "front/hole_0.csv"}, {"exclude_rows", rows}},
                     {{"feature", 1}, {"csv", "front/hole_1.csv"}}});
    const std::string path = write("plan.json", plan.dump());
    const auto run = test_support::runCli("check " + path, test_support::Stderr::Only);
    EXPECT_EQ(run.status, 2) << rows;
    EXPECT_NE(run.out.find("plan.json: /placements/0/measurements/0" + expected), std::string::npos)
        << rows << ": " << run.out;
  }
}

TEST_F(CsvFolder, CommandLineAnswersWithOneLineAndStatusTwo) {
  json plan = examplePlan();
  write("front/hole_0.csv", "1,2,3,4,5,6\n1,2,3,4,5\n");
  plan["placements"][0]["measurements"] =
      json::array({{{"feature", 0}, {"csv", "front/hole_0.csv"}},
                   {{"feature", 1}, {"csv", "front/hole_1.csv"}}});
  const std::string path = write("plan.json", plan.dump());
  const auto run = test_support::runCli("check " + path, test_support::Stderr::Only);
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.out, "error: " + (dir_ / "front/hole_0.csv").string() +
                         ": line 2: expected 6 readings, got 5\n");
  plan["placements"][0]["measurements"][0]["unit"] = "grad";
  const std::string unit = write("unit.json", plan.dump());
  const auto bad_unit = test_support::runCli("check " + unit, test_support::Stderr::Only);
  EXPECT_EQ(bad_unit.status, 2);
  EXPECT_NE(bad_unit.out.find("unit.json: /placements/0/measurements/0/unit: unknown unit"),
            std::string::npos);
}

/// `line` split at `separator` (no quotes in these lines).
std::vector<std::string_view> fieldsOf(std::string_view line, char separator = ',') {
  std::vector<std::string_view> out;
  for (std::size_t start = 0;;) {
    const std::size_t end = line.find(separator, start);
    out.push_back(line.substr(start, end == std::string_view::npos ? end : end - start));
    if (end == std::string_view::npos) return out;
    start = end + 1;
  }
}

// headerShift on hand-made lines, each answer read off the line by eye (csv_readings.hpp): the
// names over the row's last fields when the header is narrower and its names do not stand over
// numbers as written; a header as wide as the row, ending in empty names, shifted only when its
// names stood over text (a peer's export), not over an index written last (pandas).
TEST(HeaderShift, HandMadeHeadersAndRows) {
  struct Case {
    std::string header, row;
    std::vector<int> selected;
    std::size_t shift;
  };
  const std::vector<Case> cases = {
      {"j1,j2,j3", "1,2,3", {0, 1, 2}, 0},                // as written
      {"j1,j2,j3", "front,1,2,3", {0, 1, 2}, 1},          // one leading label unnamed
      {"j1,j2,j3", "front,7,1,2,3", {0, 1, 2}, 2},        // two leading fields unnamed
      {"j1,j2,j3", "4,1,2,3", {0, 1, 2}, 0},              // numbers as written: no shift
      {"j1,j2,j3,", "1,2,3,4", {0, 1, 2}, 0},             // a trailing index (pandas)
      {"j1,j2,j3,", "front,1,2,3", {0, 1, 2}, 1},         // names written left of their values
      {"j1,j2,j3,,", "front,label,1,2,3", {0, 1, 2}, 2},  // two of them
      {"j1,j2,j3", "1,2", {0, 1, 2}, 0},                  // a row narrower than its header
      {"t,j1,j2", "front,x,1,2", {1, 2}, 1},              // a named column of text, shifted
  };
  for (const Case& c : cases) {
    EXPECT_EQ(headerShift(fieldsOf(c.header), fieldsOf(c.row), c.selected), c.shift)
        << "header \"" << c.header << "\", row \"" << c.row << "\"";
  }
  // With ';' and decimal commas: "1,5" is one number.
  const CsvDialect semicolon = csvDialect("j1;j2;j3");
  EXPECT_EQ(headerShift(fieldsOf("j1;j2;j3", ';'), fieldsOf("front;1,5;2,5;3,5", ';'), {0, 1, 2},
                        semicolon),
            1u);
}

// The readings a header-named file gives, whatever unnamed fields its rows carry first or last:
// the numbers written under each name, in radians (the oracle: the values written).
TEST_F(CsvFolder, NamedColumnsReadTheValuesWrittenUnderTheirNames) {
  const std::vector<JointKind> kinds(3, JointKind::Revolute);
  std::vector<CsvColumn> columns(3);
  columns[0].name = "j1";
  columns[1].name = "j2";
  columns[2].name = "j3";
  const std::vector<std::vector<double>> written = {{10.0, -20.0, 30.5}, {11.0, 21.0, -31.25}};
  struct Layout {
    std::string header, before, after;
  };
  for (const Layout& layout :
       {Layout{"j1,j2,j3", "", ""}, Layout{"j1,j2,j3", "front,", ""},
        Layout{"j1,j2,j3", "front,0.5,", ""}, Layout{"j1,j2,j3,", "", ",7"},
        Layout{"j1,j2,j3,", "front,", ""}, Layout{"t,j2,j1,j3", "0.25,", ""}}) {
    std::string text = layout.header + "\n";
    const bool swapped = layout.header.rfind("t,j2", 0) == 0;
    for (const auto& r : written) {
      std::ostringstream row;
      row << layout.before;
      if (swapped)
        row << r[1] << "," << r[0] << "," << r[2];
      else
        row << r[0] << "," << r[1] << "," << r[2];
      row << layout.after << "\n";
      text += row.str();
    }
    const std::string file = (dir_ / "named.csv").string();
    std::ofstream(file) << text;
    const std::vector<Eigen::VectorXd> read = readJointCsv(file, kinds, {}, nullptr, &columns);
    ASSERT_EQ(read.size(), written.size()) << text;
    for (std::size_t r = 0; r < written.size(); ++r)
      for (int j = 0; j < 3; ++j)
        EXPECT_NEAR(read[r][j], written[r][static_cast<std::size_t>(j)] * std::numbers::pi / 180.0,
                    1e-15)
            << text << "row " << r << " joint " << j;
  }
}

}  // namespace csv_readings_test
}  // namespace artcal
