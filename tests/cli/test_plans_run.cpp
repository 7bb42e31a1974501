// Every example plan in plans/ runs (issue 9, "plans that run"): `simulate` writes readings that
// `calibrate` converges on, and `confirm` confirms the prediction with a few trials (1000 trials
// are measured by hand: docs/hardening.md). A plan `optimize` wrote keeps its readings
// `design.joint_margin` inside the joint limits, so that a machine off nominal reaches them too.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "artcal/internal.hpp"
#include "cli_runner.hpp"
#include "sanitizers.hpp"

namespace artcal {
namespace plans_run_test {

namespace fs = std::filesystem;
using test_support::CliRun;
using test_support::runCli;
using test_support::Stderr;

/// The leave-one-out pairs of the MUKCa Panda (panda-all-but-X, panda-position-X) but the first:
/// the same readings and code paths in other combinations, left out under the sanitizers only
/// (they cost a minute there; the Release run takes every plan).
bool repeatsAnotherUnderSanitizers(const std::string& name) {
  if (!test_support::kUnderSanitizers) return false;
  const bool pair = name.rfind("panda-all-but-", 0) == 0 || name.rfind("panda-position-", 0) == 0;
  return pair && name.find("front-center") == std::string::npos;
}

/// The plans of plans/ (the optimization specs are inputs of optimize, not plans).
std::vector<std::string> examplePlans() {
  std::vector<std::string> plans;
  for (const auto& entry : fs::directory_iterator(ARTCAL_PLANS_DIR)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".json" || name.find(".spec.") != std::string::npos) continue;
    if (repeatsAnotherUnderSanitizers(name)) continue;
    std::ifstream in(entry.path());
    const nlohmann::json document = nlohmann::json::parse(in);
    // plans/ also holds machine blocks (calibrate --write-machine): not plans
    if (document.value("format", "") == "artcal-plan/1") plans.push_back(entry.path().string());
  }
  std::sort(plans.begin(), plans.end());
  return plans;
}

/// A plan of real readings (measurements from CSV files, the MUKCa Panda): its calibrated
/// parameters can be so poorly determined (u of degrees) that a machine perturbed by 1 u cannot
/// reach the readings' points, and its linear prediction need not hold (docs/hardening.md).
bool hasRealReadings(const std::string& plan) {
  std::ifstream in(plan);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str().find("\"csv\"") != std::string::npos;
}

std::string tempPath(const std::string& name) {
  return (fs::temp_directory_path() /
          ("artcal-plans-run-" + std::to_string(::getpid()) + "-" + name))
      .string();
}

TEST(PlansRun, ThereAreExamplePlans) {
  EXPECT_GE(examplePlans().size(), 5u);
}

// simulate (the nominal machine as the truth, so that the test says nothing about the size of a
// perturbation), then calibrate the simulated readings.
TEST(PlansRun, SimulateAndCalibrateEveryPlan) {
  const std::string truth = tempPath("truth.json");
  std::ofstream(truth) << R"({"parameters": {}})";
  for (const std::string& plan : examplePlans()) {
    SCOPED_TRACE(plan);
    const std::string out = tempPath(fs::path(plan).filename().string());
    const CliRun simulated = runCli(
        "simulate '" + plan + "' --truth '" + truth + "' --seed 3 -o '" + out + "'", Stderr::Merge);
    ASSERT_EQ(simulated.status, 0) << simulated.out;
    const CliRun calibrated = runCli("calibrate '" + out + "'", Stderr::Merge);
    // Planned readings converge; real ones (u of degrees) get converged or not, never an error.
    if (!hasRealReadings(plan)) {
      EXPECT_EQ(calibrated.status, 0) << calibrated.out;
    } else {
      EXPECT_TRUE(calibrated.status == 0 || calibrated.status == 1) << calibrated.out;
    }
    fs::remove(out);
  }
  fs::remove(truth);
}

// confirm with 12 trials (the band is wide at that count; 1000 are run by hand). Planned
// readings confirm; a plan of real readings gets an answer, never bad input or a crash: exit 0,
// or exit 1 with one line naming the reading, the joint and the trial.
TEST(PlansRun, ConfirmEveryPlan) {
  for (const std::string& plan : examplePlans()) {
    SCOPED_TRACE(plan);
    const CliRun r =
        runCli("confirm '" + plan + "' --trials 12 --seed 1 --threads 2 --quiet", Stderr::Merge);
    if (!hasRealReadings(plan)) {
      EXPECT_EQ(r.status, 0) << r.out;
      EXPECT_EQ(r.out.find("error:"), std::string::npos) << r.out;
    } else if (r.status != 0) {
      EXPECT_EQ(r.status, 1) << r.out;
      const auto error = r.out.find("error: " + plan + ": /placements/");
      if (error != std::string::npos) {
        EXPECT_NE(r.out.find("cannot reach this reading's point: joint", error), std::string::npos)
            << r.out;
        EXPECT_NE(r.out.find(": trial ", error), std::string::npos) << r.out;
      }
    }
  }
}

// Every reading of a plan with a design block stays the design's joint margin (default 2 deg /
// 1 mm) inside each joint's limits; joints with a full turn of range wrap and need none.
TEST(PlansRun, OptimizedReadingsKeepTheJointMargin) {
  int checked = 0;
  for (const std::string& path : examplePlans()) {
    const Plan plan = loadPlan(path);
    if (!plan.design) continue;
    SCOPED_TRACE(path);
    const Machine& machine = plan.machine;
    for (const Placement& placement : plan.placements) {
      for (const Measurement& m : placement.measurements) {
        for (int i = 0; i < m.joints.size(); ++i) {
          const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
          const bool revolute = machine.mechanism->jointKind(i) == JointKind::Revolute;
          if (revolute && hi - lo >= 2 * std::numbers::pi - 1e-12) continue;
          const double margin =
              plan.design->joint_margin.size() > i
                  ? plan.design->joint_margin[i]
                  : (revolute ? degToRad(kDefaultRevoluteMarginDeg) : kDefaultPrismaticMarginMm);
          EXPECT_GE(m.joints[i], lo + margin * (1 - 1e-9)) << "joint " << i + 1;
          EXPECT_LE(m.joints[i], hi - margin * (1 - 1e-9)) << "joint " << i + 1;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 0);
}

}  // namespace plans_run_test
}  // namespace artcal
