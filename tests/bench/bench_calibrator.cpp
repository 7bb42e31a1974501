// Speed of the calibrator and of the Monte-Carlo confirmation (issue 4):
//   BM_CalibrateSixAxis100Placements: the 6-axis arm from 100 ball-bar placements x 6 readings
//     (2 balls x 3 postures), starting from nominal, readings simulated with a perturbed truth.
//     Target: <= 100 ms.
//   BM_Confirm20Bars1000Trials: 1000 simulated calibrations of the 20-bar planar 2R plan
//     (plans/paper-2r-20bars.json, or an equivalent generated here), both cores. Target: <= 10 s.
// Run: build/tests/bench/bench_calibrator

#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>

#include "artcal/calibration/calibrator.hpp"
#include "artcal/calibration/confirmation.hpp"
#include "artcal/calibration/simulation.hpp"
#include "artcal/internal.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace {

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(rng() >> 11) * 0x1.0p-53);
}

/// The 6-axis arm of tests/data/ref-aacmm-3bars-3postures.json with `count` random 300 mm bar
/// placements, each ball read in 3 postures (inverse kinematics at nominal).
Plan sixAxisPlan(int count) {
  Plan plan = loadPlan(test_support::testDataFile("ref-aacmm-3bars-3postures.json"));
  const Artifact& bar = plan.artifacts[0];
  std::mt19937_64 rng(2024);
  std::vector<Placement> placements;
  while (static_cast<int>(placements.size()) < count) {
    const double azimuth = uniform(rng, -3.1, 3.1);
    const double reach = uniform(rng, 450.0, 850.0);
    const Eigen::Vector3d center(reach * std::cos(azimuth), reach * std::sin(azimuth),
                                 uniform(rng, -200.0, 500.0));
    Eigen::Vector3d direction(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    if (direction.norm() < 0.2) continue;
    direction.normalize();
    const RigidTransform pose = placeSpatial(center, direction, 0.0);
    const RigidTransform inverse = pose.inverse();
    Placement placement;
    placement.artifact = 0;
    placement.pose = Pose{center, 0.0, direction, 0.0};
    bool reachable = true;
    for (int feature = 0; feature < 2 && reachable; ++feature) {
      const Eigen::VectorXd target = inverse.apply(bar.features.col(feature));
      const auto postures = diversePostures(plan.machine, plan.machine.nominal, target, 3, rng);
      reachable = postures.size() == 3;
      for (const Eigen::VectorXd& q : postures) placement.measurements.push_back({feature, q});
    }
    if (reachable) placements.push_back(std::move(placement));
  }
  plan.placements = std::move(placements);
  return plan;
}

void BM_CalibrateSixAxis100Placements(benchmark::State& state) {
  const Plan plan = sixAxisPlan(100);
  Eigen::VectorXd truth = plan.machine.nominal;
  for (int k = 0; k < plan.machine.calibratedCount(); ++k) {
    const int i = plan.machine.calibrated[static_cast<std::size_t>(k)];
    truth[i] += plan.machine.calibratedInfo(k).quantity == Quantity::Angle ? degToRad(0.01) : 0.05;
  }
  NormalSource normal(1);
  const std::vector<Placement> readings = Simulator(plan).simulate(truth, normal).placements;
  Calibrator calibrator(plan);
  int iterations = 0;
  for (auto _ : state) {
    const Calibration c = calibrator.run(readings);
    if (!c.summary.converged()) state.SkipWithError("did not converge");
    iterations = c.summary.iterations;
    benchmark::DoNotOptimize(c.parameters.data());
  }
  state.counters["LM_iterations"] = iterations;
  state.counters["readings"] = 600;
}
BENCHMARK(BM_CalibrateSixAxis100Placements)->Unit(benchmark::kMillisecond);

/// plans/paper-2r-20bars.json, or 20 random reachable bars of the seed's arm.
Plan twentyBarPlan() {
  const std::string path = test_support::planFile("paper-2r-20bars.json");
  if (std::filesystem::exists(path)) return loadPlan(path);
  Plan plan = loadPlan(test_support::testDataFile("ref-2r-5bars.json"));
  std::mt19937_64 rng(20);
  std::vector<Placement> placements;
  while (placements.size() < 20) {
    const Eigen::Vector2d center(uniform(rng, -200, 200), uniform(rng, -200, 200));
    const RigidTransform inverse = placePlanar(center, uniform(rng, -3.1, 3.1)).inverse();
    Placement placement;
    for (int feature = 0; feature < 2; ++feature) {
      const auto q = solveInverseKinematics(plan.machine, plan.machine.nominal,
                                            inverse.apply(plan.artifacts[0].features.col(feature)),
                                            Eigen::Vector2d(0.0, 1.5));
      if (q) placement.measurements.push_back({feature, *q});
    }
    if (placement.measurements.size() == 2) placements.push_back(placement);
  }
  plan.placements = placements;
  return plan;
}

void BM_Confirm20Bars1000Trials(benchmark::State& state) {
  const Plan plan = twentyBarPlan();
  ConfirmationOptions options;
  options.trials = 1000;
  options.seed = 1;
  options.threads = static_cast<int>(state.range(0));
  bool confirmed = false;
  for (auto _ : state) {
    const Confirmation c = confirmPlan(plan, options);
    confirmed = c.confirmed;
    benchmark::DoNotOptimize(c.parameters.data());
  }
  state.counters["confirmed"] = confirmed ? 1 : 0;
  state.counters["threads"] = static_cast<double>(options.threads);
}
BENCHMARK(BM_Confirm20Bars1000Trials)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

}  // namespace
}  // namespace artcal
