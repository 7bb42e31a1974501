// The hexapod (models.md section 3): forward kinematics with both Jacobians per reading (Newton
// from home, then the implicit function theorem), and one prepared evaluation of a 30-placement,
// 3-posture plan over a 10,000-sample task-space workspace (models.md section 5).
//
//   build/tests/bench/bench_hexapod --benchmark_filter=ForwardWithJacobians   target <= 5 us
//   build/tests/bench/bench_hexapod --benchmark_filter=Evaluate30Placements   target <= 5 ms

#include <benchmark/benchmark.h>

#include "artcal/internal.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace {

Plan hexapodSpec() {
  return loadPlan(test_support::planFile("hexapod-10bars.spec.json"), false);
}

void ForwardWithJacobians(benchmark::State& state) {
  const Plan plan = loadPlan(test_support::planFile("hexapod-10bars.json"));
  std::vector<Eigen::VectorXd> readings;
  for (const Placement& placement : plan.placements)
    for (const Measurement& m : placement.measurements) readings.push_back(m.joints);
  const Mechanism& mech = *plan.machine.mechanism;
  Eigen::VectorXd x;
  Eigen::MatrixXd J_x_p, J_x_q;
  std::size_t k = 0;
  for (auto _ : state) {
    const ForwardStatus status = mech.forward(plan.machine.nominal, readings[k], x, &J_x_p, &J_x_q);
    if (status != ForwardStatus::Ok) {
      state.SkipWithError("forward kinematics failed");
      return;
    }
    benchmark::DoNotOptimize(J_x_p.data());
    k = (k + 1) % readings.size();
  }
  state.counters["readings"] = static_cast<double>(readings.size());
}
BENCHMARK(ForwardWithJacobians)->Unit(benchmark::kMicrosecond);

void Evaluate30Placements(benchmark::State& state) {
  Plan plan = hexapodSpec();
  plan.design->placements = 30;
  const DesignSpace space(plan);
  std::mt19937_64 rng(5);
  std::vector<Placement> placements;
  while (placements.size() < 30) {
    if (auto candidate = space.randomPlacement(rng, 100)) placements.push_back(candidate->second);
  }
  WorkspaceSpec workspace = plan.workspace;
  workspace.samples = 10'000;
  PlanEvaluator evaluator(plan, workspaceConfigurations(plan.machine, workspace));
  const std::vector<RigidTransform> poses = fitPlacements(plan, placements, plan.machine.nominal);
  double worst = 0.0;
  for (auto _ : state) {
    const auto tip = evaluator.tip(placements, &poses);
    if (!tip) {
      state.SkipWithError("plan not identifiable");
      return;
    }
    worst = tip->worst.total;
  }
  state.counters["worst_tip_mm"] = worst;
  state.counters["configurations"] = evaluator.workspace().size();
  state.counters["parameters"] = plan.machine.calibratedCount();
}
BENCHMARK(Evaluate30Placements)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace artcal
