// The planner's effort against its result: NLopt refinement algorithms compared on the seed's
// arm (5 and 20 bars) and the 6-axis arm. Counters: `G_um` (worst-case tip uncertainty of the
// result, um), `starts`. Run: build-*/tests/bench/bench_optimizer --benchmark_filter=...

#include <benchmark/benchmark.h>

#include "artcal/internal.hpp"
#include "artcal/planning/optimizer.hpp"

#include <algorithm>
#include <random>

#include "test_paths.hpp"

namespace artcal {
namespace {

Plan spec(const std::string& name) {
  return loadPlan(test_support::planFile(name + ".spec.json"), false);
}

void runOptimizer(benchmark::State& state, const std::string& name, RefineAlgorithm algorithm,
                  double smooth_power) {
  const Plan plan = spec(name);
  OptimizerOptions options = OptimizerOptions::fromDesign(*plan.design);
  options.algorithm = algorithm;
  options.smooth_power = smooth_power;
  double value = 0.0;
  for (auto _ : state) value = optimizePlan(plan, options).value;
  state.counters["G_um"] = value * 1000.0;
  state.counters["starts"] = options.starts;
}

// The criterion of random feasible layouts (the design space's own sampling: each bar's first
// ball uniform over the region, its direction uniform, elbow branches at random): `median_um`
// and `best_um` of `layouts` draws.
void randomLayouts(benchmark::State& state, const std::string& name) {
  const Plan plan = spec(name);
  const DesignSpace space(plan);
  DesignCriterion criterion(plan, plan.design->criterion);
  const int layouts = static_cast<int>(state.range(0));
  std::vector<double> values;
  for (auto _ : state) {
    values.clear();
    std::mt19937_64 rng(plan.design->seed);
    for (int l = 0; l < layouts; ++l) {
      Eigen::MatrixXd total = Eigen::MatrixXd::Zero(criterion.globalSize(), criterion.globalSize());
      for (int j = 0; j < plan.design->placements; ++j) {
        total += criterion.contribution(space.randomPlacement(rng, 100000)->second);
      }
      values.push_back(criterion.value(total));
    }
  }
  std::sort(values.begin(), values.end());
  state.counters["median_um"] = 1000.0 * values[values.size() / 2];
  state.counters["best_um"] = 1000.0 * values.front();
}

void registerAll() {
  for (const char* name : {"seed-2r-5bars", "seed-2r-20bars"}) {
    benchmark::RegisterBenchmark((std::string(name) + "/random-layouts").c_str(),
                                 [name](benchmark::State& state) { randomLayouts(state, name); })
        ->Arg(1000)
        ->Iterations(1)
        ->Unit(benchmark::kSecond);
  }
  struct Variant {
    const char* label;
    RefineAlgorithm algorithm;
    double power;
  };
  const Variant variants[] = {{"none", RefineAlgorithm::None, 0.0},
                              {"sbplx/max", RefineAlgorithm::Subplex, 0.0},
                              {"sbplx/p64", RefineAlgorithm::Subplex, 64.0},
                              {"bobyqa/max", RefineAlgorithm::Bobyqa, 0.0},
                              {"bobyqa/p64", RefineAlgorithm::Bobyqa, 64.0},
                              {"neldermead/max", RefineAlgorithm::NelderMead, 0.0},
                              {"cobyla/max", RefineAlgorithm::Cobyla, 0.0}};
  for (const char* name : {"seed-2r-5bars", "seed-2r-20bars", "aacmm-4bars-3postures"}) {
    for (const Variant& v : variants) {
      benchmark::RegisterBenchmark(
          (std::string(name) + "/" + v.label).c_str(),
          [name, v](benchmark::State& state) { runOptimizer(state, name, v.algorithm, v.power); })
          ->Iterations(1)
          ->Unit(benchmark::kSecond)
          ->UseRealTime();
    }
  }
}

const int registered = (registerAll(), 0);

}  // namespace
}  // namespace artcal
