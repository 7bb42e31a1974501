// Hardening II (issue 19, docs/hardening.md): hostile and careless inputs of the newer families
// (URDF, CSV readings, machine files, output paths, stdout). One test per class; each asserts the
// answer: exit status 2 with one line `error: FILE: ...` naming what to check, nothing replaced.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "artcal/internal.hpp"
#include "artcal/core/linear_algebra.hpp"
#include "artcal/core/parallel.hpp"
#include "artcal/io/csv_readings.hpp"
#include "artcal/report/procedure.hpp"
#include "cli_runner.hpp"
#include "test_paths.hpp"

namespace hostile_inputs_test {

using namespace artcal;
using namespace artcal::test_support;
using nlohmann::json;
namespace fs = std::filesystem;

/// A fresh folder under the system's temporary folder, removed at the end.
struct Scratch {
  fs::path dir;
  Scratch() {
    std::string pattern = (fs::temp_directory_path() / "artcal-hostile-XXXXXX").string();
    dir = ::mkdtemp(pattern.data());
  }
  ~Scratch() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
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

json referencePlan() {
  return json::parse(readText(testDataFile("ref-2r-5bars.json")));
}

std::string shellQuoted(const std::string& path) {
  return "'" + path + "'";
}

/// The CLI's answer on stderr (stdout discarded): exit 2 and exactly one line starting with
/// "error: FILE: " and holding `part`.
void expectRefused(const std::string& arguments, const std::string& file, const std::string& part) {
  const CliRun run = runCli(arguments, Stderr::Only);
  EXPECT_EQ(run.status, 2) << arguments << "\n" << run.out;
  EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1) << run.out;
  EXPECT_EQ(run.out.rfind("error: " + file + ": ", 0), 0u) << run.out;
  EXPECT_NE(run.out.find(part), std::string::npos) << "expected \"" << part << "\" in " << run.out;
}

// ------------------------------------------------------------------------------------ crashes

TEST(HostileCrashes, OverflowingAndUnderflowingNoiseIsRefusedWhereItEnters) {
  Scratch scratch;
  for (const char* which : {"probe", "encoder"}) {
    for (const double noise : {1e160, 1e300, 1e-300}) {
      json plan = referencePlan();
      plan["machine"]["calibrate"] = "identifiable";
      plan["noise"][which] = noise;
      const std::string file = scratch.write("noise.json", plan.dump());
      expectRefused("check " + shellQuoted(file), file, std::string("/noise/") + which);
    }
  }
  const std::string kept = testDataFile("hostile/underflowing-noise-identifiable.json");
  expectRefused("evaluate " + shellQuoted(kept), kept,
                "/noise/probe: a standard deviation of 1e-300");
}

TEST(HostileCrashes, TheEigenSolverAnswersANonFiniteMatrixWithoutDecomposingIt) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(4, 4);
  A(1, 2) = A(2, 1) = std::numeric_limits<double>::quiet_NaN();
  A(3, 3) = std::numeric_limits<double>::infinity();
  const SymmetricEigenSolver eig(A);
  EXPECT_EQ(eig.info(), Eigen::NumericalIssue);
  EXPECT_EQ(eig.eigenvalues().size(), 4);
  EXPECT_EQ(eig.eigenvectors().rows(), 4);
  EXPECT_EQ(eig.eigenvectors().cols(), 4);
  EXPECT_TRUE(eig.eigenvalues().array().isNaN().all());
  const SymmetricEigenSolver finite(Eigen::MatrixXd::Identity(3, 3));
  EXPECT_EQ(finite.info(), Eigen::Success);
  EXPECT_EQ(finite.eigenvalues(), Eigen::VectorXd::Ones(3));
}

TEST(HostileCrashes, HugeParametersAndAxisRangesAreRefused) {
  Scratch scratch;
  json plan = referencePlan();
  plan["machine"]["calibrate"] = "identifiable";
  plan["machine"]["parameters"]["l1"] = 1e300;
  std::string file = scratch.write("param.json", plan.dump());
  expectRefused("check " + shellQuoted(file), file, "/machine/parameters/l1: magnitude 1e+300");
  plan = referencePlan();
  plan["machine"]["joint_limits"] = {{-1e300, 1e300}, {-170, 170}};
  file = scratch.write("limits.json", plan.dump());
  expectRefused("evaluate " + shellQuoted(file), file, "/machine/joint_limits/0/0");
}

TEST(HostileCrashes, DeepUrdfChainIsRefusedBeforeUrdfdomParsesIt) {
  Scratch scratch;
  std::string urdf = "<robot name=\"deep\"><link name=\"base\"/>";
  const int depth = 150'000;
  for (int i = 0; i < depth; ++i) urdf += "<link name=\"l" + std::to_string(i) + "\"/>";
  for (int i = 0; i < depth; ++i) {
    urdf += "<joint name=\"j" + std::to_string(i) + "\" type=\"continuous\"><parent link=\"" +
            (i ? "l" + std::to_string(i - 1) : std::string("base")) + "\"/><child link=\"l" +
            std::to_string(i) + "\"/></joint>";
  }
  const std::string file = scratch.write("deep.urdf", urdf + "</robot>");
  expectRefused("import-urdf " + shellQuoted(file) + " --base base --tip l149999", file,
                "more than 4096 links");
}

TEST(HostileCrashes, ThreadCountsAreCapped) {
  EXPECT_EQ(threadCount(100'000, 1'000'000), kMaxThreads);
  EXPECT_EQ(threadCount(3, 2), 2);
  const CliRun run =
      runCli("confirm " + shellQuoted(planFile("paper-2r-5bars.json")) + " --threads 100000",
             Stderr::Only);
  EXPECT_EQ(run.status, 2) << run.out;
  EXPECT_NE(run.out.find("--threads"), std::string::npos) << run.out;
}

// ------------------------------------------------------------------- unbounded memory, hangs

TEST(HostileResources, UrdfLinksThatFormALoopAreRefused) {
  const std::string file = testDataFile("hostile/two-parents.urdf");
  expectRefused("import-urdf " + shellQuoted(file) + " --base base --tip tip", file,
                "link \"a\" is the child of joints \"j1\" and \"j3\"");
  const std::string cycle = testDataFile("hostile/cycle.urdf");
  expectRefused("import-urdf " + shellQuoted(cycle) + " --base base --tip a", cycle,
                "the links above \"a\" form a loop");
}

TEST(HostileResources, NonRegularFilesAreRefusedAsEveryInput) {
  Scratch scratch;
  const std::string fifo = scratch.file("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& special : {std::string("/dev/zero"), fifo}) {
    expectRefused("check " + shellQuoted(special), special, "not a regular file");
    expectRefused("import-urdf " + shellQuoted(special) + " --base a --tip b", special,
                  "not a regular file");
    json plan = json::parse(readText(planFile("panda-front-center.json")));
    plan["placements"][0]["measurements"][0]["csv"] = special;
    const std::string file = scratch.write("csv-special.json", plan.dump());
    expectRefused("check " + shellQuoted(file), special, "not a regular file");
  }
}

TEST(HostileResources, ALongCsvLineIsCountedBeforeItIsSplit) {
  Scratch scratch;
  const std::string csv = scratch.write("long.csv", std::string(20'000'000, ',') + "\n");
  const std::vector<JointKind> kinds(7, JointKind::Revolute);
  try {
    (void)readJointCsv(csv, kinds, ReadingUnits{});
    ADD_FAILURE() << "a line of 20 000 001 fields was read";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "line 1");
    EXPECT_NE(std::string(e.what()).find("expected 7 readings, got 20000001"), std::string::npos);
  }
}

TEST(HostileResources, CsvReadingsOfAPlanAreBoundedInAll) {
  Scratch scratch;
  std::string rows;
  for (int i = 0; i < 2500; ++i) rows += "0,10,0,-90,0,90,0\n";
  scratch.write("rows.csv", rows);
  json plan = json::parse(readText(planFile("panda-front-center.json")));
  json placement = plan["placements"][0];
  placement["measurements"] = {{{"feature", 0}, {"csv", "rows.csv"}}};
  plan["placements"] = json::array();
  for (int i = 0; i < 1000; ++i) plan["placements"].push_back(placement);
  const std::string file = scratch.write("many.json", plan.dump());
  expectRefused("check " + shellQuoted(file), file, "more than 2000000 readings from CSV files");
}

// ------------------------------------------------------------------------ nothing lost, exit 0

TEST(HostileOutputs, AnOutputThatIsAnInputIsRefusedBeforeAnyWork) {
  Scratch scratch;
  const std::string plan = scratch.write("plan.json", readText(testDataFile("ref-2r-5bars.json")));
  const std::string link = scratch.file("link.json");
  fs::create_symlink(plan, link);
  const std::string before = readText(plan);
  expectRefused("simulate " + shellQuoted(plan) + " --truth " + shellQuoted(plan) + " -o " +
                    shellQuoted(plan),
                plan, "is the input");
  expectRefused("calibrate " + shellQuoted(plan) + " --write-machine " + shellQuoted(link), link,
                "is the input");
  expectRefused("report " + shellQuoted(plan) + " -o " + shellQuoted(plan), plan, "is the input");
  const std::string spec =
      scratch.write("spec.json", readText(planFile("seed-2r-5bars.spec.json")));
  expectRefused("optimize " + shellQuoted(spec) + " -o " + shellQuoted(spec), spec, "is the input");
  const std::string urdf =
      scratch.write("arm.urdf", readText(testDataFile("urdf/arm3-slide.urdf")));
  const std::string urdf_before = readText(urdf);
  expectRefused(
      "import-urdf " + shellQuoted(urdf) + " --base base --tip probe -o " + shellQuoted(urdf), urdf,
      "is the input");
  const std::string machine = scratch.file("machine.json");
  ASSERT_EQ(runCli("import-urdf " + shellQuoted(urdf) + " --base base --tip probe -o " +
                   shellQuoted(machine))
                .status,
            0);
  expectRefused("export-urdf --machine " + shellQuoted(machine) + " --urdf " + shellQuoted(urdf) +
                    " -o " + shellQuoted(urdf),
                urdf, "is the input");
  EXPECT_EQ(readText(plan), before);
  EXPECT_EQ(readText(urdf), urdf_before);
}

TEST(HostileOutputs, AFullStandardOutputIsAnError) {
  const std::string plan = shellQuoted(testDataFile("ref-2r-5bars.json"));
  for (const std::string& command : {"check " + plan, "evaluate " + plan, "evaluate --json " + plan,
                                     "procedure --csv " + plan, "verify " + plan}) {
    const CliRun run = runCli(command + " >/dev/full", Stderr::Discard);
    EXPECT_NE(run.status, 0) << command;
    EXPECT_NE(run.status, -1) << command;
  }
}

// A pipe whose reader is gone (`artcal evaluate P | head -c 1` once head has left): the reader
// has what it wanted, so the CLI ends silently with the status of a death by SIGPIPE (141, for
// `set -o pipefail`), as other tools do (issue 32: "Broken pipe" was printed), instead of dying by
// the signal. The reading end is closed before artcal starts, so that the outcome does not depend
// on timing.
TEST(HostileOutputs, AClosedPipeOnStandardOutputEndsSilentlyNotByASignal) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  ::close(fds[0]);
  const std::string plan = testDataFile("ref-2r-5bars.json");
  char errors[] = "/tmp/artcal-pipe-stderr-XXXXXX";
  const int err = ::mkstemp(errors);
  ASSERT_GE(err, 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::dup2(fds[1], STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    ::execl(ARTCAL_CLI, ARTCAL_CLI, "evaluate", plan.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(fds[1]);
  ::close(err);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 141);
  EXPECT_EQ(readText(errors), "");
  ::unlink(errors);
}

TEST(HostileOutputs, ReportFiguresAreCheckedBeforeAnyIsWritten) {
  Scratch scratch;
  const std::string plan = shellQuoted(testDataFile("ref-2r-5bars.json"));
  const std::string svg = scratch.file("svg");
  const std::string html = scratch.file("report.html");
  ASSERT_EQ(
      runCli("report " + plan + " -o " + shellQuoted(html) + " --svg " + shellQuoted(svg)).status,
      0);
  std::vector<fs::path> figures;
  for (const auto& entry : fs::directory_iterator(svg)) figures.push_back(entry.path());
  ASSERT_GE(figures.size(), 2u);
  for (const fs::path& figure : figures) std::ofstream(figure) << "old";
  std::ofstream(html) << "old";
  fs::remove(figures.back());
  fs::create_directory(figures.back());  // one target cannot be replaced
  const CliRun run = runCli(
      "report " + plan + " -o " + shellQuoted(html) + " --svg " + shellQuoted(svg), Stderr::Only);
  EXPECT_EQ(run.status, 2) << run.out;
  EXPECT_NE(run.out.find("is a directory"), std::string::npos) << run.out;
  EXPECT_EQ(readText(html), "old");
  for (std::size_t i = 0; i + 1 < figures.size(); ++i) EXPECT_EQ(readText(figures[i]), "old");
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(svg)) ++entries;
  EXPECT_EQ(entries, figures.size());  // no temporary file left
}

TEST(HostileOutputs, EveryPlanOfAPlacementSweepIsCheckedBeforeTheSearch) {
  Scratch scratch;
  const std::string spec = shellQuoted(planFile("seed-2r-5bars.spec.json"));
  const std::string name = json::parse(readText(planFile("seed-2r-5bars.spec.json")))["name"];
  const fs::path dir = scratch.dir / "sweep";
  fs::create_directories(dir / (name + "-3.json"));  // the plan for 3 placements: a directory
  const CliRun run =
      runCli("optimize " + spec + " --placements 2..4 --quiet -o " + shellQuoted(dir.string()),
             Stderr::Only);
  EXPECT_EQ(run.status, 2) << run.out;
  EXPECT_NE(run.out.find(name + "-3.json: is a directory"), std::string::npos) << run.out;
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1u);  // nothing written
  const std::string file = scratch.write("file", "keep");
  expectRefused("optimize " + spec + " --placements 2..4 --quiet -o " + shellQuoted(file), file,
                "not a directory");
  EXPECT_EQ(readText(file), "keep");
}

TEST(HostileOutputs, AMachineOfAnotherRobotIsRefusedNamingTheFirstDifference) {
  Scratch scratch;
  json machine = json::parse(readText(planFile("panda-8positions.machine.json")));
  machine["joints"][3]["axis"] = {1, 0, 0};
  const std::string file = scratch.write("other.json", machine.dump());
  expectRefused("verify " + shellQuoted(planFile("panda-front-center.json")) + " --machine " +
                    shellQuoted(file),
                file, "/joints/3/axis");
}

// A mimic joint is kept, never dropped (instruments.md: its master's one reading drives it); a
// mimic that cannot be resolved is refused naming the <mimic>'s line.
TEST(HostileOutputs, MimicJointsAreKeptNotDroppedAndBadMimicsRefused) {
  const std::string file = testDataFile("hostile/mimic-in-chain.urdf");
  const CliRun run = runCli("import-urdf " + shellQuoted(file) + " --base base --tip tip");
  ASSERT_EQ(run.status, 0) << run.out;
  const json machine = json::parse(run.out);
  EXPECT_EQ(machine["joints"][1]["mimic"],
            json({{"joint", "j1"}, {"multiplier", 2.0}, {"offset", 0.0}}));
  EXPECT_EQ(machine["joint_limits"], json({{-180.0, 180.0}}));  // j1's reading only
  const std::string missing = testDataFile("hostile/mimic-of-missing-joint.urdf");
  expectRefused("import-urdf " + shellQuoted(missing) + " --base base --tip tip", missing,
                "line 6: joint \"j2\" mimics joint \"no_such_joint\", which does not exist");
  const std::string cycle = testDataFile("hostile/mimic-cycle.urdf");
  expectRefused("import-urdf " + shellQuoted(cycle) + " --base base --tip tip", cycle, "(a cycle)");
}

TEST(HostileOutputs, CoincidentBallPlateCentresAreRefused) {
  json plan = referencePlan();
  plan["artifacts"]["plate"] = {{"type", "ball_plate"}, {"centers", {{0, 0}, {100, 0}, {100, 0}}}};
  try {
    (void)parsePlan(plan, "plan.json");
    ADD_FAILURE() << "two coincident centres accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "/artifacts/plate/centers");
    EXPECT_NE(std::string(e.what()).find("centers 1 and 2 coincide"), std::string::npos);
  }
}

TEST(HostileOutputs, ProcedureCsvQuotesAndNeutralisesTextFields) {
  EXPECT_EQ(csvTextField("bar80"), "bar80");
  EXPECT_EQ(csvTextField("a,b"), "\"a,b\"");
  EXPECT_EQ(csvTextField("say \"x\""), "\"say \"\"x\"\"\"");
  EXPECT_EQ(csvTextField("two\nlines"), "\"two\nlines\"");
  EXPECT_EQ(csvTextField("=HYPERLINK(1)"), "'=HYPERLINK(1)");
  EXPECT_EQ(csvTextField("-2+3"), "'-2+3");
  EXPECT_EQ(csvTextField("@SUM(A1,A2)"), "\"'@SUM(A1,A2)\"");
}

// ------------------------------------------------------------------- no NaN, inf, null output

TEST(HostileNumbers, EveryNumberOptionRefusesNonFiniteValues) {
  const std::string plan = shellQuoted(testDataFile("ref-2r-5bars.json"));
  for (const std::string& command :
       {"evaluate " + plan + " --rank-tol nan", "check " + plan + " --rank-tol inf",
        "optimize " + shellQuoted(planFile("seed-2r-5bars.spec.json")) +
            " -o /tmp/unused.json --placements 2..3 --target-tip nan",
        "confirm " + plan + " --noise-scale=-nan", "evaluate " + plan + " --profile-steps 1e999"}) {
    const CliRun run = runCli(command, Stderr::Only);
    EXPECT_EQ(run.status, 2) << command << "\n" << run.out;
    EXPECT_NE(run.out.find("expected a finite number"), std::string::npos) << run.out;
  }
}

TEST(HostileNumbers, UrdfNumbersBeyondTheBoundAreRefusedNotWrittenAsNull) {
  const std::string file = testDataFile("hostile/huge-limit-and-axis.urdf");
  expectRefused("import-urdf " + shellQuoted(file) + " --base base --tip tip", file,
                "joint \"j1\": <limit> beyond");
}

// ----------------------------------------------------------------------------------- messages

TEST(HostileMessages, ReadingsFromCsvAreLocatedByFileAndRow) {
  Plan plan = parsePlan(json::parse(readText(planFile("panda-front-center.json"))),
                        planFile("panda-front-center.json"));
  const ReadingLocation at = readingLocation(plan, 0, 3);
  EXPECT_EQ(fs::path(at.file).filename(), "hole_0.csv");
  EXPECT_TRUE(fs::exists(at.file)) << at.file;
  EXPECT_EQ(at.where, "row 4");
  const Plan inline_plan = parsePlan(referencePlan(), "plan.json");
  EXPECT_EQ(readingLocation(inline_plan, 1, 0).where, "/placements/1/measurements/0");
}

TEST(HostileMessages, AByteOrderMarkIsDroppedAndADirectoryIsNamed) {
  Scratch scratch;
  const std::string plan =
      scratch.write("bom.json", "\xEF\xBB\xBF" + readText(testDataFile("ref-2r-5bars.json")));
  EXPECT_EQ(runCli("check " + shellQuoted(plan)).status, 0);
  const std::string csv = scratch.write("bom.csv", "\xEF\xBB\xBFj1,j2\n1,2\n");
  EXPECT_EQ(readJointCsv(csv, {JointKind::Revolute, JointKind::Revolute}, ReadingUnits{}).size(),
            1u);
  const std::string dir = scratch.dir.string();
  expectRefused("import-urdf " + shellQuoted(dir) + " --base a --tip b", dir, "is a directory");
}

TEST(HostileMessages, AHugeUrdfAxisIsNamedAsSuchNotAsAZeroAxis) {
  Scratch scratch;
  std::string urdf = readText(testDataFile("hostile/huge-limit-and-axis.urdf"));
  urdf.replace(urdf.find("lower=\"-1e308\""), 14, "lower=\"-1\"");
  urdf.replace(urdf.find("upper=\"1e308\""), 13, "upper=\"1\"");
  const std::string file = scratch.write("axis.urdf", urdf);
  expectRefused("import-urdf " + shellQuoted(file) + " --base base --tip tip", file,
                "<axis xyz> needs 3 numbers within +-1e9");
}

}  // namespace hostile_inputs_test
