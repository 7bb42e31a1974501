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
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "artcal/io/model_registry.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/model/joint_compliance.hpp"
#include "artcal/model/rotation_vector.hpp"
#include "finite_difference.hpp"
#include "several_tips.hpp"
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
  for (int k = 0; k < count && !readings.empty(); ++k) {
    Eigen::VectorXd q = readings[static_cast<std::size_t>(rng() % readings.size())];
    for (int i = 0; i < q.size(); ++i) q[i] += 0.02 * (2.0 * unit(rng) - 1.0);
    if (mechanism.forward(machine.nominal, q, x) == ForwardStatus::Ok) out.push_back(q);
  }
  return out;
}

/// A model with orientation (instruments.md, "measures": "pose"): forwardPose gives forward()'s
/// point and Jacobians, its angular Jacobians match central differences of log(R(v) R0^T)
/// (the spatial turn), and the pose residual against a measured orientation far from R0 (so
/// that J_l^-1 is not the identity) has derivative J_e_w J_w_p, exactly.
void expectPoseJacobiansExact(const Mechanism& mechanism, const Eigen::VectorXd& p,
                              const Eigen::VectorXd& q, std::mt19937_64& rng) {
  const std::string where = mechanism.modelName() + " pose";
  Eigen::VectorXd x, x_pose;
  Eigen::MatrixXd J_x_p, J_x_q, Jp_pose, Jq_pose, J_w_p, J_w_q;
  Eigen::Matrix3d R0;
  ASSERT_EQ(mechanism.forward(p, q, x, &J_x_p, &J_x_q), ForwardStatus::Ok) << where;
  ASSERT_EQ(mechanism.forwardPose(p, q, x_pose, R0, &Jp_pose, &Jq_pose, &J_w_p, &J_w_q),
            ForwardStatus::Ok)
      << where;
  EXPECT_EQ((x_pose - x).norm(), 0.0) << where;
  EXPECT_EQ((Jp_pose - J_x_p).norm(), 0.0) << where;
  EXPECT_EQ((Jq_pose - J_x_q).norm(), 0.0) << where;
  EXPECT_LT((R0.transpose() * R0 - Eigen::Matrix3d::Identity()).norm(), 1e-12) << where;
  auto turn = [&](const Eigen::VectorXd& v, bool of_p) {
    Eigen::VectorXd y;
    Eigen::Matrix3d R;
    EXPECT_EQ(mechanism.forwardPose(of_p ? v : p, of_p ? q : v, y, R), ForwardStatus::Ok);
    return Eigen::VectorXd(rotationVector(R * R0.transpose()));
  };
  auto of_p = [&](const Eigen::VectorXd& v) { return turn(v, true); };
  auto of_q = [&](const Eigen::VectorXd& v) { return turn(v, false); };
  expectJacobianNear(J_w_p, centralDifferenceJacobian(of_p, p, 1e-5), 1e-6, where + " J_w_p");
  expectJacobianNear(J_w_q, centralDifferenceJacobian(of_q, q, 1e-5), 1e-6, where + " J_w_q");
  // Only the angular Jacobian asked for: the same columns.
  Eigen::MatrixXd J_w_alone;
  Eigen::Matrix3d R;
  ASSERT_EQ(mechanism.forwardPose(p, q, x, R, nullptr, nullptr, &J_w_alone), ForwardStatus::Ok);
  EXPECT_EQ((J_w_alone - J_w_p).norm(), 0.0) << where;
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::Vector3d measured = rotationVector(
      rotationFromVector(Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized() *
                         1.2) *
      R0);
  Eigen::Matrix3d J_e_w;
  orientationResidual(R0, measured, &J_e_w);
  auto residual_of_p = [&](const Eigen::VectorXd& v) {
    Eigen::VectorXd y;
    Eigen::Matrix3d Rv;
    EXPECT_EQ(mechanism.forwardPose(v, q, y, Rv), ForwardStatus::Ok);
    return Eigen::VectorXd(orientationResidual(Rv, measured));
  };
  expectJacobianNear(J_e_w * J_w_p, centralDifferenceJacobian(residual_of_p, p, 1e-5), 1e-6,
                     where + " d residual / dp");
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
      if (mechanism.hasOrientation() && stylus == 0) expectPoseJacobiansExact(mechanism, p, q, rng);
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

// Chains that run against the URDF tree (docs/urdf.md): the humanoid from its left sole to both
// grippers (seven reversed joints, then torso and arms; two tips, both checked, the pose of the
// first), and the small arm from its finger (a reversed prismatic joint, a reversed continuous
// joint with a gimbal-locked origin) up to the world and across to its probe.
// DISABLED: the test's plan builder left a placement without readings (IK from its starts
// failed; "expected at least 1 entries, got 0"): to be fixed in the builder, not the model.
// A chain block alone (no readings needed: configurations are drawn within the joint limits).
Plan machineOnlyPlan(const nlohmann::json& machine) {
  const nlohmann::json document = {
      {"format", "artcal-plan/1"},
      {"name", "machine-only"},
      {"machine", machine},
      {"noise", {{"probe", 0.02}, {"encoder", 0.002}}},
      {"artifacts", {{"bar", {{"type", "ball_bar"}, {"length", 100.0}}}}},
      {"placements", nlohmann::json::array()}};
  return parsePlan(document, "machine-only", false);
}

TEST(RegisteredModels, ChainsUpTheTreeAndWithSeveralTipsHaveExactJacobians) {
  std::mt19937_64 rng(22);
  const nlohmann::json humanoid =
      importUrdf(test_support::humanoidUrdf(), "left_sole_link",
                 std::vector<std::string>{"gripper_left_base_link", "gripper_right_base_link"});
  const Plan two_tips = machineOnlyPlan(humanoid);
  ASSERT_EQ(two_tips.machine.mechanism->stylusCount(), 2);
  expectJacobiansMatchDifferences(two_tips, rng);
  const std::string arm = test_support::testDataFile("urdf/arm3-slide.urdf");
  for (const char* tip : {"world", "probe"}) {
    SCOPED_TRACE(tip);
    expectJacobiansMatchDifferences(machineOnlyPlan(importUrdf(arm, "finger", tip)), rng);
  }
}

}  // namespace registry_jacobians_test
}  // namespace artcal

namespace artcal {
namespace registry_jacobians_test {

// Joint compliance (docs/compliance.md section 3) through the battery: every serial family with a
// compliance block (standard and modified DH with beta, URDF chains straight, up the tree and
// with an off-chain mimic master), at compliances of 1e-4 rad/(N m) and their readings'
// gravity torques with a payload, and at arbitrary torques: the deflected forward kinematics'
// J_x_p and J_w_p (the compliance columns (dx/dq_r) tau_r) against central differences over
// every parameter, torques held fixed.
nlohmann::json withMasses(nlohmann::json machine) {
  nlohmann::json masses = nlohmann::json::object();
  double m = 1.0;
  for (const nlohmann::json& joint : machine.at("joints")) {
    masses[joint.at("name").get<std::string>()] = {{"mass", m},
                                                   {"centre", {30.0 * m, -10.0, 20.0}}};
    m += 0.5;
  }
  machine["compliance"] = {{"masses", masses}, {"gravity", {0.5, -1.0, -9.7}}};
  return machine;
}

nlohmann::json dhWithCompliance(const char* convention) {
  std::ifstream in(test_support::testDataFile("ur5-tracker/ur5-compliance.machine.json"));
  nlohmann::json machine = nlohmann::json::parse(in);
  machine["convention"] = convention;
  machine["joints"][2]["beta"] = 0.5;
  machine["probe"] = {60.0, 20.0, 40.0};
  return machine;
}

void expectComplianceColumnsExact(const Plan& plan, std::mt19937_64& rng) {
  const Machine& machine = plan.machine;
  const Mechanism& mech = *machine.mechanism;
  const JointCompliance* compliance = mech.jointCompliance();
  ASSERT_NE(compliance, nullptr) << mech.modelName();
  Eigen::VectorXd p = machine.nominal;
  for (const int c : compliance->complianceParameters()) p[c] = 1e-4 * (1.0 + 0.1 * c);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const std::vector<Eigen::VectorXd> configurations = randomConfigurations(plan, 3, rng);
  ASSERT_GE(configurations.size(), 3u);
  for (std::size_t c = 0; c < configurations.size(); ++c) {
    Measurement m;
    m.joints = configurations[c];
    m.payload = {3.0, Eigen::Vector3d(20.0, -30.0, 50.0)};
    Eigen::VectorXd arbitrary(m.joints.size());
    for (int r = 0; r < arbitrary.size(); ++r) arbitrary[r] = 40.0 * unit(rng);
    for (const Eigen::VectorXd& tau : {readingTorques(machine, m), arbitrary}) {
      const std::string where = mech.modelName() + " configuration " + std::to_string(c);
      ASSERT_GT(tau.cwiseAbs().maxCoeff(), 0.1) << where;
      Eigen::VectorXd x;
      Eigen::Matrix3d R0;
      Eigen::MatrixXd J_x_p, J_x_q, J_w_p, J_w_q;
      ASSERT_EQ(forwardLoadedPose(mech, 0, p, m.joints, tau, x, R0, &J_x_p, &J_x_q, &J_w_p, &J_w_q),
                ForwardStatus::Ok);
      auto of_p = [&](const Eigen::VectorXd& v) {
        Eigen::VectorXd y;
        EXPECT_EQ(forwardLoaded(mech, 0, v, m.joints, tau, y), ForwardStatus::Ok);
        return y;
      };
      auto turn_of_p = [&](const Eigen::VectorXd& v) {
        Eigen::VectorXd y;
        Eigen::Matrix3d R;
        EXPECT_EQ(forwardLoadedPose(mech, 0, v, m.joints, tau, y, R), ForwardStatus::Ok);
        return Eigen::VectorXd(rotationVector(R * R0.transpose()));
      };
      expectJacobianNear(J_x_p, centralDifferenceJacobian(of_p, p, 1e-6), 1e-6, where + " J_x_p");
      expectJacobianNear(J_w_p, centralDifferenceJacobian(turn_of_p, p, 1e-6), 1e-6,
                         where + " J_w_p");
      Eigen::VectorXd x_plain;
      Eigen::MatrixXd J_plain;
      ASSERT_EQ(forwardLoaded(mech, 0, p, m.joints, tau, x_plain, &J_plain), ForwardStatus::Ok);
      EXPECT_EQ((J_plain - J_x_p).norm(), 0.0) << where;
    }
  }
}

TEST(RegisteredModels, EverySerialFamilyWithComplianceHasExactComplianceColumns) {
  std::mt19937_64 rng(47);
  std::set<std::string> covered;
  std::vector<Plan> plans;
  plans.push_back(machineOnlyPlan(dhWithCompliance("standard")));
  plans.push_back(machineOnlyPlan(dhWithCompliance("modified")));
  plans.push_back(machineOnlyPlan(importUrdfWithCompliance(
      test_support::testDataFile("urdf/arm3-masses.urdf"), "base_link", {"tool"})));
  plans.push_back(machineOnlyPlan(withMasses(
      importUrdf(test_support::testDataFile("urdf/arm3-slide.urdf"), "finger", "world"))));
  plans.push_back(machineOnlyPlan(withMasses(importUrdf(
      test_support::testDataFile("urdf/lifting-column-arm6.urdf"), "base_link", "prism_link"))));
  for (const Plan& plan : plans) {
    SCOPED_TRACE(plan.machine.mechanism->modelName());
    expectComplianceColumnsExact(plan, rng);
    covered.insert(plan.machine.mechanism->modelName());
  }
  EXPECT_EQ(covered, (std::set<std::string>{"chain", "serial-dh"}));
}

}  // namespace registry_jacobians_test
}  // namespace artcal
