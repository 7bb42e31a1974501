// Five-axis machine tools (issue 31, docs/five-axis.md): `evaluate` of 100 probings with 10 000
// workspace configurations (target <= 5 ms) and `calibrate` of 100 probings (target <= 10 ms), on
// the trunnion of plans/machine-tool-trunnion-2spheres.json: two spheres, 50 probings each (A
// at 5 positions, C at 10); and the table-spindle ball bar of
// plans/machine-tool-trunnion-ballbar.json cut to 100 readings.
//
//   build/tests/bench/bench_machine_tool

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include <cmath>
#include <fstream>
#include <numbers>

#include "artcal/calibration/calibrator.hpp"
#include "artcal/calibration/simulation.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/io/plan_io.hpp"
#include "evaluate_loop.hpp"

namespace artcal {
namespace {

constexpr int kConfigurations = 10000;

nlohmann::json planDocument(const std::string& name) {
  std::ifstream in(std::string(ARTCAL_PLANS_DIR) + "/" + name);
  nlohmann::json document = nlohmann::json::parse(in);
  document["workspace"] = {{"samples", kConfigurations}, {"seed", 5}};
  return document;
}

// The nominal axis readings (mm, deg) that put the probe ball at workpiece point w: the table
// turned by A about X, then C about Z (five-axis.md section 2), the tip the tool length below
// the spindle nose.
nlohmann::json probing(const Eigen::Vector3d& w, double a_deg, double c_deg, double tool) {
  const double d = std::numbers::pi / 180.0;
  const Eigen::Vector3d t = Eigen::AngleAxisd(a_deg * d, Eigen::Vector3d::UnitX()) *
                            (Eigen::AngleAxisd(c_deg * d, Eigen::Vector3d::UnitZ()) * w);
  return {{"feature", 0}, {"joints", {t.x(), t.y(), t.z() + tool, a_deg, c_deg}}};
}

Plan spheres100() {
  nlohmann::json document = planDocument("machine-tool-trunnion-2spheres.json");
  const double tool = document["machine"]["tool_length"].get<double>();
  const Eigen::Vector3d centres[2] = {{150.0, 0.0, 50.0}, {-80.0, 120.0, 150.0}};
  for (int s = 0; s < 2; ++s) {
    nlohmann::json measurements = nlohmann::json::array();
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 10; ++j)
        measurements.push_back(probing(centres[s], -90.0 + 22.5 * i, -180.0 + 36.0 * j, tool));
    document["placements"][s]["measurements"] = measurements;
  }
  return parsePlan(document, "trunnion-100-probings");
}

Plan ballBar100() {
  nlohmann::json document = planDocument("machine-tool-trunnion-ballbar.json");
  for (auto& placement : document["placements"]) {
    auto& readings = placement["measurements"];
    readings.erase(readings.begin() + 50, readings.end());
  }
  return parsePlan(document, "trunnion-ballbar-100");
}

// Readings simulated once from the nominal machine plus 20 um / 20 urad on every calibrated
// parameter; each iteration is the whole calibration from nominal.
void runCalibrate(benchmark::State& state, const Plan& plan) {
  Eigen::VectorXd truth = plan.machine.nominal;
  for (int k : plan.machine.calibrated)
    truth[k] += plan.machine.mechanism->parameters()[static_cast<std::size_t>(k)].quantity ==
                        Quantity::Angle
                    ? 20e-6
                    : 0.02;
  NormalSource normal(7);
  const SimulatedRun run = Simulator(plan).simulate(truth, normal);
  int iterations = 0;
  for (auto _ : state) {
    Calibrator calibrator(plan, CalibrationOptions{});
    const Calibration result = calibrator.run(run.placements);
    if (!result.summary.converged()) {
      state.SkipWithError("not converged");
      return;
    }
    iterations = result.summary.iterations;
  }
  state.counters["iterations"] = iterations;
}

void MachineToolEvaluate100Probings(benchmark::State& state) {
  bench::runEvaluate(state, spheres100(), kConfigurations);
}
BENCHMARK(MachineToolEvaluate100Probings)->Unit(benchmark::kMillisecond);

void MachineToolCalibrate100Probings(benchmark::State& state) {
  runCalibrate(state, spheres100());
}
BENCHMARK(MachineToolCalibrate100Probings)->Unit(benchmark::kMillisecond);

void MachineToolBallBarEvaluate100Readings(benchmark::State& state) {
  bench::runEvaluate(state, ballBar100(), kConfigurations);
}
BENCHMARK(MachineToolBallBarEvaluate100Readings)->Unit(benchmark::kMillisecond);

void MachineToolBallBarCalibrate100Readings(benchmark::State& state) {
  runCalibrate(state, ballBar100());
}
BENCHMARK(MachineToolBallBarCalibrate100Readings)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace artcal
