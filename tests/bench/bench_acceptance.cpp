// Cost of the ISO 10360-2 prediction (spec acceptance.md) on the shipped CMM plan
// (cmm-plate-3planes-2styli: 50 calibrated coefficients): the linear part for the 105 results
// (35 gauges: ends, axis readings, J_p and J_q at both ends, sigma_sys, sigma_noise, the gauges'
// systematic covariance; target < 1 ms) and 10^5 Monte-Carlo trials (target < 1 s on two cores).
//
//   build/tests/bench/bench_acceptance

#include <benchmark/benchmark.h>

#include "artcal/acceptance/length_acceptance.hpp"
#include "artcal/internal.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace {

struct Shipped {
  Plan plan;
  AcceptanceInput input;
  LengthTestOptions options;
};

Shipped shipped() {
  Shipped s{loadPlan(test_support::planFile("cmm-plate-3planes-2styli.json")), {}, {}};
  s.input = *acceptanceInputFromPlan(s.plan, evaluatePlan(s.plan));
  s.input.machine = &s.plan.machine;
  s.options.mpe = *parseMpe("1.5 + L/333");
  return s;
}

void LengthTestLinear105Results(benchmark::State& state) {
  const Shipped s = shipped();
  double worst = 0.0;
  for (auto _ : state) {
    const LengthTestPrediction prediction = predictLengthTestLinear(s.input, s.options);
    worst = prediction.gauges.back().sigma_sys;
    benchmark::DoNotOptimize(worst);
  }
  state.counters["parameters"] = static_cast<double>(s.input.uncertainty.indices.size());
}
BENCHMARK(LengthTestLinear105Results)->Unit(benchmark::kMicrosecond);

void LengthTestMonteCarlo1e5Trials(benchmark::State& state) {
  const Shipped s = shipped();
  const LengthTestPrediction linear = predictLengthTestLinear(s.input, s.options);
  const LinearGaussianTest model = lengthTestModel(linear, s.input);
  MonteCarloOptions options;
  options.trials = 100000;
  options.threads = static_cast<int>(state.range(0));
  double p = 0.0;
  for (auto _ : state) {
    p = runMonteCarlo(model, options).p_pass;
    benchmark::DoNotOptimize(p);
  }
  state.counters["p_pass"] = p;
  state.counters["threads"] = static_cast<double>(options.threads);
}
BENCHMARK(LengthTestMonteCarlo1e5Trials)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace artcal
