// Hardening III (issue 32, docs/hardening.md "Hardening III"): the newer surfaces (import-readings
// folders, calibrate without degrees of freedom, values that do not exist, repeated readings,
// work caps, messages, acceptance from a machine file, outputs). One test per class; each asserts
// the documented answer. Regression inputs: tests/data/hostile/ or generated here (links, FIFOs
// and devices cannot be committed).

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "test_paths.hpp"

namespace hostile_inputs_iii_test {

using namespace artcal::test_support;
using nlohmann::json;
namespace fs = std::filesystem;

struct Scratch {
  fs::path dir;
  Scratch() {
    std::string pattern = (fs::temp_directory_path() / "artcal-hostile3-XXXXXX").string();
    dir = ::mkdtemp(pattern.data());
  }
  ~Scratch() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
  std::string file(const std::string& name) const { return (dir / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    fs::create_directories((dir / name).parent_path());
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

std::string quoted(const std::string& path) {
  return "'" + path + "'";
}

/// Exit 2 and exactly one line `error: FILE: ...` holding `part`.
void expectRefused(const std::string& arguments, const std::string& file, const std::string& part) {
  const CliRun run = runCli(arguments, Stderr::Only);
  EXPECT_EQ(run.status, 2) << arguments << "\n" << run.out;
  EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1) << run.out;
  EXPECT_EQ(run.out.rfind("error: " + file + ": ", 0), 0u) << run.out;
  EXPECT_NE(run.out.find(part), std::string::npos) << "expected \"" << part << "\" in " << run.out;
}

// ------------------------------------------------------------- import-readings: the folder walk

/// A folder of two tracker stations (plans/tracker-arm6, joints deg, points m) and the machine.
struct StationFolder {
  Scratch scratch;
  std::string machine, stations;
  StationFolder() {
    const json plan = json::parse(readText(planFile("tracker-arm6-2stations-csv.json")));
    machine = scratch.write("machine.json", plan["machine"].dump());
    stations = scratch.file("stations");
    fs::create_directories(stations);
    for (const char* name : {"station1.csv", "station2.csv"})
      fs::copy_file(planFile(std::string("tracker-arm6/") + name), fs::path(stations) / name);
  }
  std::string command(const std::string& folder) const {
    return "import-readings " + quoted(folder) + " --machine " + quoted(machine) +
           " --instrument 0.01 --unit deg --point-unit m -o " + quoted(scratch.file("out.json"));
  }
};

TEST(HostileFolders, EveryFileIsReadOnceOrRefusedNamingIt) {
  StationFolder f;
  const fs::path dir = f.stations;
  ASSERT_EQ(runCli(f.command(f.stations)).status, 0);
  // A link to the folder itself merged both stations into one placement (exit 0).
  fs::create_directory_symlink(".", dir / "self");
  expectRefused(f.command(f.stations), (dir / "self").string(), "a loop");
  fs::remove(dir / "self");
  // A link to a device, a FIFO, a directory named like a CSV: skipped without a word.
  fs::create_symlink("/dev/null", dir / "s3.csv");
  expectRefused(f.command(f.stations), (dir / "s3.csv").string(), "a device, named like a CSV");
  fs::remove(dir / "s3.csv");
  ASSERT_EQ(::mkfifo((dir / "s4.csv").c_str(), 0600), 0);
  expectRefused(f.command(f.stations), (dir / "s4.csv").string(), "a FIFO, named like a CSV");
  fs::remove(dir / "s4.csv");
  fs::create_directory(dir / "s5.csv");
  expectRefused(f.command(f.stations), (dir / "s5.csv").string(), "a directory, named like");
  fs::remove(dir / "s5.csv");
  // A second name of one file: read twice.
  fs::create_symlink("station1.csv", dir / "again.csv");
  expectRefused(f.command(f.stations), (dir / "station1.csv").string(), "is the same file as");
  fs::remove(dir / "again.csv");
  // A loose CSV beside station sub-folders: dropped without a word.
  fs::create_directory(dir / "sub");
  fs::copy_file(dir / "station1.csv", dir / "sub" / "station1.csv");
  expectRefused(f.command(f.stations), (dir / "station1.csv").string(),
                "a CSV file beside station sub-folders");
  fs::remove_all(dir / "sub");
  // A name that is not UTF-8: reported against the machine file.
  const std::string bad = std::string("x") + char(0xFF) + ".csv";
  std::ofstream(dir / bad) << "1\n";
  expectRefused(f.command(f.stations), (dir / "x\\xFF.csv").string(), "not valid UTF-8");
  fs::remove(dir / bad);
  // A header of 2000 columns: refused by its count, before it is split (120 million took 2.3 GB).
  f.scratch.write("stations/wide.csv", std::string(2000, ',') + "\n");
  expectRefused(f.command(f.stations), (dir / "wide.csv").string(), "more than 1024 columns");
}

TEST(HostileFolders, UnreadCsvFilesAreNamedInAWarning) {
  // A placement folder's CSV that is no feature file is said, not dropped silently: MUKCa's
  // front_center holds hole_0.csv, hole_1.csv (read) and hole_0_pose.csv, hole_1_pose.csv.
  Scratch scratch;
  const std::string mukca = testDataFile("mukca/mukca");
  fs::create_directories(scratch.file("p"));
  fs::copy(mukca + "/panda_2/front_center", scratch.file("p/front_center"));
  scratch.write("p/front_center/notes.csv", "a,b\n");
  scratch.write("p/loose.csv", "a,b\n");
  const CliRun run = runCli("import-readings " + quoted(scratch.file("p")) + " --urdf " +
                                quoted(mukca + "/urdf/panda.urdf") +
                                " --base panda_link0 --tip ball_link --ball-bar 50 --unit deg -o -",
                            Stderr::Only);
  ASSERT_EQ(run.status, 0) << run.out;
  EXPECT_NE(run.out.find("warning: 4 CSV file(s) of "), std::string::npos) << run.out;
  for (const char* name : {"front_center/hole_0_pose.csv", "front_center/hole_1_pose.csv",
                           "front_center/notes.csv", "loose.csv"})
    EXPECT_NE(run.out.find(name), std::string::npos) << name << " in " << run.out;
}

/// The folder-layout fuzzer (bounded, deterministic): random layouts of station files, copies,
/// links to files, to the folder, to a parent, to devices, FIFOs, directories named like CSV
/// files, notes and empty folders. Every answer is exit 0 with each CSV file of the plan a
/// distinct file, or exit 2 with one line naming a path of the layout; never a crash.
TEST(HostileFolders, RandomLayoutsAreReadOnceOrRefusedNamingAPath) {
  StationFolder f;
  const std::string source = readText((fs::path(f.stations) / "station1.csv").string());
  std::mt19937 random(32);
  int refused = 0, accepted = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const fs::path dir = f.scratch.dir / ("layout" + std::to_string(trial));
    fs::create_directories(dir);
    const bool folders = random() % 2 == 0;
    const int entries = 1 + static_cast<int>(random() % 5);
    for (int e = 0; e < entries; ++e) {
      const fs::path at = folders ? dir / ("s" + std::to_string(e)) : dir;
      fs::create_directories(at);
      const std::string name = "r" + std::to_string(e) + ".csv";
      switch (random() % 9) {
        case 0:
        case 1:
        case 2:
          std::ofstream(at / name) << source;
          break;
        case 3:
          std::ofstream(at / name) << source;
          fs::create_symlink(name, at / ("copy" + std::to_string(e) + ".csv"));
          break;
        case 4:
          fs::create_directory_symlink(fs::absolute(dir), at / ("up" + std::to_string(e)));
          break;
        case 5:
          fs::create_symlink("/dev/zero", at / name);
          break;
        case 6:
          ::mkfifo((at / name).c_str(), 0600);
          break;
        case 7:
          fs::create_directory(at / name);
          break;
        default:
          std::ofstream(at / ("notes" + std::to_string(e) + ".txt")) << "notes\n";
          std::ofstream(dir / name) << source;  // loose beside sub-folders when there are some
          break;
      }
    }
    const CliRun run = runCli(f.command(dir.string()), Stderr::Only);
    if (run.status == 2) {
      ++refused;
      EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1) << run.out;
      EXPECT_EQ(run.out.rfind("error: " + dir.string(), 0), 0u) << run.out;
      continue;
    }
    ASSERT_EQ(run.status, 0) << run.out;
    ++accepted;
    const json plan = json::parse(readText(f.scratch.file("out.json")));
    std::set<fs::path> files;
    for (const json& placement : plan["placements"]) {
      for (const json& entry : placement["measurements"]) {
        const fs::path file = fs::canonical(f.scratch.dir / entry["csv"].get<std::string>());
        EXPECT_TRUE(files.insert(file).second) << file << " read twice";
      }
    }
  }
  // Both answers occur (the generator is not degenerate).
  EXPECT_GT(refused, 0);
  EXPECT_GT(accepted, 0);
}

// ------------------------------------------------------- calibrate without degrees of freedom

TEST(HostileCalibrate, NoDegreesOfFreedomGivesCheckSAnswerNotConverged) {
  const std::string plan = testDataFile("hostile/tracker-one-station-3-readings.json");
  const CliRun check = runCli("check " + quoted(plan));
  const CliRun calibrate = runCli("calibrate " + quoted(plan));
  EXPECT_EQ(check.status, 1);
  EXPECT_EQ(calibrate.status, check.status);
  EXPECT_EQ(calibrate.out, check.out);  // the answer is check's, word for word
  EXPECT_EQ(calibrate.out.find("converged"), std::string::npos);
  EXPECT_EQ(calibrate.out.find("estimated from the fit"), std::string::npos);
  EXPECT_EQ(runCli("calibrate --json " + quoted(plan)).out,
            runCli("check --json " + quoted(plan)).out);
  const CliRun said = runCli("calibrate " + quoted(plan), Stderr::Only);
  EXPECT_NE(said.out.find("degrees of freedom -18"), std::string::npos) << said.out;
}

TEST(HostileCalibrate, AnEstimatedNoiseAtZeroDegreesOfFreedomIsRefused) {
  // 2 stations of 6 and 5 readings: 33 coordinates, 12 station unknowns, 21 parameters: dof 0.
  Scratch scratch;
  json plan = json::parse(readText(planFile("tracker-arm6-2stations.simulated.json")));
  auto& first = plan["placements"][0]["measurements"];
  first.erase(first.begin() + 6, first.end());
  auto& second = plan["placements"][1]["measurements"];
  second.erase(second.begin() + 5, second.end());
  plan["noise"]["probe"] = "estimate";
  const std::string file = scratch.write("dof0.json", plan.dump());
  expectRefused("calibrate " + quoted(file), file, "/noise/probe: \"estimate\" needs more");
}

// ------------------------------------------------------------ values that do not exist, numbers

TEST(HostileValues, VerifyWithoutCalibrationHasNoPosterior) {
  const std::string plan = quoted(planFile("tracker-arm6-2stations.simulated.json"));
  const json out = json::parse(runCli("verify --json " + plan).out);
  int stations = 0;
  for (const json& station : out["instrument"]["stations"]) {
    EXPECT_TRUE(station["predicted_rms_posterior"].is_null()) << station.dump();
    ++stations;
  }
  EXPECT_EQ(stations, 2);
  EXPECT_TRUE(out["instrument"]["all"]["predicted_rms_posterior"].is_null());
  const std::string table = runCli("verify " + plan).out;
  EXPECT_EQ(table.find(" 0.0000\n"), std::string::npos) << table;
  EXPECT_NE(table.find("            -\n"), std::string::npos) << table;
}

TEST(HostileValues, ARotationVectorLongerThanATurnNamesTheReading) {
  Scratch scratch;
  json plan = json::parse(readText(planFile("tracker-arm6-pose.json")));
  plan["placements"][1]["measurements"][3]["point"][4] = 1e8;
  const std::string file = scratch.write("pose.json", plan.dump());
  expectRefused("check " + quoted(file), file,
                "/placements/1/measurements/3/point: the measured orientation (a rotation "
                "vector) turns 1e+08 deg, more than a turn");
}

TEST(HostileValues, NumberOptionsNameTheOption) {
  const std::string plan = quoted(testDataFile("ref-2r-5bars.json"));
  CliRun run = runCli("evaluate " + plan + " --rank-tol nan", Stderr::Only);
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.out, "error: --rank-tol: nan: expected a finite number (every number option)\n");
  run = runCli("evaluate " + plan + " --rank-tol=-inf", Stderr::Only);
  EXPECT_EQ(run.out, "error: --rank-tol: -inf: expected a finite number (every number option)\n");
}

// ----------------------------------------------------------------------- repeated readings

TEST(HostileRepeats, RepeatedReadingsAreNamedInAWarning) {
  const std::string file = testDataFile("hostile/repeated-readings.json");
  const CliRun run = runCli("calibrate --json " + quoted(file));
  const json out = json::parse(run.out);
  bool named = false;
  for (const json& warning : out["warnings"]) {
    const std::string text = warning.get<std::string>();
    if (text.find("readings repeat another bit for bit") == std::string::npos) continue;
    named = true;
    // Placement 0: 2 readings, each written 4 times: 6 copies of 8, the first copy reading 2;
    // u up to sqrt(8 / 2) = 2 times too small.
    EXPECT_NE(text.find("placement 0: 6 of 8 readings"), std::string::npos) << text;
    EXPECT_NE(text.find("/placements/0/measurements/2 = /placements/0/measurements/0"),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("up to 2x too small"), std::string::npos) << text;
  }
  EXPECT_TRUE(named) << out["warnings"].dump();
}

// --repeats once: copies counted once. A simulated plan with every reading written 3 times
// calibrates, with the option, to the plan written once: the same estimates and u; without it,
// each u about sqrt(3) smaller (the copies counted as measurements), and the warning says so.
TEST(HostileRepeats, RepeatsOnceCalibratesAsTheReadingsWrittenOnce) {
  Scratch scratch;
  const std::string truth = scratch.write("truth.json", R"({"parameters": {"E_X0C": 0.03}})");
  const std::string once = scratch.file("once.json");
  ASSERT_EQ(runCli("simulate " + quoted(planFile("machine-tool-trunnion-2spheres.json")) +
                   " --truth " + quoted(truth) + " --seed 3 -o " + quoted(once))
                .status,
            0);
  json plan = json::parse(std::ifstream(once));
  for (json& placement : plan["placements"]) {
    json thrice = json::array();
    for (const json& m : placement["measurements"])
      for (int copy = 0; copy < 3; ++copy) thrice.push_back(m);
    placement["measurements"] = thrice;
  }
  const std::string repeated = scratch.write("repeated.json", plan.dump());
  const json a = json::parse(runCli("calibrate --json " + quoted(once)).out);
  const json b = json::parse(runCli("calibrate --json --repeats once " + quoted(repeated)).out);
  const json c = json::parse(runCli("calibrate --json " + quoted(repeated)).out);
  ASSERT_EQ(a["parameters"].size(), b["parameters"].size());
  ASSERT_EQ(a["parameters"].size(), c["parameters"].size());
  for (std::size_t k = 0; k < a["parameters"].size(); ++k) {
    const double u = a["parameters"][k]["u"].get<double>();
    EXPECT_NEAR(b["parameters"][k]["estimate"].get<double>(),
                a["parameters"][k]["estimate"].get<double>(), 1e-9 * u);
    EXPECT_NEAR(b["parameters"][k]["u"].get<double>(), u, 1e-9 * u);
    EXPECT_NEAR(c["parameters"][k]["u"].get<double>(), u / std::sqrt(3.0), 1e-6 * u);
  }
  EXPECT_EQ(b["dof"], a["dof"]);
  bool warned = false;
  for (const json& warning : c["warnings"])
    warned |= warning.get<std::string>().find("calibrate --repeats once") != std::string::npos;
  EXPECT_TRUE(warned) << c["warnings"].dump();
  EXPECT_EQ(runCli("calibrate --repeats twice " + quoted(repeated)).status, 2);
}

// --------------------------------------------------------------------------------- work caps

TEST(HostileWork, TooManyLengthTestLinesAreRefusedNamingTheFile) {
  Scratch scratch;
  json lines = json::array();
  for (int i = 0; i < 3000; ++i) lines.push_back({1.0, 0.0, 0.0});
  const std::string file = scratch.write("lines.json", lines.dump());
  expectRefused("acceptance " + quoted(planFile("cmm-plate-xy.json")) +
                    " --test iso10360-2 --mpe '3 + L/300' --lines " + quoted(file),
                file, "3000 lines, more than 256");
}

// ------------------------------------------------------------------ acceptance, MPE, outputs

TEST(HostileAcceptance, AMachineFileWarnsOfTheParametersItDidNotCalibrate) {
  Scratch scratch;
  const std::string truth = scratch.write("truth.json", R"({"parameters": {"y.tx.1": 0.003}})");
  const std::string simulated = scratch.file("sim.json"), machine = scratch.file("m.json");
  ASSERT_EQ(runCli("simulate " + quoted(planFile("cmm-plate-xy.json")) + " --truth " +
                   quoted(truth) + " --seed 3 -o " + quoted(simulated))
                .status,
            0);
  const json calibration = json::parse(
      runCli("calibrate --json " + quoted(simulated) + " --write-machine " + quoted(machine)).out);
  ASSERT_TRUE(calibration["converged"].get<bool>());
  const std::string test = " --test iso10360-2 --mpe '3 + L/300' --trials 200 --json";
  const json from_plan = json::parse(runCli("acceptance " + quoted(simulated) + test).out);
  const json from_machine = json::parse(
      runCli("acceptance " + quoted(machine) + " --plan " + quoted(simulated) + test).out);
  const auto names = [](const json& out) {
    std::set<std::string> warned;
    for (const json& w : out["warnings"]) {
      const std::string text = w.get<std::string>();
      warned.insert(text.substr(10, text.find(' ', 10) - 10));  // "parameter NAME is ..."
    }
    return warned;
  };
  const std::set<std::string> plan_names = names(from_plan), machine_names = names(from_machine);
  EXPECT_FALSE(plan_names.empty());
  // The same calibration: every parameter the plan's prediction warns of, and besides only the
  // 3 the calibration held at nominal (z.tx.3 z.ty.3 z.tz.3), not 11 more from the estimate.
  for (const std::string& name : plan_names) EXPECT_TRUE(machine_names.count(name)) << name;
  EXPECT_LE(machine_names.size(), plan_names.size() + 3);
  // In table mode the warnings go to stderr: stdout is the table alone.
  const CliRun table = runCli("acceptance " + quoted(machine) + " --plan " + quoted(simulated) +
                              " --test iso10360-2 --mpe '3 + L/300' --trials 200");
  EXPECT_EQ(table.out.find("warning"), std::string::npos) << table.out;
}

TEST(HostileAcceptance, DatasheetMpeFormsAreRead) {
  const std::string plan = quoted(planFile("cmm-plate-xy.json"));
  const auto mpeOf = [&](const std::string& mpe) {
    return json::parse(
        runCli("acceptance " + plan + " --test iso10360-2 --trials 100 --json --mpe '" + mpe + "'")
            .out);
  };
  const json ratio = mpeOf("3 + L/250"), product = mpeOf("3 + 0.004*L"),
             capped = mpeOf("min(3 + L/250, 3.5)");
  ASSERT_EQ(ratio["items"].size(), product["items"].size());
  for (std::size_t i = 0; i < ratio["items"].size(); ++i) {
    const double length = ratio["items"][i]["length"].get<double>();
    const double expected = 3.0 + length / 250.0;  // um
    EXPECT_NEAR(product["items"][i]["mpe_um"].get<double>(), expected, 1e-9);
    EXPECT_NEAR(ratio["items"][i]["mpe_um"].get<double>(), expected, 1e-9);
    EXPECT_NEAR(capped["items"][i]["mpe_um"].get<double>(), std::min(expected, 3.5), 1e-9);
  }
  EXPECT_EQ(capped["mpe_C_um"].get<double>(), 3.5);
  expectRefused("acceptance " + plan + " --test iso10360-2 --mpe 'min(3 + L/250, 2)'", "--mpe",
                "cap C must be a number at least A");
}

TEST(HostileOutputs, DevStdoutIntoAPipeSuggestsTheDash) {
  const std::string plan = quoted(testDataFile("ref-2r-5bars.json"));
  Scratch scratch;
  const std::string truth = scratch.write("truth.json", R"({"parameters": {"l1": 150.01}})");
  const CliRun run =
      runCli("simulate " + plan + " --truth " + quoted(truth) + " -o /dev/stdout 2>&1 | cat");
  EXPECT_NE(run.out.find("error: /dev/stdout: is a FIFO"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("use - for standard output"), std::string::npos) << run.out;
}

// A machine whose "joints" lost a row while its joint_limits kept one per joint of the plan's
// readings: the message names the machine's joint count, not the limits alone (the finding
// blamed /joint_limits with "expected at most 5 entries, got 6").
TEST(HostileInputsIII, AMachineWithAJointLeftOutNamesTheJointCount) {
  Scratch scratch;
  json plan = json::parse(readText(planFile("aacmm-6axis-3bars.json")));
  ASSERT_EQ(plan["machine"]["joints"].size(), 6u);
  plan["machine"]["joints"].erase(5);
  json calibrate = json::array();
  for (const json& name : plan["machine"]["calibrate"])
    if (name.get<std::string>().rfind("j6.", 0) != 0) calibrate.push_back(name);
  plan["machine"]["calibrate"] = calibrate;
  const std::string path = scratch.write("five.json", plan.dump());
  expectRefused("check " + quoted(path), path,
                "/machine/joint_limits: 6 entries, but the machine described has 5 joints "
                "(model \"serial-dh\"): one [lower, upper] per joint; check the machine's "
                "joints as well as these limits");
}

// Readings that identify nothing: one probing per sphere, each absorbed by the sphere's position.
// "identifiable" kept no parameter, and check and evaluate crashed on the empty set (SIGSEGV); an
// optimize spec of one posture per placement crashed in the search (SIGFPE). Now the listed set
// stays and check, evaluate and calibrate answer NOT IDENTIFIABLE (exit 1, every parameter to
// fix named), and optimize says what to add.
TEST(HostileInputsIII, ReadingsThatIdentifyNothingAreAnsweredNotCrashedOn) {
  Scratch scratch;
  json plan = json::parse(readText(planFile("machine-tool-trunnion-2spheres.json")));
  for (json& placement : plan["placements"])
    placement["measurements"] = json::array({placement["measurements"][0]});
  plan["machine"]["calibrate"] = "identifiable";
  const std::string path = scratch.write("one-probing.json", plan.dump());
  for (const char* command : {"check ", "evaluate ", "calibrate "}) {
    const CliRun run = runCli(command + quoted(path));
    EXPECT_EQ(run.status, 1) << command << run.out;
    EXPECT_NE(run.out.find("NOT IDENTIFIABLE"), std::string::npos) << command << run.out;
    EXPECT_NE(run.out.find("fix: E_Y0A"), std::string::npos) << command << run.out;
  }
  json spec = json::parse(readText(planFile("machine-tool-trunnion-8probings.spec.json")));
  spec["design"]["placements"] = 8;
  spec["design"]["postures"] = 1;
  spec["design"]["starts"] = 1;
  const std::string spec_path = scratch.write("one-posture.spec.json", spec.dump());
  expectRefused("optimize " + quoted(spec_path) + " -o " + quoted(scratch.file("out.json")),
                spec_path, "/design/postures: ");
  EXPECT_FALSE(fs::exists(scratch.file("out.json")));
}

}  // namespace hostile_inputs_iii_test
