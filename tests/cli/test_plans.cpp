// The example plans in plans/: every one loads and is identifiable, their readings put the probe on
// the features of the stated poses, and their figures are the ones README.md states (the README's
// walk-through and tables are real output of these plans; regenerating a plan means updating both).

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include <sys/wait.h>

#include "artcal/internal.hpp"
#include "cli_runner.hpp"

namespace artcal {
namespace plans_test {

namespace fs = std::filesystem;

std::string plansDir() {
  return ARTCAL_PLANS_DIR;
}
std::string planPath(const std::string& name) {
  return plansDir() + "/" + name + ".json";
}

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string readme() {
  return readText(plansDir() + "/../README.md");
}

using test_support::runCli;

// A figure as README.md prints it: 8 significant digits, lengths in um, angles in deg.
struct Figure {
  std::string label;  ///< parameter name, or tip.worst, tip.kinematic, tip.encoder, tip.mean
  std::string text;
};

struct ExamplePlan {
  std::string name;
  std::vector<Figure> figures;
};

// The figures README.md states ("Figures of the example plans").
const std::vector<ExamplePlan>& examplePlans() {
  static const std::vector<ExamplePlan> plans = {
      {"paper-2r-5bars",
       {{"l1", "7.4984179"},
        {"l2", "4.8548067"},
        {"dt2", "0.0026612263"},
        {"tip.worst", "13.577971"},
        {"tip.kinematic", "12.780032"},
        {"tip.encoder", "4.5860731"},
        {"tip.mean", "10.608757"}}},
      {"paper-2r-20bars",
       {{"l1", "4.2442137"},
        {"l2", "2.4024413"},
        {"dt2", "0.0010195031"},
        {"tip.worst", "8.0098541"},
        {"tip.kinematic", "6.4969693"},
        {"tip.encoder", "4.6847788"},
        {"tip.mean", "6.2898068"}}},
      {"aacmm-6axis-3bars", {{"j1.a", "5.2177645"},          {"j1.alpha", "0.00058303531"},
                             {"j2.theta", "0.00056422864"},  {"j2.d", "5.5595225"},
                             {"j2.a", "6.8612707"},          {"j2.alpha", "0.00056063674"},
                             {"j3.theta", "0.00048731715"},  {"j3.d", "13.455289"},
                             {"j3.a", "3.9310039"},          {"j3.alpha", "0.0015442146"},
                             {"j4.theta", "0.001958101"},    {"j4.d", "19.054039"},
                             {"j4.a", "22.504418"},          {"j4.alpha", "0.0019896043"},
                             {"j5.theta", "0.002619694"},    {"j5.d", "12.130734"},
                             {"j5.a", "4.4321009"},          {"j5.alpha", "0.0022899736"},
                             {"probe.x", "5.051342"},        {"probe.y", "4.5711164"},
                             {"probe.z", "4.8402022"},       {"tip.worst", "52.596773"},
                             {"tip.kinematic", "50.826998"}, {"tip.encoder", "13.529107"},
                             {"tip.mean", "31.354439"}}},
  };
  return plans;
}

/// The figure `label` of an `artcal evaluate --json` document, in README units (um or deg).
double figureOf(const nlohmann::json& evaluation, const std::string& label) {
  const auto& tip = evaluation.at("tip");
  if (label == "tip.worst") return 1000.0 * tip.at("worst").at("total").get<double>();
  if (label == "tip.kinematic") return 1000.0 * tip.at("worst").at("kinematic").get<double>();
  if (label == "tip.encoder") return 1000.0 * tip.at("worst").at("encoder").get<double>();
  if (label == "tip.mean") return 1000.0 * tip.at("mean").get<double>();
  for (const auto& parameter : evaluation.at("parameters")) {
    if (parameter.at("name") != label) continue;
    const double u = parameter.at("u").get<double>();
    return parameter.at("unit") == "mm" ? 1000.0 * u : u;
  }
  ADD_FAILURE() << "no figure " << label;
  return 0.0;
}

void expectFigures(const ExamplePlan& example, const nlohmann::json& evaluation) {
  ASSERT_TRUE(evaluation.at("identifiable").get<bool>()) << example.name;
  EXPECT_EQ(evaluation.at("parameters").size() + 4, example.figures.size()) << example.name;
  for (const Figure& figure : example.figures) {
    const double expected = std::stod(figure.text);
    EXPECT_NEAR(figureOf(evaluation, figure.label), expected, 1e-6 * expected)
        << example.name << " " << figure.label;
  }
}

bool hasPlacements(const std::string& path) {
  const nlohmann::json document = readJsonFile(path);
  return document.contains("placements") && !document["placements"].empty();
}

TEST(Plans, EveryPlanLoadsAndIsIdentifiable) {
  int plans = 0;
  for (const auto& entry : fs::directory_iterator(plansDir())) {
    if (entry.path().extension() != ".json") continue;
    const std::string path = entry.path().string();
    // plans/ also holds calibrated machine blocks (calibrate --write-machine): not plans.
    if (readJsonFile(path).value("format", "") != "artcal-plan/1") continue;
    SCOPED_TRACE(path);
    ++plans;
    if (!hasPlacements(path)) {  // an optimization spec: it must load, placements come later
      EXPECT_NO_THROW(loadPlan(path, /*require_placements=*/false));
      continue;
    }
    const Plan plan = loadPlan(path);
    EXPECT_TRUE(plan.warnings.empty()) << plan.warnings.front();
    EXPECT_FALSE(plan.description.empty());
    const Evaluation evaluation = evaluatePlan(plan);
    EXPECT_TRUE(evaluation.identifiable());
    EXPECT_EQ(evaluation.identifiability.deficiency, 0);
  }
  EXPECT_GE(plans, static_cast<int>(examplePlans().size()));
}

TEST(Plans, ExampleFiguresAreTheReadmeFigures) {
  for (const ExamplePlan& example : examplePlans()) {
    const Plan plan = loadPlan(planPath(example.name));
    expectFigures(example, evaluationToJson(plan, evaluatePlan(plan)));
  }
}

TEST(Plans, ReadmeStatesEveryFigure) {
  const std::string text = readme();
  ASSERT_FALSE(text.empty());
  for (const ExamplePlan& example : examplePlans()) {
    for (const Figure& figure : example.figures) {
      EXPECT_NE(text.find(figure.text), std::string::npos)
          << example.name << " " << figure.label << " " << figure.text;
    }
  }
}

// The command line the demo runs prints the same figures and exits 0.
TEST(Plans, CommandLineGivesTheSameFigures) {
  for (const ExamplePlan& example : examplePlans()) {
    SCOPED_TRACE(example.name);
    EXPECT_EQ(runCli("check " + planPath(example.name)).status, 0);
    const auto [status, out] = runCli("evaluate --json " + planPath(example.name));
    ASSERT_EQ(status, 0);
    expectFigures(example, nlohmann::json::parse(out));
  }
}

// The reconstructions were chosen to be near the seed's Table 2 (method.md section 8).
TEST(Plans, ReconstructionsAreNearTheSeedsTable2) {
  struct Row {
    std::string plan;
    double l1_um, l2_um, dt2_deg;
  };
  for (const Row& row :
       {Row{"paper-2r-5bars", 7.5, 4.9, 0.0026}, Row{"paper-2r-20bars", 4.3, 2.4, 0.0010}}) {
    SCOPED_TRACE(row.plan);
    const Plan plan = loadPlan(planPath(row.plan));
    const nlohmann::json evaluation = evaluationToJson(plan, evaluatePlan(plan));
    EXPECT_NEAR(figureOf(evaluation, "l1"), row.l1_um, 0.05 * row.l1_um);
    EXPECT_NEAR(figureOf(evaluation, "l2"), row.l2_um, 0.05 * row.l2_um);
    EXPECT_NEAR(figureOf(evaluation, "dt2"), row.dt2_deg, 0.05 * row.dt2_deg);
  }
}

/// Machine-frame position of an artifact feature for a placement's stated pose.
Eigen::VectorXd featureInMachineFrame(const Plan& plan, const Placement& placement, int feature) {
  const Pose& pose = *placement.pose;
  const RigidTransform W = plan.machine.dimension() == 2
                               ? placePlanar(pose.center.head<2>(), pose.angle)
                               : placeSpatial(pose.center.head<3>(), pose.direction, pose.roll);
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  return W.inverse().apply(artifact.features.col(feature));
}

// Nominal readings: each one puts the nominal probe on its feature of the stated pose, within the
// joint limits; the 6-axis plan reads each ball in 3 distinct postures.
TEST(Plans, ReadingsReachTheFeaturesOfTheirPoses) {
  for (const ExamplePlan& example : examplePlans()) {
    SCOPED_TRACE(example.name);
    const Plan plan = loadPlan(planPath(example.name));
    for (const Placement& placement : plan.placements) {
      ASSERT_TRUE(placement.pose.has_value());
      for (const Measurement& m : placement.measurements) {
        Eigen::VectorXd x;
        forwardOrThrow(*plan.machine.mechanism, plan.machine.nominal, m.joints, x);
        EXPECT_LT((x - featureInMachineFrame(plan, placement, m.feature)).norm(), 1e-6);
        EXPECT_TRUE(plan.machine.withinLimits(m.joints));
      }
    }
  }
}

TEST(Plans, ArticulatedArmReadsEachBallInThreeDistinctPostures) {
  const Plan plan = loadPlan(planPath("aacmm-6axis-3bars"));
  EXPECT_EQ(plan.machine.calibratedCount(), 21);
  ASSERT_EQ(plan.placements.size(), 3u);
  for (const Placement& placement : plan.placements) {
    for (int feature = 0; feature < 2; ++feature) {
      std::vector<Eigen::VectorXd> postures;
      for (const Measurement& m : placement.measurements) {
        if (m.feature == feature) postures.push_back(m.joints);
      }
      ASSERT_EQ(postures.size(), 3u);
      for (std::size_t a = 0; a < postures.size(); ++a) {
        for (std::size_t b = a + 1; b < postures.size(); ++b) {
          EXPECT_GT((postures[a] - postures[b]).norm(), 0.5);  // rad: genuinely different
        }
      }
    }
  }
  // The seed's m >= 2 example: N(p) = 21, N(r) = 5, n = 2, o = 3, k = 3.
  const Evaluation evaluation = evaluatePlan(plan);
  EXPECT_EQ(evaluation.identifiability.counting.minimum_alike, 2);
}

}  // namespace plans_test
}  // namespace artcal
