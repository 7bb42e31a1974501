// Hardening IV (issue 44, docs/hardening.md "Hardening IV"): numbers of 1e300 in an instrument's
// readings (a pose's point, its rotation vector, roll-pitch-yaw, a quaternion; inline and from
// CSV) and in a URDF. Each is refused where it is read, exit 2 with one line naming the file, the
// pointer (or the CSV line and column) and what to check: never "inf mm", "turns inf deg", a
// 300-digit norm, or "not a number" for a number. Then the outputs: no temporary file left by a
// run a signal ends while it writes; `plan --complete` of a design without placements. Then the
// rest of issue 44's findings (docs/hardening.md "every finding answered"): options given twice
// and numbers in options, copies of an instrument's readings, what a message names, flush
// contacts read as lines.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "test_paths.hpp"

namespace hostile_inputs_iv_test {

using namespace artcal::test_support;
using nlohmann::json;
namespace fs = std::filesystem;

struct Scratch {
  fs::path dir;
  Scratch() {
    std::string pattern = (fs::temp_directory_path() / "artcal-hostile4-XXXXXX").string();
    dir = ::mkdtemp(pattern.data());
  }
  ~Scratch() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  std::string file(const std::string& name) const { return (dir / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(file(name), std::ios::binary) << text;
    return file(name);
  }
};

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string inQuotes(const std::string& path) {
  return "'" + path + "'";
}

/// Exit 2, nothing on stdout, and exactly the line `error: FILE: REST` on stderr.
void expectRefusedWith(const std::string& arguments, const std::string& line) {
  const CliRun err = runCli(arguments, Stderr::Only);
  EXPECT_EQ(err.status, 2) << arguments;
  EXPECT_EQ(err.out, line + "\n");
  EXPECT_EQ(runCli(arguments).out, "");
}

json posePlan() {
  return json::parse(readText(planFile("tracker-arm6-pose.json")));
}

// ------------------------------------------------------------------ a pose written in the plan

TEST(HostileNumbersIV, APosesPointOf1e300IsRefusedAtItsCoordinate) {
  Scratch scratch;
  json plan = posePlan();
  plan["placements"][1]["measurements"][3]["point"][0] = 1e300;
  const std::string file = scratch.write("pose.json", plan.dump());
  expectRefusedWith("check " + inQuotes(file),
                    "error: " + file +
                        ": /placements/1/measurements/3/point/0: magnitude 1e+300 beyond 1e+09: "
                        "check the value and its units (mm, deg)");
}

TEST(HostileNumbersIV, APosesRotationVectorOf1e300IsRefusedAtItsCoordinateNotAsInfDeg) {
  Scratch scratch;
  json plan = posePlan();
  plan["placements"][1]["measurements"][3]["point"][5] = -1e300;
  const std::string file = scratch.write("pose.json", plan.dump());
  expectRefusedWith("check " + inQuotes(file),
                    "error: " + file +
                        ": /placements/1/measurements/3/point/5: magnitude 1e+300 beyond 1e+09: "
                        "check the value and its units (mm, deg)");
}

TEST(HostileNumbersIV, APointInMetresBeyond1e9MmIsRefused) {
  // 1e8 m is within the bound of a number as written, 1e11 mm is beyond the bound of a length.
  Scratch scratch;
  json plan = posePlan();
  json& reading = plan["placements"][1]["measurements"][3];
  for (int k = 0; k < 3; ++k) reading["point"][k] = reading["point"][k].get<double>() / 1000.0;
  reading["point_unit"] = "m";
  reading["point"][1] = 1e8;
  const std::string file = scratch.write("pose.json", plan.dump());
  expectRefusedWith("check " + inQuotes(file),
                    "error: " + file +
                        ": /placements/1/measurements/3/point/1: the measured point's coordinate "
                        "is 1e+11 mm, beyond 1e+09 mm (1000 km): check the value and its unit "
                        "(point_unit mm or m)");
}

// ------------------------------------------------------------ a pose station read from a CSV

/// The plan whose second station is read from station2.csv in orientation `form` (its readings
/// converted from the plan's rotation vectors, deg): a header, then one row per reading.
struct CsvStation {
  Scratch scratch;
  std::string plan, csv;
  std::vector<std::vector<double>> rows;
  std::string form;

  explicit CsvStation(std::string orientation) : form(std::move(orientation)) {
    json document = posePlan();
    for (const json& m : document["placements"][1]["measurements"]) {
      std::vector<double> row = m["joints"].get<std::vector<double>>();
      const std::vector<double> point = m["point"].get<std::vector<double>>();
      row.insert(row.end(), point.begin(), point.begin() + 3);
      const Eigen::Vector3d w(point[3], point[4], point[5]);  // deg
      const Eigen::AngleAxisd turn(w.norm() * M_PI / 180.0, w.normalized());
      if (form == "rotation_vector") {
        row.insert(row.end(), point.begin() + 3, point.end());
      } else if (form == "rpy") {
        // R = Rz(yaw) Ry(pitch) Rx(roll): eulerAngles(2, 1, 0) = (yaw, pitch, roll).
        const Eigen::Vector3d ypr = turn.toRotationMatrix().eulerAngles(2, 1, 0) * 180.0 / M_PI;
        row.insert(row.end(), {ypr[2], ypr[1], ypr[0]});
      } else {
        const Eigen::Quaterniond q(turn);
        row.insert(row.end(), {q.w(), q.x(), q.y(), q.z()});
      }
      rows.push_back(row);
    }
    document["placements"][1]["measurements"] =
        json::array({{{"csv", "station2.csv"}, {"orientation", form}}});
    plan = scratch.write("plan.json", document.dump());
    csv = scratch.file("station2.csv");
    writeRows();
  }

  void writeRows() const {
    std::ofstream out(csv);
    out << "j1,j2,j3,j4,j5,j6,x,y,z,o1,o2,o3" << (form == "quaternion" ? ",o4" : "") << "\n";
    out.precision(17);
    for (const std::vector<double>& row : rows) {
      for (std::size_t k = 0; k < row.size(); ++k) out << (k ? "," : "") << row[k];
      out << "\n";
    }
  }

  /// Row `row` (from 0) column `column` (from 0) set to `value`; the file written again.
  void set(std::size_t row, std::size_t column, double value) {
    rows[row][column] = value;
    writeRows();
  }
};

TEST(HostileNumbersIV, TheCsvStationsAreReadInEveryOrientationForm) {
  // The control of the tests below: the files they spoil, unspoilt, are read (exit 0).
  for (const char* form : {"rotation_vector", "rpy", "quaternion"}) {
    const CsvStation station(form);
    const CliRun run = runCli("check " + inQuotes(station.plan), Stderr::Merge);
    EXPECT_EQ(run.status, 0) << form << "\n" << run.out;
  }
}

TEST(HostileNumbersIV, ACsvPointOf1e300IsRefusedAtItsLineAndColumn) {
  CsvStation station("rotation_vector");
  station.set(3, 6, 1e300);  // line 5, x in column 7
  expectRefusedWith("check " + inQuotes(station.plan),
                    "error: " + station.csv +
                        ": line 5 (row 4): column 7: the measured x is 1e+300 mm, beyond 1e+09 mm "
                        "(1000 km): check the value, its unit (point_unit mm or m) and the "
                        "columns (the joints, then x, y, z)");
}

TEST(HostileNumbersIV, ACsvRotationVectorOf1e300IsRefusedAtItsColumnNotAsInfDeg) {
  CsvStation station("rotation_vector");
  station.set(0, 11, 1e300);  // line 2, rz in column 12
  expectRefusedWith("check " + inQuotes(station.plan),
                    "error: " + station.csv +
                        ": line 2 (row 1): column 12: the measured orientation's rz (a rotation "
                        "vector) is 1e+300 deg, more than a turn: check its unit "
                        "(orientation_unit deg or rad) and the columns (x, y, z, then rx, ry, "
                        "rz)");
  // Three coordinates of 1e200 (each within double, their squares not): the same, at the first.
  station.set(0, 9, 1e200);
  station.set(0, 10, 1e200);
  station.set(0, 11, 1e200);
  const CliRun run = runCli("check " + inQuotes(station.plan), Stderr::Only);
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.out.find(": line 2 (row 1): column 10: the measured orientation's rx (a rotation "
                         "vector) is 1e+200 deg"),
            std::string::npos)
      << run.out;
}

TEST(HostileNumbersIV, ACsvRollPitchYawOf1e300IsRefusedNotReadAsAnAngle) {
  CsvStation station("rpy");
  station.set(1, 10, 1e300);  // line 3, pitch in column 11
  expectRefusedWith("check " + inQuotes(station.plan),
                    "error: " + station.csv +
                        ": line 3 (row 2): column 11: the measured pitch is 1e+300 deg, more than "
                        "a turn: check its unit (orientation_unit deg or rad) and the columns (x, "
                        "y, z, then roll, pitch, yaw)");
}

TEST(HostileNumbersIV, ACsvQuaternionOf1e300IsRefusedWithoutA300DigitNorm) {
  CsvStation station("quaternion");
  station.set(0, 9, 1e300);  // line 2, w in column 10
  expectRefusedWith("check " + inQuotes(station.plan),
                    "error: " + station.csv +
                        ": line 2 (row 1): column 10: the quaternion's w is 1e+300, beyond 1 (a "
                        "unit quaternion's components are within [-1, 1]): check the columns (w, "
                        "x, y, z) and the entry's \"orientation\"");
}

// ------------------------------------------------------------------------------------- URDF

/// tests/data/urdf/arm3-slide.urdf with the first occurrence of `from` replaced by `to`.
std::string spoiltUrdf(const Scratch& scratch, const std::string& from, const std::string& to) {
  std::string text = readText(testDataFile("urdf/arm3-slide.urdf"));
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return scratch.write("robot.urdf", text);
}

TEST(HostileNumbersIV, AUrdfNumberOf1e306IsOutOfRangeNotNotANumber) {
  // j1's origin (line 26): 1e306 m is a number, 1e309 mm is beyond a double; 1e306 rad likewise
  // beyond 1e9 deg.
  Scratch scratch;
  const std::string origin = "<origin xyz=\"0 0 0.3\" rpy=\"0 0 0.25\"/>";
  const std::string lengths =
      spoiltUrdf(scratch, origin, "<origin xyz=\"1e306 0 0.3\" rpy=\"0 0 0.25\"/>");
  const std::string import = "import-urdf " + inQuotes(lengths) + " --base base --tip probe";
  expectRefusedWith(import, "error: " + lengths +
                                ": line 26: <origin xyz>: \"1e306\" is beyond 1e6 m (1e9 mm, 1000 "
                                "km): check the value (a URDF's lengths are in metres)");
  const std::string angles =
      spoiltUrdf(scratch, origin, "<origin xyz=\"0 0 0.3\" rpy=\"0 0 -1e306\"/>");
  expectRefusedWith(import, "error: " + angles +
                                ": line 26: <origin rpy>: \"-1e306\" is beyond 1.7e7 rad (1e9 "
                                "deg): check the value (a URDF's angles are in radians)");
}

// ------------------------------------------------------------------------------------ outputs

TEST(HostileOutputsIV, AnOutputCutShortByASignalLeavesNoTemporaryFile) {
  // simulate writes its output to a temporary file beside it, renamed into place when whole. A
  // file size limit of 16 blocks (8 or 16 KB) ends the run by SIGXFSZ in the middle of that
  // write, as a SIGTERM would at that moment, but at the same byte every time (no timing): the
  // run's handler removes the temporary file (it was left, cut short), then dies by the signal.
  Scratch scratch;
  json document = json::parse(readText(planFile("paper-2r-5bars.json")));
  const json placements = document["placements"];
  document["placements"] = json::array();
  for (std::size_t i = 0; i < 1000; ++i)
    document["placements"].push_back(placements[i % placements.size()]);
  const std::string plan =
      inQuotes(scratch.write("plan.json", document.dump())) + " --truth " +
      inQuotes(scratch.write("truth.json", R"({"parameters": {"l1": 150.02}})"));
  const std::string whole = scratch.file("whole/simulated.json");
  fs::create_directories(scratch.dir / "whole");
  ASSERT_EQ(runCli("simulate " + plan + " --seed 1 -o " + inQuotes(whole)).status, 0);
  ASSERT_GT(fs::file_size(whole), 64u * 1024u);  // the control: larger than the limit
  const fs::path folder = scratch.dir / "cut";
  fs::create_directories(folder);
  const std::string command = "ulimit -c 0; ulimit -f 16; exec " + std::string(ARTCAL_CLI) +
                              " simulate " + plan + " --seed 1 -o " +
                              inQuotes((folder / "simulated.json").string()) + " 2>/dev/null";
  const int status = std::system(("sh -c " + inQuotes(command) + " 2>/dev/null").c_str());
  ASSERT_TRUE(WIFSIGNALED(status) || (WIFEXITED(status) && WEXITSTATUS(status) > 128)) << status;
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(folder)) left.push_back(entry.path().string());
  EXPECT_TRUE(left.empty()) << left.size() << " file(s) left, the first " << left.front();
}

TEST(HostileOutputsIV, PlanCompleteOfADesignWithoutPlacementsSaysWhatPlansIt) {
  // An instrument's design (stations and readings, no placements): it was "/placements: missing
  // field", a field of the completed copy the user never wrote.
  Scratch scratch;
  const std::string spec = planFile("tracker-arm6.spec.json");
  const std::string out = scratch.file("out.json");
  expectRefusedWith("plan --complete " + inQuotes(spec) + " -o " + inQuotes(out),
                    "error: " + spec +
                        ": no placements: nothing to complete (plan --complete plans the "
                        "readings of placements that ask for them, {\"feature\": k, "
                        "\"postures\": N}); this plan's \"design\" is planned by `artcal "
                        "optimize " +
                        spec + " -o PLAN`");
  EXPECT_FALSE(fs::exists(out));
}

// ---------------------------------------------------------------- options: one rule for all

TEST(HostileOptionsIV, EveryNumberOptionReadsDecimalNumbersOnly) {
  // CLI11 read --seed 0x10 as 16 and --cube 0x10 as 16 mm, with exit 0.
  Scratch scratch;
  const std::string plan = inQuotes(planFile("paper-2r-5bars.json"));
  const std::string truth = inQuotes(scratch.write("truth.json", R"({"parameters": {}})"));
  const std::string out = inQuotes(scratch.file("out.json"));
  expectRefusedWith("simulate " + plan + " --truth " + truth + " --seed 0x10 -o " + out,
                    "error: --seed: expected a decimal number, not \"0x10\" (decimal numbers "
                    "only) (artcal --help; artcal COMMAND --help)");
  EXPECT_FALSE(fs::exists(scratch.file("out.json")));
  const std::string hexapod = inQuotes(planFile("hexapod-10bars.json"));
  expectRefusedWith("acceptance " + hexapod + " --test iso9283 --cube 0x10 --center 0,0,500",
                    "error: --cube: expected a decimal number, not \"0x10\" (decimal numbers "
                    "only) (artcal --help; artcal COMMAND --help)");
  expectRefusedWith("acceptance " + hexapod + " --test iso9283 --cube 1e300 --center 0,0,500",
                    "error: --cube: expected a decimal number within 1e9, not \"1e300\" "
                    "(artcal --help; artcal COMMAND --help)");
  // The control: decimal numbers are read.
  EXPECT_EQ(runCli("simulate " + plan + " --truth " + truth + " --seed 16 -o " + out).status, 0);
  EXPECT_EQ(runCli("acceptance " + hexapod + " --test iso9283 --cube 16 --center 0,0,500").status,
            0);
}

TEST(HostileOptionsIV, AStylusOffsetOf1e300IsRefusedNotWrittenAsNull) {
  // It wrote "null" and quantiles of 1e296.
  const std::string plan = inQuotes(planFile("cmm-plate-xy.json"));
  expectRefusedWith("acceptance " + plan +
                        " --test iso10360-2 --mpe '3 + L/300' --trials 10 --stylus-offset 1e300",
                    "error: --stylus-offset: expected a number >= 0 within 1e9, not \"1e300\" "
                    "(artcal --help; artcal COMMAND --help)");
  EXPECT_EQ(runCli("acceptance " + plan +
                   " --test iso10360-2 --mpe '3 + L/300' --trials 10 --stylus-offset 150")
                .status,
            0);
}

TEST(HostileOptionsIV, AnOptionGivenTwiceCountsOnceOrIsRefusedWhereItConflicts) {
  // One rule for every option of every command: the same value again counts once (CLI11 refused
  // it for an option of one value, while --hold took it once); two values are refused naming
  // both, where a repeatable option kept the first (--hold, --tip-of) or the last (--frame-of).
  Scratch scratch;
  const std::string plan = inQuotes(planFile("paper-2r-5bars.json"));
  const std::string truth = inQuotes(scratch.write("truth.json", R"({"parameters": {}})"));
  const std::string once = scratch.file("once.json"), twice = scratch.file("twice.json");
  ASSERT_EQ(
      runCli("simulate " + plan + " --truth " + truth + " --seed 3 -o " + inQuotes(once)).status,
      0);
  ASSERT_EQ(
      runCli("simulate " + plan + " --truth " + truth + " --seed 3 --seed 3 -o " + inQuotes(twice))
          .status,
      0);
  EXPECT_EQ(readText(once), readText(twice));
  expectRefusedWith("simulate " + plan + " --truth " + truth + " --seed 3 --seed 4 -o " +
                        inQuotes(scratch.file("conflict.json")),
                    "error: --seed: given twice, 3 and 4: give it once");
  EXPECT_FALSE(fs::exists(scratch.file("conflict.json")));
  EXPECT_EQ(runCli("check --json --json " + plan).status, 0);
  // A repeatable option: the same tip twice is one tip (it was refused as "given twice").
  const std::string urdf = inQuotes(testDataFile("urdf/humanoid-small.urdf")) +
                           " --base left_sole_link --tip gripper_left_base_link";
  const CliRun single = runCli("import-urdf " + urdf + " -o -");
  const CliRun repeated = runCli("import-urdf " + urdf + " --tip gripper_left_base_link -o -");
  ASSERT_EQ(single.status, 0);
  EXPECT_EQ(repeated.status, 0);
  EXPECT_EQ(repeated.out, single.out);
}

/// A flush plane plan simulated and calibrated in `scratch` (sim.json, cal.json), its first
/// placement named `table` (the calibration's frames are named after its placements).
void calibrateFlushPlanes(const Scratch& scratch, const std::string& table) {
  json plan = json::parse(readText(planFile("planes/arm6-flush.json")));
  plan["placements"].erase(3);  // the gauge block
  plan["placements"][0]["name"] = table;
  const std::string quiet = inQuotes(scratch.write("plan.json", plan.dump()));
  const std::string truth = inQuotes(scratch.write("truth.json", R"({"parameters": {}})"));
  const std::string sim = inQuotes(scratch.file("sim.json"));
  ASSERT_EQ(runCli("simulate " + quiet + " --truth " + truth + " --seed 4 -o " + sim).status, 0);
  ASSERT_EQ(
      runCli("calibrate " + sim + " --write-machine " + inQuotes(scratch.file("cal.json"))).status,
      0);
}

TEST(HostileOptionsIV, FrameOfGivenTwiceCountsOnceOrIsRefusedWhereItConflicts) {
  // verify --frame-of HELD=A --frame-of HELD=B scored HELD in B's frame, the last, unchecked.
  Scratch scratch;
  calibrateFlushPlanes(scratch, "table");
  const std::string verify = "verify --json " + inQuotes(scratch.file("sim.json")) + " --machine " +
                             inQuotes(scratch.file("cal.json"));
  const CliRun one = runCli(verify + " --frame-of wall=table");
  const CliRun same = runCli(verify + " --frame-of wall=table --frame-of wall=table");
  ASSERT_EQ(one.status, 0) << one.out;
  EXPECT_EQ(same.status, 0);
  EXPECT_EQ(same.out, one.out);
  expectRefusedWith(verify + " --frame-of wall=table --frame-of wall=slanted",
                    "error: --frame-of: wall=slanted: placement \"wall\" is paired twice, with "
                    "\"table\" and \"slanted\": give one --frame-of per placement");
}

TEST(HostileMessagesIV, TheFrameOfNoteSuggestsAnOptionThatIsTaken) {
  // The note printed `--frame-of table day2=table day1`, which the shell splits and verify
  // refuses: it quotes what it suggests, and the suggestion runs.
  Scratch scratch;
  calibrateFlushPlanes(scratch, "table day1");
  json held = json::parse(readText(scratch.file("sim.json")));
  held["placements"][0]["name"] = "table day2";
  const std::string file = inQuotes(scratch.write("held.json", held.dump()));
  const std::string against = file + " --machine " + inQuotes(scratch.file("cal.json"));
  const CliRun noted = runCli("verify " + against, Stderr::Only);
  ASSERT_EQ(noted.status, 0) << noted.out;
  const std::string option = "--frame-of 'table day2=table day1'";
  EXPECT_NE(noted.out.find("also score it in that frame: " + option + "\n"), std::string::npos)
      << noted.out;
  const CliRun taken = runCli("verify --json " + against + " " + option);
  ASSERT_EQ(taken.status, 0) << taken.out;
  const json placement = json::parse(taken.out)["verify"]["placements"][0];
  EXPECT_EQ(placement["in_calibration_frame"]["frame_of"], "table day1") << placement.dump();
}

// ------------------------------------------------------ copies of an instrument's readings

/// `plan` with each placement's readings written `copies` times over.
std::string withEveryReadingWritten(const Scratch& scratch, const std::string& plan, int copies) {
  json document = json::parse(readText(planFile(plan)));
  for (json& placement : document["placements"]) {
    json written = json::array();
    for (const json& reading : placement["measurements"])
      for (int copy = 0; copy < copies; ++copy) written.push_back(reading);
    placement["measurements"] = written;
  }
  return scratch.write(std::to_string(copies) + "-" + plan, document.dump());
}

TEST(HostileRepeatsIV, CopiesOfTrackerReadingsAreFoundAndCountedOnce) {
  // Each instrument reading is a feature of its own, so the repeat key (the feature index among
  // it) never matched: a tracker plan written twice calibrated on 567 degrees of freedom instead
  // of 267, no warning, --repeats once removed nothing, every u sqrt(2) too small.
  Scratch scratch;
  for (const char* plan : {"tracker-arm6-pose.json", "tracker-arm6-2stations.json"}) {
    const std::string once = inQuotes(planFile(plan));
    const std::string twice = inQuotes(withEveryReadingWritten(scratch, plan, 2));
    const json a = json::parse(runCli("calibrate --json " + once).out);
    const json b = json::parse(runCli("calibrate --json --repeats once " + twice).out);
    const json c = json::parse(runCli("calibrate --json " + twice).out);
    EXPECT_EQ(b["dof"], a["dof"]) << plan;
    ASSERT_EQ(b["parameters"].size(), a["parameters"].size()) << plan;
    for (std::size_t k = 0; k < a["parameters"].size(); ++k) {
      const double u = a["parameters"][k]["u"].get<double>();
      EXPECT_NEAR(b["parameters"][k]["u"].get<double>(), u, 1e-9 * u) << plan;
    }
    bool warned = false;
    for (const json& warning : c["warnings"]) {
      const std::string text = warning.get<std::string>();
      warned |= text.find("readings repeat another bit for bit") != std::string::npos &&
                text.find("up to 1.41x too small") != std::string::npos;
    }
    EXPECT_TRUE(warned) << plan << ": " << c["warnings"].dump();
  }
}

// ------------------------------------------- what a message names: the option, the file read

TEST(HostileMessagesIV, APriorOrAPoseFileIsNamedNotTheOutputPlan) {
  // A bad --prior or a folder's pose.json was reported against the output plan, never written:
  // "error: out.json: /machine/prior/default/length: ...", ".../placements/0/pose/center/2".
  Scratch scratch;
  fs::create_directories(scratch.dir / "bar");
  scratch.write("bar/feature_0.csv", "j1 [deg],j2 [deg],j3 [mm]\n10,20,30\n11,21,31\n");
  const std::string arm = " --urdf " + inQuotes(testDataFile("urdf/arm3-slide.urdf")) +
                          " --base world --tip probe --ball-bar 100";
  const std::string bar = "import-readings " + inQuotes(scratch.file("bar")) + arm;
  const std::string out = " -o " + inQuotes(scratch.file("out.json"));
  expectRefusedWith(bar + " --hold j4=0 --prior 1e300,1" + out,
                    "error: --prior: 1e+300,1: expected LENGTH,ANGLE (mm, deg), each > 0 and "
                    "within 1e9, e.g. 5,0.5");
  const std::string pose =
      scratch.write("bar/pose.json", R"({"center": [0, 0, 1e300], "direction": [0, 0, 1]})");
  expectRefusedWith(bar + " --hold j4=0" + out,
                    "error: " + pose +
                        ": /center/2: magnitude 1e+300 beyond 1e+09: check the value and its "
                        "units (mm, deg)");
  scratch.write("bar/pose.json", R"({"center": "x"})");
  expectRefusedWith(bar + " --hold j4=0" + out,
                    "error: " + pose + ": /center: expected 3 numbers, got a string");
  EXPECT_FALSE(fs::exists(scratch.file("out.json")));
}

TEST(HostileMessagesIV, AHeldValueIsNamedAtItsOptionNotAsACsvColumn) {
  // --hold j4=1e300 was "feature_0.csv: /columns/3: magnitude ...", --hold j4=-1e8 "line 2 (row
  // 1): reading -100000000 deg of joint 4", and --hold j4=500 widened j4's limits "to the
  // readings".
  Scratch scratch;
  fs::create_directories(scratch.dir / "bar");
  scratch.write("bar/feature_0.csv", "j1 [deg],j2 [deg],j3 [mm]\n10,20,30\n11,21,31\n");
  const std::string bar = "import-readings " + inQuotes(scratch.file("bar")) + " --urdf " +
                          inQuotes(testDataFile("urdf/arm3-slide.urdf")) +
                          " --base world --tip probe --ball-bar 100 -o " +
                          inQuotes(scratch.file("out.json"));
  // j4 is continuous: its readings may reach a turn beyond its limits (540 deg).
  expectRefusedWith(bar + " --hold j4=1e300",
                    "error: --hold: j4=1e+300: joint \"j4\" held at 1e+300 deg, beyond what its "
                    "readings may reach (-540 .. 540 deg, its joint_limits [-180, 180] deg): "
                    "check the value (deg, or mm for a prismatic joint)");
  expectRefusedWith(bar + " --hold j4=-1e8",
                    "error: --hold: j4=-100000000: joint \"j4\" held at -100000000 deg, beyond "
                    "what its readings may reach (-540 .. 540 deg, its joint_limits [-180, 180] "
                    "deg): check the value (deg, or mm for a prismatic joint)");
  EXPECT_EQ(runCli(bar + " --hold j4=90").status, 0);
}

// ------------------------------------------------------------ flush contacts: lines, not rays

TEST(HostileValuesIV, FlushVerifyIsTheSameWithANormalOrAToolAxisOfTheOtherSign) {
  // calibrate gives the same estimates bit for bit when a plane's normal (or the tool axis) is
  // written with the other sign; verify said 180 deg of roll for every touch.
  Scratch scratch;
  json plan = json::parse(readText(planFile("planes/arm6-flush.json")));
  plan["placements"].erase(3);  // the gauge block
  const std::string quiet = inQuotes(scratch.write("plan.json", plan.dump()));
  const std::string truth = inQuotes(scratch.write("truth.json", R"({"parameters": {}})"));
  const std::string sim = scratch.file("sim.json");
  ASSERT_EQ(
      runCli("simulate " + quiet + " --truth " + truth + " --seed 4 -o " + inQuotes(sim)).status,
      0);
  json normals = json::parse(readText(sim));
  for (json& placement : normals["placements"]) {
    for (json& x : placement["pose"]["direction"]) x = -x.get<double>();
  }
  json axis = json::parse(readText(sim));
  for (json& x : axis["artifacts"]["table"]["axis"]) x = -x.get<double>();
  const auto flush = [](const std::string& file) {
    const CliRun run = runCli("verify --json " + inQuotes(file));
    EXPECT_EQ(run.status, 0) << run.out;
    return json::parse(run.out)["verify"]["flush"];
  };
  const json as_written = flush(sim);
  ASSERT_LT(as_written["roll_rms_deg"].get<double>(), 0.01);  // u_tilt 0.002 deg
  for (const json& other : {flush(scratch.write("normals.json", normals.dump())),
                            flush(scratch.write("axis.json", axis.dump()))}) {
    for (const char* figure : {"height_rms", "roll_rms_deg", "pitch_rms_deg"}) {
      EXPECT_NEAR(other[figure].get<double>(), as_written[figure].get<double>(),
                  1e-9 * (1.0 + as_written[figure].get<double>()))
          << figure;
    }
  }
}

TEST(HostileMessagesIV, ATableSpindleBarInAnOptimizeSpecIsNamedAtItsPointer) {
  // It failed deep in the search: "the spindle's ball is at the table ball's centre: no bar
  // direction", naming no field.
  Scratch scratch;
  json spec = json::parse(readText(planFile("machine-tool-trunnion-8probings.spec.json")));
  spec["artifacts"] = {{"bar", {{"type", "ball_bar"}, {"ends", "table-spindle"}, {"length", 100}}}};
  spec["design"]["artifact"] = "bar";
  const std::string file = scratch.write("spec.json", spec.dump());
  expectRefusedWith("optimize " + inQuotes(file) + " -o " + inQuotes(scratch.file("out.json")),
                    "error: " + file +
                        ": /design/artifact: \"bar\" is a table-spindle ball bar, which optimize "
                        "does not place: write its placements and readings in a plan "
                        "(docs/five-axis.md section 3), or design with a sphere");
}

}  // namespace hostile_inputs_iv_test
