#pragma once
// The loop of the `evaluate` benchmarks (bench_plane, bench_machine_tool): the whole evaluatePlan
// of one plan per iteration, its worst tip uncertainty, readings and workspace size as counters.

#include <benchmark/benchmark.h>

#include "artcal/estimation/evaluator.hpp"

namespace artcal::bench {

inline void runEvaluate(benchmark::State& state, const Plan& plan, int configurations) {
  int readings = 0;
  for (const Placement& placement : plan.placements)
    readings += static_cast<int>(placement.measurements.size());
  double worst = 0.0;
  for (auto _ : state) {
    const Evaluation evaluation = evaluatePlan(plan);
    if (!evaluation.tip) {
      state.SkipWithError("plan not identifiable");
      return;
    }
    worst = evaluation.tip->worst.total;
  }
  state.counters["worst_tip_mm"] = worst;
  state.counters["readings"] = readings;
  state.counters["configurations"] = configurations;
}

}  // namespace artcal::bench
