// Cost of one prepared evaluation (PlanEvaluator: the workspace Jacobians computed once, as the
// optimizer uses it): information of p for the placements (Schur-reduced, method.md section 3),
// V_p, and the tip summary over the workspace (section 4).
//
//   build-core/tests/bench/bench_evaluator                        all
//   build-core/tests/bench/bench_evaluator --benchmark_filter=Seed2R20Bars
//   build-core/tests/bench/bench_evaluator --benchmark_filter=Aacmm30Bars
//   build-core/tests/bench/bench_evaluator --benchmark_filter=Placements   (linear in m)
//   build-core/tests/bench/bench_evaluator --benchmark_filter=Parameters
//   build-core/tests/bench/bench_evaluator --benchmark_filter=PeakMemory   (peak_rss_MB counter)

#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include "../support/plan_builders.hpp"
#include "artcal/estimation/error_functions.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/report/cartesian_report.hpp"
#include "artcal/report/report.hpp"

namespace artcal {
namespace {

using testing::aacmmPlan;
using testing::randomPlanarBars;
using testing::randomSpatialBars;
using testing::seedPlanar2RPlan;

std::vector<Eigen::VectorXd> sampledWorkspace(const Machine& machine, int samples) {
  WorkspaceSpec spec;
  spec.kind = WorkspaceSpec::Kind::Samples;
  spec.samples = samples;
  spec.seed = 11;
  return workspaceConfigurations(machine, spec);
}

// The same placements repeated up to `count` (the cost per placement does not depend on which).
std::vector<Placement> cycled(const std::vector<Placement>& base, int count) {
  std::vector<Placement> out;
  for (int j = 0; j < count; ++j) out.push_back(base[static_cast<std::size_t>(j) % base.size()]);
  return out;
}

void runEvaluations(benchmark::State& state, PlanEvaluator& evaluator,
                    const std::vector<Placement>& placements) {
  const std::vector<RigidTransform> poses =
      fitPlacements(evaluator.plan(), placements, evaluator.plan().machine.nominal);
  double worst = 0.0;
  for (auto _ : state) {
    const auto tip = evaluator.tip(placements, &poses);
    if (!tip) {
      state.SkipWithError("plan not identifiable");
      return;
    }
    // (No DoNotOptimize on the double: GCC 12 with benchmark 1.7.1 "+m,r" corrupts it.)
    worst = tip->worst.total;
  }
  state.counters["worst_tip_mm"] = worst;
  state.counters["placements"] = static_cast<double>(placements.size());
  state.counters["configurations"] = evaluator.workspace().size();
}

double peakResidentMegabytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// Target: <= 20 us per evaluation (the seed's 2R arm, 20 bars, 120 configurations).
void Seed2R20Bars(benchmark::State& state) {
  const Plan plan = seedPlanar2RPlan();
  const auto placements = randomPlanarBars(plan, 20, 3);
  PlanEvaluator evaluator(plan, sampledWorkspace(plan.machine, 120));
  runEvaluations(state, evaluator, placements);
}
BENCHMARK(Seed2R20Bars)->Unit(benchmark::kMicrosecond);

// The shipped plans/paper-2r-5bars.json as the Python module runs it (docs/python.md, "Cost of a
// call"; tests/bench/bench_python_evaluate.py times the same calls from Python): the prepared
// evaluation (artcal.Evaluator.tip: each r_j fitted per call) and the whole evaluate, with and
// without the JSON document (Plan.evaluate(per_configuration=False) returns that document).
void Paper2R5BarsPrepared(benchmark::State& state) {
  const Plan plan = loadPlan(std::string(ARTCAL_PLANS_DIR) + "/paper-2r-5bars.json");
  PlanEvaluator evaluator(plan);
  double worst = 0.0;
  for (auto _ : state) {
    const auto tip = evaluator.tip(plan.placements);
    if (tip) worst = tip->worst.total;
  }
  state.counters["worst_tip_mm"] = worst;
}
BENCHMARK(Paper2R5BarsPrepared)->Unit(benchmark::kMicrosecond);

void Paper2R5BarsEvaluate(benchmark::State& state) {
  const Plan plan = loadPlan(std::string(ARTCAL_PLANS_DIR) + "/paper-2r-5bars.json");
  const bool with_json = state.range(0) != 0;
  std::size_t size = 0;
  for (auto _ : state) {
    const Evaluation evaluation = evaluatePlan(plan);
    if (with_json) {
      nlohmann::json out = evaluationToJson(plan, evaluation);
      out.update(cartesianAnswersToJson(plan, cartesianAnswers(plan, &evaluation)));
      size = out.size();
    }
  }
  state.counters["json_members"] = static_cast<double>(size);
}
BENCHMARK(Paper2R5BarsEvaluate)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// Target: <= 1 ms (21 parameters, 30 bars x 2 balls x 3 postures, 10,000 configurations).
void Aacmm30Bars(benchmark::State& state) {
  const Plan plan = aacmmPlan();
  const auto placements = randomSpatialBars(plan, 30, 3, 5);
  PlanEvaluator evaluator(plan, sampledWorkspace(plan.machine, 10'000));
  runEvaluations(state, evaluator, placements);
}
BENCHMARK(Aacmm30Bars)->Unit(benchmark::kMicrosecond);

// The information of p alone against the number of placements m: linear (Schur reduction).
void PlacementsSeed2R(benchmark::State& state) {
  const Plan plan = seedPlanar2RPlan();
  const auto placements = cycled(randomPlanarBars(plan, 50, 3), static_cast<int>(state.range(0)));
  const auto poses = fitPlacements(plan, placements, plan.machine.nominal);
  PlanEvaluator evaluator(plan, sampledWorkspace(plan.machine, 120));
  for (auto _ : state) benchmark::DoNotOptimize(evaluator.information(placements, &poses).data());
  state.SetComplexityN(state.range(0));
}
BENCHMARK(PlacementsSeed2R)
    ->Arg(1)
    ->Arg(3)
    ->Arg(10)
    ->Arg(30)
    ->Arg(100)
    ->Arg(300)
    ->Arg(1000)
    ->Complexity(benchmark::oN)
    ->Unit(benchmark::kMicrosecond);

void PlacementsAacmm(benchmark::State& state) {
  const Plan plan = aacmmPlan();
  const auto placements =
      cycled(randomSpatialBars(plan, 30, 3, 5), static_cast<int>(state.range(0)));
  const auto poses = fitPlacements(plan, placements, plan.machine.nominal);
  PlanEvaluator evaluator(plan, sampledWorkspace(plan.machine, 1));
  for (auto _ : state) benchmark::DoNotOptimize(evaluator.information(placements, &poses).data());
  state.SetComplexityN(state.range(0));
}
BENCHMARK(PlacementsAacmm)
    ->Arg(1)
    ->Arg(3)
    ->Arg(10)
    ->Arg(30)
    ->Arg(100)
    ->Arg(300)
    ->Arg(1000)
    ->Complexity(benchmark::oN)
    ->Unit(benchmark::kMicrosecond);

// A full evaluation against the number of calibrated parameters (the first k of the 21), 30 bars,
// 10,000 configurations: the tip summary grows as N(p)^2 per configuration.
void ParametersAacmm(benchmark::State& state) {
  Plan plan = aacmmPlan();
  const auto placements = randomSpatialBars(plan, 30, 3, 5);
  plan.machine.calibrated.resize(static_cast<std::size_t>(state.range(0)));
  PlanEvaluator evaluator(plan, sampledWorkspace(plan.machine, 10'000));
  runEvaluations(state, evaluator, placements);
  state.SetComplexityN(state.range(0));
}
BENCHMARK(ParametersAacmm)->DenseRange(3, 21, 3)->Unit(benchmark::kMicrosecond);

// Peak memory of the prepared evaluator with 1000 placements and 10,000 configurations: the
// peak_rss_MB counter (whole process: run this benchmark alone). Target < 200 MB.
void PeakMemoryAacmm1000Placements(benchmark::State& state) {
  const Plan plan = aacmmPlan();
  const auto placements = cycled(randomSpatialBars(plan, 30, 3, 5), 1000);
  PlanEvaluator evaluator(plan, sampledWorkspace(plan.machine, 10'000));
  runEvaluations(state, evaluator, placements);
  state.counters["peak_rss_MB"] = peakResidentMegabytes();
}
BENCHMARK(PeakMemoryAacmm1000Placements)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace artcal
