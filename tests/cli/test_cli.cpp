// The command line contract (plan-format.md): exit statuses of check and evaluate, the --json
// fields scripts rely on, and bad input answered with status 2 and one line on stderr naming the
// file and the JSON pointer. Runs the built artcal binary (ARTCAL_CLI).

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "test_paths.hpp"

namespace cli_test {

namespace fs = std::filesystem;
using nlohmann::json;

struct Outcome {
  int status = -1;
  std::string out;
  std::string err;
};

std::string readText(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "artcal-cli-XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs `artcal ARGS`, stdout and stderr captured apart.
  Outcome run(const std::string& args) const {
    const fs::path out = dir_ / "stdout", err = dir_ / "stderr";
    const std::string command = std::string("'") + ARTCAL_CLI + "' " + args + " >'" + out.string() +
                                "' 2>'" + err.string() + "'";
    const int raw = std::system(command.c_str());
    Outcome r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = readText(out);
    r.err = readText(err);
    return r;
  }
  fs::path write(const std::string& name, const std::string& content) const {
    const fs::path path = dir_ / name;
    std::ofstream(path) << content;
    return path;
  }
  static std::string data(const std::string& name) {
    return artcal::test_support::testDataFile(name + ".json");
  }
  static json readJson(const std::string& path) { return json::parse(readText(path)); }

  // Exit status 2, nothing on stdout, exactly one line on stderr that starts with `prefix`.
  static void expectBadInput(const Outcome& r, const std::string& prefix) {
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(r.out.empty()) << r.out;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;  // one line
    EXPECT_EQ(r.err.rfind(prefix, 0), 0u) << r.err;
  }

  fs::path dir_;
};

TEST_F(Cli, CheckIdentifiablePlanExitsZeroWithThePromisedJson) {
  const Outcome r = run("check --json '" + data("ref-2r-5bars") + "'");
  EXPECT_EQ(r.status, 0) << r.err;
  const json out = json::parse(r.out);
  EXPECT_EQ(out["identifiable"], true);
  EXPECT_EQ(out["counting"]["N_p"], 3);
  EXPECT_EQ(out["counting"]["N_b"], 20);
  EXPECT_EQ(out["counting"]["N_r"], 15);
  EXPECT_EQ(out["counting"]["satisfied"], true);
  EXPECT_EQ(out["rank"]["deficiency"], 0);
  EXPECT_TRUE(out["rank"]["unidentifiable"].is_array());
  EXPECT_TRUE(out["rank"]["unidentifiable"].empty());
}

TEST_F(Cli, CheckRingLayoutExitsOneAndNamesTheCombinations) {
  const Outcome r = run("check --json '" + data("ref-2r-ring-degenerate") + "'");
  EXPECT_EQ(r.status, 1) << r.err;
  const json out = json::parse(r.out);
  EXPECT_EQ(out["identifiable"], false);
  EXPECT_EQ(out["counting"]["satisfied"], true);
  EXPECT_EQ(out["rank"]["deficiency"], 2);
  ASSERT_EQ(out["rank"]["unidentifiable"].size(), 2u);
  EXPECT_TRUE(out["rank"]["unidentifiable"][0].is_array());
  EXPECT_TRUE(out["rank"]["unidentifiable"][0][0].is_string());
  // The human table says so too.
  const Outcome table = run("check '" + data("ref-2r-ring-degenerate") + "'");
  EXPECT_EQ(table.status, 1);
  EXPECT_NE(table.out.find("dt2"), std::string::npos) << table.out;
}

TEST_F(Cli, EvaluateJsonCarriesTheReferenceFigures) {
  const Outcome r = run("evaluate --json '" + data("ref-2r-5bars") + "'");
  EXPECT_EQ(r.status, 0) << r.err;
  const json out = json::parse(r.out);
  const json expected = readJson(artcal::test_support::testDataFile("ref-2r-5bars.expected.json"));
  ASSERT_EQ(out["parameters"].size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const json& p = out["parameters"][i];
    EXPECT_EQ(p["name"], expected["parameters"][i]["name"]);
    EXPECT_TRUE(p["nominal"].is_number());
    EXPECT_EQ(p["unit"], i < 2 ? "mm" : "deg");
    const double u = expected["parameters"][i]["u"].get<double>();
    EXPECT_NEAR(p["u"].get<double>(), u, 1e-6 * u);
  }
  for (const char* key : {"total", "kinematic", "encoder"}) {
    const double e = expected["tip"]["worst"][key].get<double>();
    EXPECT_NEAR(out["tip"]["worst"][key].get<double>(), e, 1e-6 * e) << key;
  }
  EXPECT_EQ(out["tip"]["worst"]["joints"].size(), 2u);
  const double mean = expected["tip"]["mean"].get<double>();
  EXPECT_NEAR(out["tip"]["mean"].get<double>(), mean, 1e-6 * mean);
}

TEST_F(Cli, EvaluateDefaultIsAHumanTable) {
  const Outcome r = run("evaluate '" + data("ref-aacmm-3bars-3postures") + "'");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(json::accept(r.out));
  for (const char* word : {"j2.theta", "probe.z", "deg", "mm"}) {
    EXPECT_NE(r.out.find(word), std::string::npos) << word;
  }
}

TEST_F(Cli, EvaluateUnidentifiablePlanExitsOne) {
  const Outcome r = run("evaluate --json '" + data("ref-2r-ring-degenerate") + "'");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(json::parse(r.out)["identifiable"], false);
}

TEST_F(Cli, FieldErrorNamesFileAndPointerOnOneLine) {
  json plan = readJson(data("ref-2r-5bars"));
  plan["placements"][3]["measurements"][0]["joints"] = {1.0, 2.0, 3.0};
  const fs::path bad = write("bad.json", plan.dump());
  for (const char* command : {"check", "evaluate"}) {
    SCOPED_TRACE(command);
    const Outcome r = run(std::string(command) + " '" + bad.string() + "'");
    expectBadInput(r, "error: " + bad.string() + ": /placements/3/measurements/0/joints: ");
    EXPECT_NE(r.err.find("expected 2 numbers, got 3"), std::string::npos) << r.err;
    const Outcome j = run(std::string(command) + " --json '" + bad.string() + "'");
    expectBadInput(j, "error: " + bad.string() + ": /placements/3/measurements/0/joints: ");
  }
  plan = readJson(data("ref-2r-5bars"));
  plan["noise"]["probe"] = -1;
  const fs::path negative = write("negative.json", plan.dump());
  expectBadInput(run("evaluate '" + negative.string() + "'"),
                 "error: " + negative.string() + ": /noise/probe: ");
}

TEST_F(Cli, MalformedJsonMissingFileAndDirectory) {
  const fs::path malformed =
      write("malformed.json", "{\"format\": \"artcal-plan/1\",\n  \"machine\": [");
  const Outcome a = run("check '" + malformed.string() + "'");
  expectBadInput(a, "error: " + malformed.string() + ": ");
  EXPECT_NE(a.err.find("malformed JSON"), std::string::npos) << a.err;

  const std::string missing = (dir_ / "absent.json").string();
  const Outcome b = run("evaluate '" + missing + "'");
  expectBadInput(b, "error: " + missing + ": ");

  const Outcome c = run("check '" + dir_.string() + "'");
  expectBadInput(c, "error: " + dir_.string() + ": ");
  EXPECT_NE(c.err.find("directory"), std::string::npos) << c.err;

  const fs::path empty = write("empty.json", "");
  expectBadInput(run("evaluate --json '" + empty.string() + "'"),
                 "error: " + empty.string() + ": ");
}

TEST_F(Cli, UsageErrorsExitTwo) {
  EXPECT_EQ(run("").status, 2);
  EXPECT_EQ(run("check").status, 2);
  EXPECT_EQ(run("evaluate --no-such-flag '" + data("ref-2r-5bars") + "'").status, 2);
}

// ---------------------------------------------------------------------------------------------
// Every ```console block of README.md and docs/*.md is reproduced byte for byte. A block's `$ `
// lines run in order in one shell (so `echo $?` sees the command before it, stderr merged into
// stdout) from a scratch folder holding a copy of plans/, the repository's tests/data and
// build/tools/artcal (the binary under test): nothing in the repository is written. In the
// expected output a line `...` (indented or not) stands for any number of lines, and a line ending
// in `...` for one line starting with what comes before the dots. A block is checked when all
// its commands are `build/tools/artcal ...` (optionally piped into jq) or `echo $?`, apart from
// `artcal optimize`, a search bounded in seconds whose output depends on the machine's load.

struct ConsoleBlock {
  std::string where;  // file:line
  std::vector<std::string> lines;
};

std::vector<ConsoleBlock> consoleBlocks(const fs::path& file, const std::string& label) {
  std::ifstream in(file);
  std::vector<ConsoleBlock> blocks;
  std::string line;
  int number = 0;
  bool inside = false;
  while (std::getline(in, line)) {
    ++number;
    if (!inside && line == "```console") {
      inside = true;
      blocks.push_back({label + ":" + std::to_string(number), {}});
    } else if (inside && line == "```") {
      inside = false;
    } else if (inside) {
      blocks.back().lines.push_back(line);
    }
  }
  return blocks;
}

bool checkedCommand(const std::string& command) {
  if (command == "echo $?") return true;
  const std::string artcal = "build/tools/artcal ";
  return command.rfind(artcal, 0) == 0 && command.rfind(artcal + "optimize", 0) != 0;
}

std::string singleQuoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// The shell script that prints each `$ command` line and then its output.
std::string consoleScript(const std::vector<std::string>& lines) {
  std::string script = "status=0\n";
  for (const std::string& line : lines) {
    if (line.rfind("$ ", 0) != 0) continue;
    script += "printf '%s\\n' " + singleQuoted(line) + "\n(exit $status); " + line.substr(2) +
              " 2>&1; status=$?\n";
  }
  return script;
}

bool lineMatches(const std::string& expected, const std::string& actual) {
  const std::string dots = "...";
  if (expected.size() > dots.size() && expected.ends_with(dots)) {
    return actual.rfind(expected.substr(0, expected.size() - dots.size()), 0) == 0;
  }
  return expected == actual;
}

bool isElision(const std::string& line) {
  return line.find_first_not_of(' ') != std::string::npos &&
         line.substr(line.find_first_not_of(' ')) == "...";
}

// Expected lines against actual ones, `...` lines matching any run of lines.
bool blockMatches(const std::vector<std::string>& expected, std::size_t e,
                  const std::vector<std::string>& actual, std::size_t a) {
  if (e == expected.size()) return a == actual.size();
  if (isElision(expected[e])) {
    for (std::size_t skip = a; skip <= actual.size(); ++skip) {
      if (blockMatches(expected, e + 1, actual, skip)) return true;
    }
    return false;
  }
  return a < actual.size() && lineMatches(expected[e], actual[a]) &&
         blockMatches(expected, e + 1, actual, a + 1);
}

std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST_F(Cli, ConsoleBlocksOfTheDocumentsAreReproduced) {
  const fs::path root = fs::path(ARTCAL_PLANS_DIR).parent_path();
  fs::create_directories(dir_ / "build" / "tools");
  fs::create_symlink(ARTCAL_CLI, dir_ / "build" / "tools" / "artcal");
  fs::copy(root / "plans", dir_ / "plans", fs::copy_options::recursive);
  fs::create_directories(dir_ / "tests");
  fs::create_directory_symlink(root / "tests" / "data", dir_ / "tests" / "data");
  std::vector<ConsoleBlock> blocks = consoleBlocks(root / "README.md", "README.md");
  for (const auto& entry : fs::directory_iterator(root / "docs")) {
    if (entry.path().extension() != ".md") continue;
    for (ConsoleBlock& block :
         consoleBlocks(entry.path(), "docs/" + entry.path().filename().string())) {
      blocks.push_back(std::move(block));
    }
  }
  int checked = 0;
  for (const ConsoleBlock& block : blocks) {
    bool runnable = true;
    for (const std::string& line : block.lines) {
      if (line.rfind("$ ", 0) == 0 && !checkedCommand(line.substr(2))) runnable = false;
    }
    if (!runnable) continue;
    ++checked;
    std::ofstream(dir_ / "block.sh") << consoleScript(block.lines);
    const std::string command = "cd " + singleQuoted(dir_.string()) + " && sh block.sh";
    FILE* pipe = popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string output;
    char buffer[4096];
    for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) {
      output.append(buffer, n);
    }
    pclose(pipe);
    EXPECT_TRUE(blockMatches(block.lines, 0, splitLines(output), 0))
        << block.where << ": the block differs from what the commands print now:\n"
        << output;
  }
  EXPECT_GE(checked, 5) << "README.md's walk-through blocks are no longer found";
}

}  // namespace cli_test

namespace cli_test {

// main registers only the subcommand a command line names (start-up, issue 33): every command
// the documentation lists is still there for --help, each answers its own --help as itself, and
// --version needs none of them.
TEST(CommandLine, EverySubcommandIsThereWhenNamedAndAllAreListedByHelp) {
  const std::vector<std::string> documented = {
      "check",    "evaluate",        "procedure",   "optimize",   "plan",
      "simulate", "calibrate",       "confirm",     "verify",     "acceptance",
      "report",   "import-readings", "import-urdf", "export-urdf"};
  const artcal::test_support::CliRun help = artcal::test_support::runCli("--help");
  ASSERT_EQ(help.status, 0);
  const std::string listed = help.out.substr(help.out.find("Subcommands:"));
  for (const std::string& name : documented) {
    EXPECT_NE(listed.find("\n  " + name + " "), std::string::npos) << name << "\n" << listed;
    const artcal::test_support::CliRun own = artcal::test_support::runCli(name + " --help");
    EXPECT_EQ(own.status, 0) << name;
    EXPECT_NE(own.out.find("Usage: artcal " + name + " "), std::string::npos) << own.out;
  }
  const artcal::test_support::CliRun version = artcal::test_support::runCli("--version");
  EXPECT_EQ(version.status, 0);
  EXPECT_EQ(version.out, "artcal 0.1.0\n");
  const artcal::test_support::CliRun misspelt =
      artcal::test_support::runCli("evaluat plans/x.json", artcal::test_support::Stderr::Only);
  EXPECT_EQ(misspelt.status, 2);
  EXPECT_NE(misspelt.out.find("error: "), std::string::npos) << misspelt.out;
}

}  // namespace cli_test
