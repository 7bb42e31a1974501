// The finite-difference battery over EVERY registered model (issue 20): the test iterates the
// model registry (io/model_registry.hpp), finds for each family a plan with readings among
// plans/ and tests/data, and checks J_x_p and J_x_q of the forward kinematics, through every
// stylus, against central differences at random configurations (seeded): uniform within the
// joint limits where the forward kinematics succeeds there, and the plan's readings moved by a
// random step. A new family that ships no plan, or whose Jacobians are wrong, fails here. A
// chain with mimic joints is checked besides (its plan is not the first chain plan).

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "artcal/io/model_registry.hpp"
#include "artcal/io/plan_io.hpp"
#include "finite_difference.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace registry_jacobians_test {

namespace fs = std::filesystem;
using testing::centralDifferenceJacobian;
using testing::expectJacobianNear;

/// The first plan with readings of each model, by model name, from plans/ and tests/data.
std::map<std::string, Plan> onePlanPerModel() {
  std::vector<fs::path> files;
  for (const char* folder : {ARTCAL_PLANS_DIR, ARTCAL_TEST_DATA}) {
    for (const auto& entry : fs::directory_iterator(folder)) {
      if (entry.path().extension() == ".json") files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  std::map<std::string, Plan> out;
  for (const fs::path& file : files) {
    try {
      Plan plan = loadPlan(file.string());
      if (plan.placements.empty() || plan.placements.front().measurements.empty()) continue;
      out.try_emplace(plan.machine.mechanism->modelName(), std::move(plan));
    } catch (const std::exception&) {
      // Not a plan with readings (a spec, a machine file, a deliberately broken input).
    }
  }
  return out;
}

/// Configurations to test: `count` uniform within the joint limits at which the forward
/// kinematics succeeds (up to 20 tries each), then `count` readings of the plan moved by a
/// uniform step of up to 0.02 (rad or mm) per joint.
std::vector<Eigen::VectorXd> randomConfigurations(const Plan& plan, int count,
                                                  std::mt19937_64& rng) {
  const Machine& machine = plan.machine;
  const Mechanism& mechanism = *machine.mechanism;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::VectorXd> out;
  Eigen::VectorXd x;
  for (int tries = 0; tries < 20 * count && static_cast<int>(out.size()) < count; ++tries) {
    Eigen::VectorXd q(machine.jointCount());
    for (int i = 0; i < q.size(); ++i) {
      const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
      q[i] = lo + (hi - lo) * unit(rng);
    }
    if (mechanism.forward(machine.nominal, q, x) == ForwardStatus::Ok) out.push_back(q);
  }
  std::vector<Eigen::VectorXd> readings;
  for (const Placement& placement : plan.placements)
    for (const Measurement& m : placement.measurements) readings.push_back(m.joints);
  for (int k = 0; k < count; ++k) {
    Eigen::VectorXd q = readings[static_cast<std::size_t>(rng() % readings.size())];
    for (int i = 0; i < q.size(); ++i) q[i] += 0.02 * (2.0 * unit(rng) - 1.0);
    if (mechanism.forward(machine.nominal, q, x) == ForwardStatus::Ok) out.push_back(q);
  }
  return out;
}

void expectJacobiansMatchDifferences(const Plan& plan, std::mt19937_64& rng) {
  const Machine& machine = plan.machine;
  const Mechanism& mechanism = *machine.mechanism;
  const std::vector<Eigen::VectorXd> configurations = randomConfigurations(plan, 4, rng);
  ASSERT_GE(configurations.size(), 4u) << mechanism.modelName();
  for (int stylus = 0; stylus < mechanism.stylusCount(); ++stylus) {
    for (std::size_t c = 0; c < configurations.size(); ++c) {
      const Eigen::VectorXd& q = configurations[c];
      const Eigen::VectorXd& p = machine.nominal;
      const std::string where = mechanism.modelName() + " stylus " + std::to_string(stylus) +
                                " configuration " + std::to_string(c);
      Eigen::VectorXd x;
      Eigen::MatrixXd J_x_p, J_x_q;
      ASSERT_EQ(mechanism.forwardStylus(stylus, p, q, x, &J_x_p, &J_x_q), ForwardStatus::Ok)
          << where;
      auto of_p = [&](const Eigen::VectorXd& v) {
        Eigen::VectorXd y;
        EXPECT_EQ(mechanism.forwardStylus(stylus, v, q, y), ForwardStatus::Ok) << where;
        return y;
      };
      auto of_q = [&](const Eigen::VectorXd& v) {
        Eigen::VectorXd y;
        EXPECT_EQ(mechanism.forwardStylus(stylus, p, v, y), ForwardStatus::Ok) << where;
        return y;
      };
      ASSERT_EQ(J_x_p.cols(), mechanism.parameterCount()) << where;
      ASSERT_EQ(J_x_q.cols(), mechanism.jointCount()) << where;
      expectJacobianNear(J_x_p, centralDifferenceJacobian(of_p, p, 1e-4), 1e-6, where + " J_x_p");
      expectJacobianNear(J_x_q, centralDifferenceJacobian(of_q, q, 1e-4), 1e-6, where + " J_x_q");
    }
  }
}

TEST(RegisteredModels, EveryFamilyHasAPlanAndExactJacobians) {
  const std::map<std::string, Plan> plans = onePlanPerModel();
  std::mt19937_64 rng(20);
  ASSERT_GE(modelCodecs().size(), 5u);
  for (const ModelCodec& codec : modelCodecs()) {
    SCOPED_TRACE(codec.name);
    const auto it = plans.find(codec.name);
    ASSERT_NE(it, plans.end()) << "no plan with readings of model " << codec.name
                               << " in plans/ or tests/data: add one";
    expectJacobiansMatchDifferences(it->second, rng);
  }
}

// A chain with mimic joints (a lifting column off the chain driving two coupled segments,
// instruments.md): J_x_q of the column's reading sums both segments' columns times 0.5.
TEST(RegisteredModels, AMimicChainHasExactJacobians) {
  const Plan plan = loadPlan(test_support::testDataFile("lifting-column-tracker.json"));
  ASSERT_EQ(plan.machine.mechanism->modelName(), "chain");
  ASSERT_EQ(plan.machine.jointCount(), 7);
  std::mt19937_64 rng(21);
  expectJacobiansMatchDifferences(plan, rng);
}

}  // namespace
}  // namespace artcal
