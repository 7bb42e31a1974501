// Speed of joint compliance (issue 47, docs/compliance.md) on the UR5's 1000 laser-tracker
// readings of tests/data/ur5-tracker (train/grid.csv), imported as the README's plain path does
// (import-readings --instrument 0.015, "calibrate": "identifiable") and calibrated through
// calibrateReadings (rank rule, weak rule, plausible minimum, held-out model choice):
//   BM_CalibrateUr5Geometric: ur5.machine.json, geometric parameters only;
//   BM_CalibrateUr5Compliance: ur5-compliance.machine.json, the same with UR's published masses
//     and a compliance per joint (the held-out choice adds the geometric-only candidate).
// Target (issue 47): compliance within 2 times geometric-only.
// Run: build/tests/bench/bench_compliance

#include <benchmark/benchmark.h>

#include <string>

#include "artcal/calibration/calibrate_readings.hpp"
#include "artcal/internal.hpp"
#include "artcal/io/readings_import.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace {

Plan ur5Plan(const char* machine_file) {
  const std::string folder = std::string(ARTCAL_TEST_DATA) + "/ur5-tracker";
  ReadingsImport import;
  import.folder = folder + "/train";
  import.machine_file = folder + "/" + machine_file;
  import.instrument = 0.015;
  import.output = folder + "/train.json";
  const ImportedPlan imported = importReadings(import);
  return parsePlan(imported.plan, imported.source);
}

void calibrateUr5(benchmark::State& state, const char* machine_file) {
  const Plan plan = ur5Plan(machine_file);
  CalibrationOptions options;
  options.details = false;
  int kept = 0;
  for (auto _ : state) {
    const CalibrationRun run = calibrateReadings(plan, options);
    if (!run.calibration.summary.converged()) state.SkipWithError("did not converge");
    kept = static_cast<int>(run.kept().size());
    benchmark::DoNotOptimize(run.calibration.parameters.data());
  }
  state.counters["parameters"] = kept;
}

void BM_CalibrateUr5Geometric(benchmark::State& state) {
  calibrateUr5(state, "ur5.machine.json");
}
BENCHMARK(BM_CalibrateUr5Geometric)->Unit(benchmark::kMillisecond);

void BM_CalibrateUr5Compliance(benchmark::State& state) {
  calibrateUr5(state, "ur5-compliance.machine.json");
}
BENCHMARK(BM_CalibrateUr5Compliance)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace artcal
