// Mechanism models: J_x_p and J_x_q against central differences (one battery for every model),
// and forward kinematics against values worked out by hand.

#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "artcal/artcal.hpp"
#include "finite_difference.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace mechanism_test {

using testing::centralDifferenceJacobian;
using testing::expectJacobianNear;

// Runs the battery on one model at parameters p over several random joint configurations.
void checkJacobians(const Mechanism& model, const Eigen::VectorXd& p,
                    const std::vector<Eigen::VectorXd>& configurations) {
  for (std::size_t c = 0; c < configurations.size(); ++c) {
    const Eigen::VectorXd& q = configurations[c];
    Eigen::VectorXd x;
    Eigen::MatrixXd J_x_p, J_x_q;
    forwardOrThrow(model, p, q, x, &J_x_p, &J_x_q);
    ASSERT_EQ(x.size(), model.dimension());
    const auto of_p = [&](const Eigen::VectorXd& pp) {
      Eigen::VectorXd y;
      forwardOrThrow(model, pp, q, y);
      return y;
    };
    const auto of_q = [&](const Eigen::VectorXd& qq) {
      Eigen::VectorXd y;
      forwardOrThrow(model, p, qq, y);
      return y;
    };
    const std::string where = model.modelName() + " configuration " + std::to_string(c);
    expectJacobianNear(J_x_p, centralDifferenceJacobian(of_p, p, 1e-6), 1e-7, where + " J_x_p");
    expectJacobianNear(J_x_q, centralDifferenceJacobian(of_q, q, 1e-6), 1e-7, where + " J_x_q");
    // The position does not depend on whether Jacobians were asked for.
    Eigen::VectorXd x_alone;
    forwardOrThrow(model, p, q, x_alone);
    EXPECT_EQ(x_alone, x);
  }
}

std::vector<Eigen::VectorXd> randomConfigurations(int joints, int count, std::uint64_t seed,
                                                  double range) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(-range, range);
  std::vector<Eigen::VectorXd> out;
  for (int c = 0; c < count; ++c) {
    Eigen::VectorXd q(joints);
    for (int i = 0; i < joints; ++i) q[i] = uniform(rng);
    out.push_back(q);
  }
  return out;
}

TEST(Planar2R, ForwardMatchesTheSeedEquation) {
  const Planar2R arm;
  Eigen::VectorXd x;
  forwardOrThrow(arm, Eigen::Vector3d(150, 100, degToRad(2.0)),
                 Eigen::Vector2d(degToRad(30), degToRad(60)), x);
  EXPECT_NEAR(x[0], 150 * std::cos(degToRad(30)) + 100 * std::cos(degToRad(92)), 1e-12);
  EXPECT_NEAR(x[1], 150 * std::sin(degToRad(30)) + 100 * std::sin(degToRad(92)), 1e-12);
}

TEST(Planar2R, JacobiansMatchFiniteDifferences) {
  const Planar2R arm;
  checkJacobians(arm, Eigen::Vector3d(150.0, 100.0, degToRad(0.7)),
                 randomConfigurations(2, 8, 1, std::numbers::pi));
}

// A serial arm with revolute and prismatic joints mixed and no zero DH value.
Eigen::VectorXd mixedArmParameters() {
  Eigen::VectorXd p(4 * 5 + 3);
  p << 0.1, 210.0, 12.0, 1.4,   //
      -0.2, 15.0, 310.0, -0.3,  //
      0.05, 40.0, 25.0, 1.2,    //
      0.3, -30.0, 5.0, -1.1,    //
      -0.4, 60.0, 18.0, 0.5,    //
      110.0, -20.0, 35.0;
  return p;
}

std::shared_ptr<SerialDH> mixedArm() {
  return std::make_shared<SerialDH>(
      std::vector<JointKind>{JointKind::Revolute, JointKind::Prismatic, JointKind::Revolute,
                             JointKind::Prismatic, JointKind::Revolute});
}

TEST(SerialDH, ParameterNamesAndOrder) {
  const auto arm = mixedArm();
  ASSERT_EQ(arm->parameterCount(), 23);
  EXPECT_EQ(arm->parameters()[0].name, "j1.theta");
  EXPECT_EQ(arm->parameters()[5].name, "j2.d");
  EXPECT_EQ(arm->parameters()[19].name, "j5.alpha");
  EXPECT_EQ(arm->parameters()[22].name, "probe.z");
  EXPECT_EQ(arm->parameters()[3].quantity, Quantity::Angle);
  EXPECT_EQ(arm->parameters()[6].quantity, Quantity::Length);
  EXPECT_EQ(arm->parameterIndex("j3.a"), 10);
  EXPECT_EQ(arm->parameterIndex("j9.a"), -1);
}

// x = Rz(t1) Tz(d1) Tx(a1) Rx(alpha1) ... probe, worked out with 4x4 matrices.
TEST(SerialDH, ForwardMatchesHomogeneousTransforms) {
  const auto arm = mixedArm();
  const Eigen::VectorXd p = mixedArmParameters();
  const Eigen::VectorXd q = randomConfigurations(5, 1, 9, 1.0)[0];
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  for (int i = 0; i < 5; ++i) {
    double theta = p[4 * i], d = p[4 * i + 1];
    (arm->jointKind(i) == JointKind::Revolute ? theta : d) += q[i];
    const double a = p[4 * i + 2], alpha = p[4 * i + 3];
    Eigen::Matrix4d A;
    A << std::cos(theta), -std::sin(theta) * std::cos(alpha), std::sin(theta) * std::sin(alpha),
        a * std::cos(theta),  //
        std::sin(theta), std::cos(theta) * std::cos(alpha), -std::cos(theta) * std::sin(alpha),
        a * std::sin(theta),                     //
        0, std::sin(alpha), std::cos(alpha), d,  //
        0, 0, 0, 1;
    T = T * A;
  }
  const Eigen::Vector4d tip = T * Eigen::Vector4d(p[20], p[21], p[22], 1.0);
  Eigen::VectorXd x;
  forwardOrThrow(*arm, p, q, x);
  EXPECT_LT((x - tip.head<3>()).norm(), 1e-10);
}

TEST(SerialDH, JacobiansMatchFiniteDifferencesMixedJoints) {
  const auto arm = mixedArm();
  checkJacobians(*arm, mixedArmParameters(), randomConfigurations(5, 8, 2, 2.5));
}

TEST(SerialDH, JacobiansMatchFiniteDifferencesSixAxisArm) {
  const Plan plan = loadPlan(test_support::testDataFile("ref-aacmm-3bars-3postures.json"));
  checkJacobians(*plan.machine.mechanism, plan.machine.nominal,
                 randomConfigurations(6, 8, 3, std::numbers::pi));
}

TEST(SerialDH, RefusesMoreJointsThanPlanFilesAllow) {
  EXPECT_THROW(SerialDH(std::vector<JointKind>(33, JointKind::Revolute)), std::invalid_argument);
  EXPECT_NO_THROW(SerialDH(std::vector<JointKind>(32, JointKind::Revolute)));
}

}  // namespace mechanism_test
}  // namespace artcal
