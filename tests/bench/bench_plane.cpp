// `evaluate` of a plane plan against a ball-bar plan of the same size (issue 30: within 1.5x):
// the 6-axis arm of plans/planes/arm6-planes.json, 100 readings and 10 000 workspace
// configurations each, the whole evaluatePlan (rank test, V_p, workspace sampling and the tip
// uncertainty over it).
//
//   build/tests/bench/bench_plane
//   build/tests/bench/bench_plane --benchmark_filter=Plane

#include <benchmark/benchmark.h>

#include <fstream>

#include "../support/plan_builders.hpp"
#include "artcal/io/plan_io.hpp"
#include "evaluate_loop.hpp"

namespace artcal {
namespace {

constexpr int kConfigurations = 10000;

nlohmann::json arm6Planes() {
  std::ifstream in(std::string(ARTCAL_PLANS_DIR) + "/planes/arm6-planes.json");
  nlohmann::json document = nlohmann::json::parse(in);
  document["workspace"] = {{"samples", kConfigurations}, {"seed", 5}};
  return document;
}

// The plan's three table placements cut to 28 touches each, and its gauge block's 16: 100.
Plan planePlan() {
  nlohmann::json document = arm6Planes();
  for (auto& placement : document["placements"]) {
    if (placement["artifact"] != "table") continue;
    auto& touches = placement["measurements"];
    touches.erase(touches.begin() + 28, touches.end());
  }
  return parsePlan(document, "arm6-planes-100");
}

// The same machine, noise and workspace with 25 ball bars (400 mm) at random poses, each ball
// read in 2 postures: 100 readings.
Plan ballBarPlan() {
  nlohmann::json document = arm6Planes();
  document["artifacts"] = {{"bar", {{"type", "ball_bar"}, {"length", 400.0}}}};
  document["placements"] = nlohmann::json::array();
  Plan plan = parsePlan(document, "arm6-bars-100", false);
  plan.placements = testing::randomSpatialBars(plan, 25, 2, 3);
  return plan;
}

void PlaneEvaluate100Touches(benchmark::State& state) {
  bench::runEvaluate(state, planePlan(), kConfigurations);
}
BENCHMARK(PlaneEvaluate100Touches)->Unit(benchmark::kMillisecond);

void BallBarEvaluate100Readings(benchmark::State& state) {
  bench::runEvaluate(state, ballBarPlan(), kConfigurations);
}
BENCHMARK(BallBarEvaluate100Readings)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace artcal
