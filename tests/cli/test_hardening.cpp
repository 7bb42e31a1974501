// Hardening (issue 6): bad input gets a clear answer, numerical faults are answered rather than
// propagated, resources stay bounded, and no output file is ever seen half-written.
// The table of docs/hardening.md lists what each bad-input class below gets.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <thread>

#include "artcal/internal.hpp"
#include "artcal/calibration/calibrator.hpp"
#include "artcal/io/csv_readings.hpp"
#include "sanitizers.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace hardening_test {

namespace fs = std::filesystem;
using nlohmann::json;

// ------------------------------------------------------------------------------------- helpers

/// A fresh temporary folder, removed with its content at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "artcal-hardening-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::string testData(const std::string& name) {
  return test_support::testDataFile(name);
}

json readJson(const std::string& path) {
  return json::parse(readText(path));
}

struct CliResult {
  int status = -1;
  std::string out;
  std::string err;
};

/// Runs the artcal CLI with `arguments` (already quoted as needed).
CliResult runCli(const TempDir& dir, const std::string& arguments) {
  const std::string out = dir.file("cli.out");
  const std::string err = dir.file("cli.err");
  const std::string command =
      std::string("'") + ARTCAL_CLI + "' " + arguments + " >'" + out + "' 2>'" + err + "'";
  const int raw = std::system(command.c_str());
  CliResult result;
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  result.out = readText(out);
  result.err = readText(err);
  return result;
}

std::size_t lineCount(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

/// Every number in a JSON output is finite (JSON has no NaN; finiteOrNull turns them to null).
void expectAllFinite(const json& value, const std::string& where = "") {
  if (value.is_number()) {
    EXPECT_TRUE(std::isfinite(value.get<double>())) << where;
  } else if (value.is_structured()) {
    for (const auto& item : value.items()) expectAllFinite(item.value(), where + "/" + item.key());
  }
}

/// A table never shows nan or inf.
void expectNoNonFinite(const std::string& table) {
  std::string word;
  for (const char c : table + " ") {
    if (std::isalpha(static_cast<unsigned char>(c))) {
      word += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      continue;
    }
    EXPECT_TRUE(word != "nan" && word != "inf") << table;
    word.clear();
  }
}

// ----------------------------------------------------------------------- bad input, through CLI

/// A valid planar 2R plan, the base every bad-input case below breaks in one place.
json validPlan() {
  return readJson(testData("ref-2r-5bars.json"));
}

struct BadInput {
  const char* name;
  std::string text;
  const char* pointer;  ///< expected JSON pointer in the message ("" for the whole file)
  const char* message;  ///< expected part of the message
};

std::vector<BadInput> badInputs() {
  auto with = [](auto edit) {
    json plan = validPlan();
    edit(plan);
    return plan.dump();
  };
  return {
      {"empty file", "", "", "malformed JSON"},
      {"binary garbage", std::string("\x00\xff\xfe\x01", 4), "", "malformed JSON"},
      {"truncated JSON", validPlan().dump().substr(0, 200), "", "malformed JSON"},
      {"number beyond double", R"({"format": "artcal-plan/1", "x": 1e999})", "",
       "malformed JSON: number overflow"},
      {"invalid UTF-8 in a string", "{\"format\": \"\xc3\x28\"}", "", "malformed JSON"},
      {"nesting deeper than 64", std::string(100'000, '[') + std::string(100'000, ']'), "",
       "nested deeper than 64 levels"},
      {"root not an object", "[1, 2]", "/", "expected an object, got an array"},
      {"wrong format", with([](json& p) { p["format"] = "artcal-plan/2"; }), "/format",
       "unsupported format"},
      {"missing field", with([](json& p) { p.erase("noise"); }), "/noise", "missing field"},
      // Found by tools/sanitize.sh (asserts on): the InputError unwound through Eigen's comma
      // initializer of the planar2r parameters, whose destructor asserts; abort instead of exit 2.
      {"missing model parameter", with([](json& p) { p["machine"]["parameters"].erase("l2"); }),
       "/machine/parameters/l2", "missing field"},
      {"wrong type", with([](json& p) { p["noise"]["probe"] = "0.005"; }), "/noise/probe",
       "expected a number, got a string"},
      {"negative noise", with([](json& p) { p["noise"]["probe"] = -1; }), "/noise/probe",
       "must be positive"},
      {"zero bar length", with([](json& p) { p["artifacts"]["bar80"]["length"] = 0; }),
       "/artifacts/bar80/length", "must be positive"},
      {"wrong number of joints", with([](json& p) {
         p["placements"][3]["measurements"][0]["joints"] = {1, 2, 3};
       }),
       "/placements/3/measurements/0/joints", "expected 2 numbers, got 3"},
      {"null in a joint reading",
       with([](json& p) { p["placements"][0]["measurements"][1]["joints"][1] = nullptr; }),
       "/placements/0/measurements/1/joints", "expected 2 numbers, got an array holding null"},
      {"feature out of range",
       with([](json& p) { p["placements"][0]["measurements"][0]["feature"] = 7; }),
       "/placements/0/measurements/0/feature", "must be at most 1, got 7"},
      {"feature not whole",
       with([](json& p) { p["placements"][0]["measurements"][0]["feature"] = 0.5; }),
       "/placements/0/measurements/0/feature", "expected a whole number"},
      {"huge feature index", with([](json& p) {
         p["placements"][0]["measurements"][0]["feature"] = std::uint64_t{18446744073709551615u};
       }),
       "/placements/0/measurements/0/feature", "must be at most 1, got 18446744073709551615"},
      {"unknown artifact", with([](json& p) { p["placements"][1]["artifact"] = "bar99"; }),
       "/placements/1/artifact", "unknown artifact \"bar99\""},
      {"unknown parameter", with([](json& p) {
         p["machine"]["calibrate"] = {"l1", "l3"};
       }),
       "/machine/calibrate/1", "unknown parameter \"l3\""},
      {"unknown model", with([](json& p) { p["machine"]["model"] = "delta"; }), "/machine/model",
       "unknown model \"delta\""},
      {"no placements", with([](json& p) { p["placements"] = json::array(); }), "/placements",
       "expected at least 1 entries, got 0"},
      {"too many workspace samples", with([](json& p) {
         p["workspace"] = {{"samples", 1e12}};
       }),
       "/workspace/samples", "must be at most 1000000"},
      {"grid too large", with([](json& p) {
         p["workspace"] = {{"grid", {100000, 100000}}};
       }),
       "/workspace/grid", "more than 1000000 configurations"},
      // Plausibility (issue 9): valid JSON of the right types that only wrong units explain.
      {"reading outside joint_limits", with([](json& p) {
         p["machine"]["joint_limits"] = {{-180, 180}, {-170, 170}};
         p["placements"][0]["measurements"][0]["joints"][1] = 175.0;
       }),
       "/placements/0/measurements/0/joints/1", "outside its joint_limits [-170, 170] deg"},
      {"readings in radians", with([](json& p) {
         for (json& placement : p["placements"])
           for (json& m : placement["measurements"])
             for (json& q : m["joints"]) q = q.get<double>() * std::numbers::pi / 180.0;
       }),
       "/placements/0", "check the units"},
      {"machine in metres", with([](json& p) {
         p["machine"]["parameters"]["l1"] = 0.15;
         p["machine"]["parameters"]["l2"] = 0.1;
       }),
       "/placements/0", "check the units"},
      {"machine in metres, one feature per placement", with([](json& p) {
         p["machine"]["parameters"]["l1"] = 0.15;
         p["machine"]["parameters"]["l2"] = 0.1;
         for (json& placement : p["placements"]) placement["measurements"].erase(1);
       }),
       "/placements/0", "is 80 mm across: check the units (lengths in mm, not metres)"},
      {"misspelled optional field",
       with([](json& p) { p["artifacts"]["bar80"]["u_lenght"] = 0.004; }),
       "/artifacts/bar80/u_lenght", "unknown field (did you mean \"u_length\"?)"},
      {"misspelled machine field", with([](json& p) {
         p["machine"]["joint_limit"] = {{-180, 180}, {-170, 170}};
       }),
       "/machine/joint_limit", "did you mean \"joint_limits\"?"},
      {"pose 5 m away", with([](json& p) {
         p["placements"][2]["pose"] = {{"center", {5000.0, 0.0}}, {"angle", 0.0}};
       }),
       "/placements/2/pose", "check the pose"},
  };
}

TEST(BadInput, EveryClassExitsTwoWithOneLineNamingFileAndPointer) {
  TempDir dir;
  for (const BadInput& bad : badInputs()) {
    SCOPED_TRACE(bad.name);
    const std::string path = dir.file("bad.json");
    writeText(path, bad.text);
    for (const char* command : {"check", "evaluate"}) {
      const CliResult r = runCli(dir, std::string(command) + " '" + path + "'");
      EXPECT_EQ(r.status, 2) << command;
      EXPECT_EQ(lineCount(r.err), 1u) << r.err;
      const std::string prefix =
          "error: " + path + ": " + (*bad.pointer ? bad.pointer + std::string(": ") : "");
      EXPECT_EQ(r.err.rfind(prefix, 0), 0u) << r.err;
      EXPECT_NE(r.err.find(bad.message), std::string::npos) << r.err;
      EXPECT_TRUE(r.out.empty()) << r.out;
    }
  }
}

TEST(BadInput, MissingFileDirectoryAndOversizedFile) {
  TempDir dir;
  const CliResult missing = runCli(dir, "check '" + dir.file("absent.json") + "'");
  EXPECT_EQ(missing.status, 2);
  EXPECT_EQ(missing.err, "error: " + dir.file("absent.json") + ": cannot be read\n");
  const CliResult directory = runCli(dir, "check '" + dir.path().string() + "'");
  EXPECT_EQ(directory.status, 2);
  EXPECT_EQ(directory.err, "error: " + dir.path().string() + ": is a directory\n");
  // A sparse file just over the cap: refused by its size before a byte is read.
  const std::string big = dir.file("big.json");
  writeText(big, "{");
  fs::resize_file(big, kMaxPlanFileBytes + 1);
  const CliResult oversized = runCli(dir, "check '" + big + "'");
  EXPECT_EQ(oversized.status, 2);
  EXPECT_EQ(oversized.err, "error: " + big + ": larger than 256 MiB\n");
}

// ------------------------------------------------------------------------- fuzz regressions

std::vector<std::string> fuzzRegressions() {
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(testData("fuzz-regressions"))) {
    files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(FuzzRegression, EveryFoundInputParsesOrRaisesInputError) {
  const auto files = fuzzRegressions();
  ASSERT_FALSE(files.empty());
  for (const std::string& file : files) {
    SCOPED_TRACE(file);
    for (bool require_placements : {true, false}) {
      try {
        const Plan plan = parsePlan(readJsonFile(file), file, require_placements);
        if (require_placements) {
          const Evaluation evaluation = evaluatePlan(plan);
          expectAllFinite(evaluationToJson(plan, evaluation));
        }
      } catch (const InputError& e) {
        EXPECT_FALSE(std::string(e.what()).empty());
      }
    }
  }
}

TEST(FuzzRegression, EveryFoundInputGetsAnAnswerFromTheCli) {
  TempDir dir;
  for (const std::string& file : fuzzRegressions()) {
    SCOPED_TRACE(file);
    const CliResult r = runCli(dir, "check '" + file + "'");
    EXPECT_TRUE(r.status == 0 || r.status == 1 || r.status == 2) << r.status;
    if (r.status == 2) {
      EXPECT_EQ(lineCount(r.err), 1u) << r.err;
      EXPECT_EQ(r.err.rfind("error: " + file + ": ", 0), 0u) << r.err;
    }
  }
}

// Found by fuzz_plan and fuzz_spec in their first minute: nlohmann raises out_of_range (406), not
// parse_error, for a number beyond double; it escaped readJsonFile without the file's name.
TEST(FuzzRegression, NumberOverflowIsMalformedJsonNamingTheFile) {
  const std::string file = testData("fuzz-regressions/number-overflow-plan.json");
  try {
    readJsonFile(file);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.describe().rfind(file + ": malformed JSON: number overflow parsing", 0), 0u)
        << e.describe();
  }
}

// Found by fuzz_spec on 2026-12-01: a hexapod spec whose platform joint 5 sits 1.4 m out reaches
// none of its task-space samples. The tip uncertainty over an empty workspace took the max of an
// empty row (an Eigen assertion, a segmentation fault in Release). Now it is the plan's fault,
// answered at /workspace.
TEST(FuzzRegression, UnreachableWorkspaceIsAnInputErrorAtWorkspace) {
  const std::string file = testData("fuzz-regressions/unreachable-workspace-spec.json");
  const Plan spec = parsePlan(readJsonFile(file), file, false);
  try {
    const PlanEvaluator evaluator(spec);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "/workspace");
    EXPECT_NE(std::string(e.what()).find("4096 samples out of reach"), std::string::npos)
        << e.what();
  }
  TempDir dir;
  const CliResult r =
      runCli(dir, "optimize '" + file + "' -o '" + dir.file("out.json") + "' --starts 1 --quiet");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("error: " + file + ": /workspace: no workspace configuration is usable", 0),
            0u)
      << r.err;
}

// Found by fuzz_plan on 2026-12-01: a CMM reading of -1e308 mm on the ram (range -600 .. 0 mm) was
// not checked against the axis range (only an explicit joint_limits was), and the evaluation
// whitened a block without columns (UBSan: offset on a null pointer; a segmentation fault in
// Release). A model's own ranges are the plan's limits now; whitening skips empty blocks.
TEST(FuzzRegression, CmmReadingBeyondItsAxisRangeIsRefused) {
  const std::string file = testData("fuzz-regressions/cmm-reading-beyond-axis-range-plan.json");
  TempDir dir;
  const CliResult r = runCli(dir, "check '" + file + "'");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  EXPECT_EQ(
      r.err.rfind(
          "error: " + file +
              ": /placements/2/measurements/17/joints/2: reading -1e+308 mm of joint 3 is outside",
          0),
      0u)
      << r.err;
}

// Found by fuzz_csv on 2026-12-02: 1e306 is a finite reading, but read in metres for a prismatic
// joint it became inf mm (x 1000) and went on into the readings. The converted value is checked.
TEST(FuzzRegression, CsvReadingThatOverflowsInConversionIsRefused) {
  const std::string file = testData("fuzz-regressions/csv-overflow-in-conversion.csv");
  const std::vector<JointKind> kinds = {JointKind::Revolute, JointKind::Prismatic,
                                        JointKind::Revolute};
  EXPECT_EQ(readJointCsv(file, kinds, *readingUnitsFromName("mm")).at(0)[1], 1e306);
  try {
    (void)readJointCsv(file, kinds, *readingUnitsFromName("m"));
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.describe(), file +
                                ": line 1: column 2: \"1e306\" is too large for a joint "
                                "reading; check the column's unit")
        << e.describe();
  }
}

// A command line the parser refuses (a number out of its range, options that exclude each other)
// is one line saying what it expected, exit 2, as every input error.
TEST(CommandLine, AnOptionOutOfItsRangeIsOneLineNamingIt) {
  TempDir dir;
  const std::string plan = test_support::planFile("paper-2r-5bars.json");
  const CliResult negative = runCli(dir, "calibrate '" + plan + "' --gross-threshold -1");
  EXPECT_EQ(negative.status, 2);
  EXPECT_EQ(negative.err,
            "error: --gross-threshold: expected a number > 0, not \"-1\" (artcal --help; artcal "
            "COMMAND --help)\n");
  const CliResult word = runCli(dir, "evaluate '" + plan + "' --rank-tol abc");
  EXPECT_EQ(word.status, 2);
  EXPECT_EQ(lineCount(word.err), 1u) << word.err;
  EXPECT_NE(word.err.find("--rank-tol"), std::string::npos) << word.err;
}

// ------------------------------------------------------------------------------ resource bounds

std::string nested(int depth) {
  return std::string(static_cast<std::size_t>(depth), '[') +
         std::string(static_cast<std::size_t>(depth), ']');
}

TEST(ResourceBounds, NestingDepthBoundIsExact) {
  EXPECT_NO_THROW(parseJsonText(nested(kMaxJsonDepth), "deep.json"));
  EXPECT_THROW(parseJsonText(nested(kMaxJsonDepth + 1), "deep.json"), InputError);
  EXPECT_NO_THROW(parseJsonText("{\"a\":" + nested(kMaxJsonDepth - 1) + "}", "deep.json"));
  EXPECT_THROW(parseJsonText("{\"a\":" + nested(kMaxJsonDepth) + "}", "deep.json"), InputError);
  // Brackets inside strings, after escaped quotes and backslashes, are not nesting.
  const std::string brackets = "\"\\\\\\\"" + std::string(1000, '[') + "\"";
  EXPECT_EQ(parseJsonText("[" + brackets + "]", "strings.json")[0].get<std::string>().size(),
            1002u);
}

// What the bound protects against: nlohmann parses and destroys 100k levels without recursion
// (3.11), but dump() and comparisons recurse. The bound answers before any of it is built.
TEST(ResourceBounds, HundredThousandLevelsAnsweredWithAnError) {
  try {
    parseJsonText(nested(100'000), "deep.json");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.describe(), "deep.json: nested deeper than 64 levels");
  }
  const json deep = json::parse(nested(100'000));  // no stack overflow in parse or destructor
  EXPECT_TRUE(deep.is_array());
}

TEST(ResourceBounds, HugeArraysAreRefusedBeforeTheirEntriesAreRead) {
  json plan = validPlan();
  plan.erase("placements");
  std::string text = plan.dump();
  text.pop_back();
  text += ",\"placements\":[";
  for (int i = 0; i < 1'000'001; ++i) text += i ? ",0" : "0";
  text += "]}";
  try {
    parsePlan(parseJsonText(text, "huge.json"), "huge.json");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.describe(),
              "huge.json: /placements: expected at most 1000000 entries, got 1000001");
  }
}

/// A plan of `count` identical ball-bar placements (text, as a file would hold it).
std::string planWithPlacements(int count) {
  json plan = validPlan();
  const std::string placement = plan["placements"][0].dump();
  plan.erase("placements");
  plan["workspace"] = {{"samples", 16}, {"seed", 1}};
  std::string text = plan.dump();
  text.pop_back();
  text.reserve(text.size() + static_cast<std::size_t>(count) * (placement.size() + 1) + 32);
  text += ",\"placements\":[";
  for (int i = 0; i < count; ++i) {
    if (i) text += ',';
    text += placement;
  }
  text += "]}";
  return text;
}

// Under the sanitizers (tools/sanitize.sh) a tenth of it: 3x slower, 3x the memory.
constexpr int kManyPlacements = test_support::kUnderSanitizers ? 100'000 : 1'000'000;

long childPeakRssMiB() {
  rusage usage{};
  getrusage(RUSAGE_CHILDREN, &usage);
  return usage.ru_maxrss / 1024;
}

// A million placements (the format's bound) is handled: the CLI evaluates it within memory. The
// file is ~160 MB; the JSON document then the plan take a few GB at most. The plan is generated
// here, never committed. (Identical placements do not separate the parameters: exit 1.)
TEST(ResourceBounds, MillionPlacementsEvaluatedWithinMemory) {
  TempDir dir;
  const std::string path = dir.file("million.json");
  writeText(path, planWithPlacements(kManyPlacements));
  const CliResult r = runCli(dir, "check --json '" + path + "'");
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.err;
  const json out = json::parse(r.out);
  EXPECT_EQ(out["counting"]["N_b"], 4 * kManyPlacements);
  EXPECT_EQ(out["counting"]["N_r"], 3 * kManyPlacements);
  EXPECT_LT(childPeakRssMiB(), 8 * 1024);
}

// ------------------------------------------------------------------------- numerical faults

// The ring plan of the reference cases: every bar at the same distance from the base, so l1, l2
// and dt2 cannot be separated. The answer is "not identifiable" with the combinations, and no
// uncertainty at all: no NaN, no infinity, nothing from a pseudo-inverse.
TEST(NumericalFaults, SingularPlanAnsweredWithCombinationsNotNumbers) {
  const Plan plan = loadPlan(testData("ref-2r-ring-degenerate.json"));
  const Evaluation evaluation = evaluatePlan(plan);
  EXPECT_FALSE(evaluation.identifiable());
  EXPECT_EQ(evaluation.identifiability.deficiency, 2);
  EXPECT_EQ(evaluation.identifiability.unidentifiable.size(), 2u);
  EXPECT_FALSE(evaluation.covariance.has_value());
  const json out = evaluationToJson(plan, evaluation);
  expectAllFinite(out);
  expectNoNonFinite(evaluationTable(plan, evaluation));
  EXPECT_EQ(out["identifiable"], false);

  TempDir dir;
  const CliResult r =
      runCli(dir, "evaluate --json '" + testData("ref-2r-ring-degenerate.json") + "'");
  EXPECT_EQ(r.status, 1);
  const json cli = json::parse(r.out);
  expectAllFinite(cli);
  EXPECT_EQ(cli["rank"]["unidentifiable"].size(), 2u);
}

/// The ring plan with bar j's elbow readings moved by j * offset: the bars leave the ring, a plan
/// on the edge of singularity as offset -> 0.
Plan nearlySingularPlan(double offset_deg) {
  json plan = readJson(testData("ref-2r-ring-degenerate.json"));
  double shift = 0.0;
  for (auto& placement : plan["placements"]) {
    for (auto& m : placement["measurements"]) {
      m["joints"][1] = m["joints"][1].get<double>() + shift;
    }
    shift += offset_deg;
  }
  return parsePlan(plan, "near-singular.json", /*require_placements=*/true,
                   /*check_plausibility=*/false);
}

// Near-singular plans: either "not identifiable" (with combinations) or finite uncertainties,
// whatever the distance to singularity; never NaN or infinity in any output.
TEST(NumericalFaults, NearSingularPlansNeverGiveNonFiniteOutput) {
  int answered_not_identifiable = 0;
  int answered_with_numbers = 0;
  for (double offset : {1e-15, 1e-12, 1e-9, 1e-7, 1e-5, 1e-3, 1e-1, 10.0}) {
    SCOPED_TRACE(offset);
    const Plan plan = nearlySingularPlan(offset);
    const Evaluation evaluation = evaluatePlan(plan);
    expectAllFinite(evaluationToJson(plan, evaluation));
    expectAllFinite(identifiabilityToJson(evaluation.identifiability));
    expectNoNonFinite(evaluationTable(plan, evaluation));
    if (evaluation.identifiable()) {
      ++answered_with_numbers;
      EXPECT_TRUE(evaluation.covariance->u.allFinite());
      EXPECT_TRUE(std::isfinite(evaluation.tip->worst.total));
    } else {
      ++answered_not_identifiable;
      EXPECT_FALSE(evaluation.identifiability.unidentifiable.empty());
    }
  }
  EXPECT_GT(answered_not_identifiable, 0);  // the sweep does cross the rank threshold
  EXPECT_GT(answered_with_numbers, 0);
}

// An encoder noise of 1e160 deg: its square overflows, the whitened readings and the information
// are NaN. A plan file is refused at /noise/encoder now (issue 19: a standard deviation lies in
// 1e-15 .. 1e6); a plan built in code that carries one anyway still answers "not identifiable"
// with every coefficient shown as "-", never nan or inf (plan-format.md).
TEST(NumericalFaults, OverflowingNoiseNeverPrintsNanOrInf) {
  json document = validPlan();
  document["noise"]["encoder"] = 1e160;
  try {
    (void)parsePlan(document, "plan.json");
    ADD_FAILURE() << "an encoder noise of 1e160 deg was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "/noise/encoder");
  }
  document["noise"]["encoder"] = 0.001;
  Plan plan = parsePlan(document, "plan.json");
  plan.noise.encoder.setConstant(degToRad(1e160));
  const Evaluation evaluation = evaluatePlan(plan);
  EXPECT_FALSE(evaluation.identifiable());
  const std::string table = evaluationTable(plan, evaluation);
  expectNoNonFinite(table);
  EXPECT_NE(table.find("unidentifiable #1:  - l1"), std::string::npos) << table;
  expectAllFinite(json::parse(evaluationToJson(plan, evaluation).dump()));
}

/// Every length of a plan document times k, and the probe noise times k (angles unchanged).
void scaleLengths(json& plan, double k) {
  json& machine = plan["machine"];
  if (machine["model"] == "planar2r") {
    for (const char* key : {"l1", "l2"})
      machine["parameters"][key] = k * machine["parameters"][key].get<double>();
  } else {
    for (auto& joint : machine["joints"]) {
      ASSERT_NE(joint.value("type", "revolute"), "prismatic");
      for (const char* key : {"d", "a"}) {
        if (joint.contains(key)) joint[key] = k * joint[key].get<double>();
      }
    }
    for (auto& v : machine["probe"]) v = k * v.get<double>();
  }
  plan["noise"]["probe"] = k * plan["noise"]["probe"].get<double>();
  for (auto& artifact : plan["artifacts"]) {
    ASSERT_EQ(artifact["type"], "ball_bar");
    artifact["length"] = k * artifact["length"].get<double>();
  }
  for (auto& placement : plan["placements"]) {
    if (placement.contains("pose")) {
      for (auto& v : placement["pose"]["center"]) v = k * v.get<double>();
    }
  }
}

json evaluateJson(const json& document) {
  const Plan plan = parsePlan(document, "scaled.json");
  const Evaluation evaluation = evaluatePlan(plan);
  EXPECT_TRUE(evaluation.identifiable());
  const json out = evaluationToJson(plan, evaluation);
  expectAllFinite(out);
  return out;
}

// Scaling every length and the probe noise by k scales every length uncertainty and the tip
// uncertainty by k and leaves angle uncertainties unchanged (method.md: the model is homogeneous
// of degree 1 in the lengths; the rank test works on the unit-diagonal N_red). From a 15 um arm
// to a 15 m one.
TEST(ExtremeValues, LengthScaleFromMicrometresToMetres) {
  for (const char* name : {"ref-2r-5bars.json", "ref-aacmm-3bars-3postures.json"}) {
    const json base_plan = readJson(testData(name));
    const json base = evaluateJson(base_plan);
    for (double k : {1e-4, 1e-2, 10.0, 100.0}) {
      SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k));
      json scaled_plan = base_plan;
      scaleLengths(scaled_plan, k);
      const json scaled = evaluateJson(scaled_plan);
      ASSERT_EQ(scaled["parameters"].size(), base["parameters"].size());
      for (std::size_t i = 0; i < base["parameters"].size(); ++i) {
        const json& b = base["parameters"][i];
        const double factor = b["unit"] == "mm" ? k : 1.0;
        EXPECT_NEAR(scaled["parameters"][i]["u"].get<double>(), factor * b["u"].get<double>(),
                    1e-6 * factor * b["u"].get<double>())
            << b["name"];
      }
      for (const char* key : {"total", "kinematic", "encoder"}) {
        EXPECT_NEAR(scaled["tip"]["worst"][key].get<double>(),
                    k * base["tip"]["worst"][key].get<double>(),
                    1e-6 * k * base["tip"]["worst"][key].get<double>())
            << key;
      }
    }
  }
}

// Tiny noise: every uncertainty is linear in the noise when probe and encoder noise scale together
// (V_p proportional to sigma^2), down to a probe noise of 1e-9 mm.
TEST(ExtremeValues, ProbeNoiseOf1e9MillimetreScalesLinearly) {
  const json base_plan = readJson(testData("ref-2r-5bars.json"));
  const json base = evaluateJson(base_plan);
  const double s = 1e-9 / base_plan["noise"]["probe"].get<double>();
  json tiny_plan = base_plan;
  tiny_plan["noise"]["probe"] = 1e-9;
  tiny_plan["noise"]["encoder"] = s * base_plan["noise"]["encoder"].get<double>();
  const json tiny = evaluateJson(tiny_plan);
  for (std::size_t i = 0; i < base["parameters"].size(); ++i) {
    const double expected = s * base["parameters"][i]["u"].get<double>();
    EXPECT_NEAR(tiny["parameters"][i]["u"].get<double>(), expected, 1e-6 * expected);
  }
  const double expected_tip = s * base["tip"]["worst"]["total"].get<double>();
  EXPECT_NEAR(tiny["tip"]["worst"]["total"].get<double>(), expected_tip, 1e-6 * expected_tip);
}

// ------------------------------------------------------------------------- nothing lost

/// A version of the content: `size` bytes, all the same letter, so that a torn file shows.
std::string version(int n, std::size_t size) {
  return std::string(size, static_cast<char>('a' + n % 26));
}

bool isWholeVersion(const std::string& content, std::size_t size) {
  return content.size() == size &&
         std::all_of(content.begin(), content.end(), [&](char c) { return c == content[0]; });
}

std::vector<fs::path> temporariesOf(const TempDir& dir, const std::string& name) {
  std::vector<fs::path> out;
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    const std::string file = entry.path().filename().string();
    if (file.rfind("." + name + ".", 0) == 0) out.push_back(entry.path());
  }
  return out;
}

// Stops (SIGSTOP) the writer `child` at a moment its temporary file beside `name` exists: the
// writer's temporary file is its signal that it is mid-write. Polls until then; a stop that lands
// after the rename lets the writer go on (SIGCONT) and waits for its next temporary file. No
// delays: the outcome does not depend on the machine's load. False when the child ended.
bool stopMidWrite(pid_t child, const TempDir& dir, const std::string& name) {
  for (;;) {
    int status = 0;
    if (::waitpid(child, &status, WNOHANG) != 0) return false;
    if (temporariesOf(dir, name).empty()) {
      std::this_thread::yield();
      continue;
    }
    ::kill(child, SIGSTOP);
    if (::waitpid(child, &status, WUNTRACED) != child || !WIFSTOPPED(status)) return false;
    if (!temporariesOf(dir, name).empty()) return true;
    ::kill(child, SIGCONT);
  }
}

// A child rewrites a 32 MB file in a loop through writeFileAtomically and is killed (SIGKILL)
// while it is writing: stopped once its temporary file exists, then killed. The target is always
// one whole version, the earlier one or a later one, never a torn mix; the kill leaves exactly the
// temporary file ".NAME.XXXXXX" beside the target (nothing cleans it up after SIGKILL; it is
// removed on every error the writer sees itself).
TEST(NothingLost, KilledWriterLeavesTheEarlierFileIntact) {
  TempDir dir;
  const std::string target = dir.file("plan.json");
  const std::size_t size = 32u << 20;
  writeFileAtomically(target, version(0, size));
  for (int round = 0; round < 3; ++round) {
    SCOPED_TRACE(round);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      for (int n = 1;; ++n) writeFileAtomically(target, version(n, size));
    }
    ASSERT_TRUE(stopMidWrite(child, dir, "plan.json"));
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
    EXPECT_TRUE(isWholeVersion(readText(target), size));
    const auto temporaries = temporariesOf(dir, "plan.json");
    EXPECT_EQ(temporaries.size(), 1u);  // killed mid-write, every round
    for (const fs::path& t : temporaries) fs::remove(t);
  }
}

/// Starts the CLI with `arguments` (a vector, no shell) and returns its process id.
pid_t startCli(const std::vector<std::string>& arguments) {
  const pid_t child = ::fork();
  if (child == 0) {
    std::vector<char*> argv{const_cast<char*>(ARTCAL_CLI)};
    for (const std::string& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::execv(ARTCAL_CLI, argv.data());
    ::_exit(127);
  }
  return child;
}

/// The example plan's placements repeated to `count`: a simulation that runs for a while and
/// writes a few MB.
std::string largeSimulationPlan(int count) {
  json plan = readJson(test_support::planFile("paper-2r-5bars.json"));
  const json placements = plan["placements"];
  plan["placements"] = json::array();
  for (int i = 0; i < count; ++i) plan["placements"].push_back(placements[i % placements.size()]);
  return plan.dump();
}

// `artcal simulate -o OUT` killed (SIGKILL) at several moments of its run: OUT is always the
// earlier file, byte for byte, or a complete new plan, never a partial one.
TEST(NothingLost, KilledCliLeavesTheEarlierOutputIntact) {
  TempDir dir;
  const std::string plan = dir.file("plan.json");
  const std::string truth = dir.file("truth.json");
  const std::string output = dir.file("out.json");
  writeText(plan, largeSimulationPlan(5000));
  writeText(truth, R"({"parameters": {"l1": 150.02}})");
  const std::string earlier = "{\"earlier\": true}\n";
  writeText(output, earlier);
  int intact = 0;
  int replaced = 0;
  for (int delay_ms : {0, 50, 200, 500, 1000, 2000}) {
    SCOPED_TRACE(delay_ms);
    const pid_t child = startCli({"simulate", plan, "--truth", truth, "-o", output});
    ASSERT_GT(child, 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    const std::string content = readText(output);
    if (content == earlier) {
      ++intact;
    } else {
      ++replaced;
      const json written = json::parse(content);  // throws on a partial file
      EXPECT_EQ(written["placements"].size(), 5000u);
      writeText(output, earlier);
    }
    for (const fs::path& t : temporariesOf(dir, "out.json")) fs::remove(t);
  }
  EXPECT_GT(intact, 0);
}

// A calibration that diverges (started 1e5 mm from the truth on l1) stops and says so:
// converged false, every number finite. The command line no longer gets that far: readings that a
// 1e5 mm arm puts metres off the bar are implausible input (exit 2, a hint at the units).
TEST(NumericalFaults, DivergingCalibrationStopsWithConvergedFalse) {
  TempDir dir;
  json plan = readJson(testData("ref-2r-calibrate.json"));
  plan["machine"]["parameters"]["l1"] = 1e5;
  const std::string path = dir.file("diverging.json");
  writeText(path, plan.dump());
  const CliResult r = runCli(dir, "calibrate --json '" + path + "'");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(": /placements/0: the nominal machine puts these readings"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(lineCount(r.err), 1u);

  const Calibration calibration =
      calibratePlan(parsePlan(plan, "diverging.json", true, /*check_plausibility=*/false));
  EXPECT_FALSE(calibration.summary.converged());
  EXPECT_TRUE(calibration.parameters.allFinite());
  const Plan parsed = parsePlan(plan, "diverging.json", true, false);
  expectAllFinite(calibrationToJson(parsed, parsed.placements, calibration));
  expectNoNonFinite(calibrationTable(parsed, parsed.placements, calibration));
}

// ------------------------------------------------------------------------------ output safety

/// A TRUTH file next to the plan: the simulate command's second input.
std::string writeTruth(const TempDir& dir) {
  const std::string truth = dir.file("truth.json");
  writeText(truth, R"({"parameters": {"l1": 150.01, "l2": 99.99, "dt2": 0.002}})");
  return truth;
}

/// Every command that writes a file, with its output option left for the test to fill in.
std::vector<std::pair<std::string, std::string>> writingCommands(const TempDir& dir) {
  const std::string plan = "'" + testData("ref-2r-5bars.json") + "'";
  const std::string calibration = "'" + testData("ref-2r-calibrate.json") + "'";
  const std::string spec = "'" + test_support::planFile("seed-2r-5bars.spec.json'");
  return {{"simulate", "simulate " + plan + " --truth '" + writeTruth(dir) + "' -o "},
          {"optimize", "optimize " + spec + " --quiet --starts 1 --pool 40 --evaluations 20 -o "},
          {"report", "report " + plan + " -o "},
          {"calibrate --write-machine", "calibrate " + calibration + " --write-machine "}};
}

// Devices, FIFOs and directories are refused before any work: exit 2, one line naming the path,
// the special file untouched (a rename over /dev/null would replace the device node).
TEST(OutputSafety, DevicesFifosAndDirectoriesAreRefused) {
  TempDir dir;
  const std::string fifo = dir.file("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  fs::create_directory(dir.file("folder"));
  for (const auto& [name, command] : writingCommands(dir)) {
    for (const auto& [target, kind] :
         std::vector<std::pair<std::string, std::string>>{{"/dev/null", "is a device"},
                                                          {fifo, "is a FIFO"},
                                                          {dir.file("folder"), "is a directory"}}) {
      SCOPED_TRACE(name + " -> " + target);
      const CliResult r = runCli(dir, command + "'" + target + "'");
      EXPECT_EQ(r.status, 2) << r.err;
      EXPECT_EQ(r.err, "error: " + target + ": " + kind +
                           ", not a regular file: refusing to replace it (use - for standard "
                           "output)\n");
      EXPECT_TRUE(r.out.empty()) << r.out;
    }
  }
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_TRUE(fs::is_empty(dir.file("folder")));
}

// A symbolic link is written through: the target gets the new content (atomically, in its own
// folder), the link stays a link. A dangling link creates its target.
TEST(OutputSafety, SymbolicLinksAreWrittenThroughToTheirTarget) {
  TempDir dir;
  fs::create_directory(dir.file("real"));
  const std::string target = dir.file("real/plan.json");
  writeText(target, "old");
  ::chmod(target.c_str(), 0640);
  fs::create_symlink("real/plan.json", dir.file("link.json"));
  fs::create_symlink(dir.file("link.json"), dir.file("link2.json"));  // a chain of two
  const std::string simulate = writingCommands(dir)[0].second;
  const CliResult r = runCli(dir, simulate + "'" + dir.file("link2.json") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(dir.file("link.json")));
  EXPECT_TRUE(fs::is_symlink(dir.file("link2.json")));
  EXPECT_TRUE(json::parse(readText(target)).contains("simulation"));
  EXPECT_EQ(fs::status(target).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  for (const auto& entry : fs::directory_iterator(dir.path())) {  // no temporary left behind
    EXPECT_EQ(entry.path().filename().string().rfind(".link", 0), std::string::npos);
  }

  fs::create_symlink("real/new.json", dir.file("dangling.json"));
  ASSERT_EQ(runCli(dir, simulate + "'" + dir.file("dangling.json") + "'").status, 0);
  EXPECT_TRUE(fs::is_symlink(dir.file("dangling.json")));
  EXPECT_TRUE(json::parse(readText(dir.file("real/new.json"))).contains("simulation"));
}

// `-o -` is standard output for every command that writes a file: stdout holds the file alone
// (JSON that parses, or the HTML), the command's summary goes to stderr.
TEST(OutputSafety, DashMeansStandardOutputForEveryWritingCommand) {
  TempDir dir;
  for (const auto& [name, command] : writingCommands(dir)) {
    SCOPED_TRACE(name);
    const CliResult r = runCli(dir, command + "-");
    ASSERT_EQ(r.status, 0) << r.err;
    if (name == "report") {
      EXPECT_EQ(r.out.rfind("<!DOCTYPE html>", 0), 0u) << r.out.substr(0, 80);
    } else {
      const json document = json::parse(r.out);  // the file alone, nothing else on stdout
      EXPECT_TRUE(document.is_object());
    }
    EXPECT_FALSE(fs::exists(dir.file("-")));
  }
}

}  // namespace hardening_test
}  // namespace artcal
