// Speed of choosing readings from a pool (issue 45, planning/reading_pool.hpp):
//   BM_Choose50Of12000/<criterion>: 50 of 12 000 candidate readings of a simulated 6-axis arm
//     (the serial-dh machine of tests/data/ref-instrument-arm6-2stations.json, its 21 calibrated
//     parameters, limits +-170 deg) measured by a tracker from one station; the candidates
//     uniform within the limits (seed 1), G over 4096 workspace samples. 8 starts, all cores,
//     1024 random candidates tried per slot (optimize --choose's default). Target (issue 45): <= 10
//     s for G on the 2-core machine. Counters: the criterion (um) and the starts done.
//   BM_PreparePool12000: the pool's rows and the workspace's Jacobians alone.
// Run: build/tests/bench/bench_reading_pool

#include <benchmark/benchmark.h>

#include <fstream>
#include <random>

#include "artcal/internal.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/planning/instrument_design.hpp"
#include "artcal/planning/reading_pool.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace {

/// The arm with one tracker station whose readings are `count` random configurations within the
/// limits, each point the nominal tip (planning only: the information does not depend on it).
Plan armPool(int count) {
  std::ifstream in(std::string(ARTCAL_TEST_DATA) + "/ref-instrument-arm6-2stations.json");
  nlohmann::json document = nlohmann::json::parse(in);
  document.erase("predicted");
  document["workspace"] = {{"samples", 4096}, {"seed", 1}};
  Plan plan = parsePlan(document, "arm6.json");
  plan.placements.clear();
  std::mt19937_64 rng(1);
  Placement station;
  station.artifact = 0;
  station.name = "pool";
  const Machine& machine = plan.machine;
  for (int i = 0; i < count; ++i) {
    Measurement m;
    m.joints.resize(static_cast<int>(machine.joint_limits.size()));
    for (int j = 0; j < m.joints.size(); ++j) {
      const auto& limits = machine.joint_limits[static_cast<std::size_t>(j)];
      m.joints[j] = std::uniform_real_distribution<double>(limits[0], limits[1])(rng);
    }
    setNominalReading(machine, plan.artifacts[0], m);
    station.measurements.push_back(std::move(m));
  }
  appendDesignedPlacements(plan, {station});
  return plan;
}

const Plan& pool12000() {
  static const Plan plan = armPool(12000);
  return plan;
}

void BM_PreparePool12000(benchmark::State& state) {
  const Plan& plan = pool12000();
  for (auto _ : state) {
    const ReadingPool pool(plan);
    benchmark::DoNotOptimize(pool.size());
  }
}
BENCHMARK(BM_PreparePool12000)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_Choose50Of12000(benchmark::State& state, Criterion criterion) {
  const ReadingPool pool(pool12000());
  PoolOptions options;
  options.criterion = criterion;
  options.time_limit = 600.0;
  options.slot_candidates = 1024;  // optimize --choose's default
  PoolChoice choice;
  for (auto _ : state) choice = chooseReadings(pool, 50, options);
  state.counters["criterion_um"] = choice.value * 1000.0;
  state.counters["starts_done"] = choice.starts_done;
}
BENCHMARK_CAPTURE(BM_Choose50Of12000, worst - tip, Criterion::WorstTip)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Choose50Of12000, D, Criterion::D)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace
}  // namespace artcal
