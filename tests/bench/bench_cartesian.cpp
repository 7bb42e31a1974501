// Cost of one prepared evaluation of a Cartesian CMM plan (models.md section 4): degree 3 (54
// coefficients, the plan's identifiable set calibrated), 12 ball-plate placements x 25 balls x 2
// styli, 10 000 workspace samples prepared once. Target: <= 2 ms per evaluation.
//
//   build-cmm/tests/bench/bench_cartesian

#include <benchmark/benchmark.h>

#include "artcal/internal.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace {

void Cartesian12Plates2Styli(benchmark::State& state) {
  Plan plan = loadPlan(test_support::planFile("cmm-plate-3planes-2styli.json"));
  // Twelve placements: the plan's nine (three per plane) and the first three again.
  for (int j = 0; j < 3; ++j)
    plan.placements.push_back(plan.placements[static_cast<std::size_t>(j)]);
  WorkspaceSpec spec;
  spec.kind = WorkspaceSpec::Kind::Samples;
  spec.samples = 10'000;
  spec.seed = 11;
  PlanEvaluator evaluator(plan, workspaceConfigurations(plan.machine, spec));
  const std::vector<RigidTransform> poses =
      fitPlacements(plan, plan.placements, plan.machine.nominal);
  double worst = 0.0;
  for (auto _ : state) {
    const auto tip = evaluator.tip(plan.placements, &poses);
    if (!tip) {
      state.SkipWithError("plan not identifiable");
      return;
    }
    worst = tip->worst.total;
  }
  state.counters["worst_tip_um"] = worst * 1000.0;
  state.counters["parameters"] = plan.machine.calibratedCount();
  state.counters["model_parameters"] = plan.machine.mechanism->parameterCount();
  state.counters["placements"] = static_cast<double>(plan.placements.size());
  state.counters["configurations"] = evaluator.workspace().size();
}
BENCHMARK(Cartesian12Plates2Styli)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace artcal
