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

namespace {

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
    return std::string(ARTCAL_TEST_DATA) + "/" + name + ".json";
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
  const json expected = readJson(std::string(ARTCAL_TEST_DATA) + "/ref-2r-5bars.expected.json");
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

}  // namespace
