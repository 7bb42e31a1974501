// Joint compliance (docs/compliance.md): the gravity torques of the serial families against an
// independent static recursive Newton-Euler pass written here from the spec's definitions (the
// UR5's standard DH with Universal Robots' published masses and centres, and a payload), a
// prismatic joint's force, a mimic's torque by virtual work, the parameter names and units, and
// the deflected forward kinematics (q + C tau) with its compliance columns.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "artcal/model/chain.hpp"
#include "artcal/model/joint_compliance.hpp"
#include "artcal/model/serial_dh.hpp"
#include "finite_difference.hpp"

namespace artcal {
namespace compliance_test {

using testing::centralDifferenceJacobian;
using testing::expectJacobianNear;

// The UR5 (Universal Robots, "DH parameters for calculations of kinematics and dynamics"): d, a
// (m), alpha (rad), masses (kg) and centres of mass in the DH link frames (m).
constexpr double kD[6] = {0.089159, 0, 0, 0.10915, 0.09465, 0.0823};
constexpr double kA[6] = {0, -0.425, -0.39225, 0, 0, 0};
constexpr double kAlpha[6] = {std::numbers::pi / 2,  0, 0, std::numbers::pi / 2,
                              -std::numbers::pi / 2, 0};
constexpr double kMass[6] = {3.7, 8.393, 2.33, 1.219, 1.219, 0.1879};
const double kCentre[6][3] = {{0, -0.02561, 0.00193}, {0.2125, 0, 0.11336}, {0.15, 0, 0.0265},
                              {0, -0.0018, 0.01634},  {0, 0.0018, 0.01634}, {0, 0, -0.001159}};

SerialDH ur5(const Eigen::Vector3d& gravity) {
  ComplianceSpec spec;
  spec.gravity = gravity;
  for (int i = 0; i < 6; ++i)
    spec.masses.push_back(
        {kMass[i], 1000.0 * Eigen::Vector3d(kCentre[i][0], kCentre[i][1], kCentre[i][2])});
  return SerialDH(std::vector<DHJoint>(6, DHJoint{}), DHConvention::Standard, spec);
}

Eigen::VectorXd ur5Nominal() {
  Eigen::VectorXd p = Eigen::VectorXd::Zero(4 * 6 + 3 + 6);
  for (int i = 0; i < 6; ++i) {
    p[4 * i + 1] = 1000.0 * kD[i];
    p[4 * i + 2] = 1000.0 * kA[i];
    p[4 * i + 3] = kAlpha[i];
  }
  return p;  // probe at the flange, compliances 0
}

// A standard DH transform written out (metres).
Eigen::Matrix4d dhMatrix(double theta, double d, double a, double alpha) {
  const double ct = std::cos(theta), st = std::sin(theta), ca = std::cos(alpha),
               sa = std::sin(alpha);
  Eigen::Matrix4d T;
  T << ct, -st * ca, st * sa, a * ct,  //
      st, ct * ca, -ct * sa, a * st,   //
      0, sa, ca, d,                    //
      0, 0, 0, 1;
  return T;
}

// Static recursive Newton-Euler from the tip down: f_i = f_{i+1} - m_i g is the force link i-1
// exerts on link i at joint i's point P_i, n_i = n_{i+1} + (P_{i+1} - P_i) x f_{i+1} -
// (r_i - P_i) x m_i g its moment about P_i. Gravity's torque about +z_{i-1} is -n_i . z_{i-1}.
Eigen::VectorXd newtonEulerTorques(const Eigen::VectorXd& q, const Eigen::Vector3d& g,
                                   double payload_mass, const Eigen::Vector3d& payload_centre_m) {
  std::vector<Eigen::Matrix4d> F{Eigen::Matrix4d::Identity()};
  for (int i = 0; i < 6; ++i) F.push_back(F.back() * dhMatrix(q[i], kD[i], kA[i], kAlpha[i]));
  std::vector<Eigen::Vector3d> r(6);
  std::vector<double> m(kMass, kMass + 6);
  for (int i = 0; i < 6; ++i)
    r[i] = (F[i + 1] * Eigen::Vector4d(kCentre[i][0], kCentre[i][1], kCentre[i][2], 1)).head<3>();
  // The payload joins link 6: one body at the combined centre.
  const Eigen::Vector3d rp = (F[6] * payload_centre_m.homogeneous()).head<3>();
  r[5] = (m[5] * r[5] + payload_mass * rp) / (m[5] + payload_mass);
  m[5] += payload_mass;
  Eigen::VectorXd tau(6);
  Eigen::Vector3d f = Eigen::Vector3d::Zero(), n = Eigen::Vector3d::Zero();
  Eigen::Vector3d P_next = Eigen::Vector3d::Zero();
  for (int i = 5; i >= 0; --i) {
    const Eigen::Vector3d P = F[i].block<3, 1>(0, 3), z = F[i].block<3, 1>(0, 2);
    const Eigen::Vector3d f_i = f - m[i] * g;
    n = n + (P_next - P).cross(f) - (r[i] - P).cross(m[i] * g);
    f = f_i;
    P_next = P;
    tau[i] = -n.dot(z);
  }
  return tau;
}

TEST(Compliance, Ur5GravityTorquesMatchAStaticNewtonEulerPass) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  for (const Eigen::Vector3d& g :
       {Eigen::Vector3d(0, 0, -9.81), Eigen::Vector3d(1.2, -3.0, -9.2)}) {
    const SerialDH arm = ur5(g);
    const Eigen::VectorXd p = ur5Nominal();
    for (int trial = 0; trial < 20; ++trial) {
      Eigen::VectorXd q(6);
      for (int i = 0; i < 6; ++i) q[i] = angle(rng);
      const Payload payload{trial % 2 ? 5.0 : 0.0, Eigen::Vector3d(10.0, -20.0, 60.0)};
      const Eigen::VectorXd tau = arm.gravityTorques(p, q, payload);
      const Eigen::VectorXd expected =
          newtonEulerTorques(q, g, payload.mass, payload.centre / 1000.0);
      ASSERT_EQ(tau.size(), 6);
      EXPECT_GT(expected.cwiseAbs().maxCoeff(), 1.0);  // N m: not a vacuous comparison
      for (int i = 0; i < 6; ++i)
        EXPECT_NEAR(tau[i], expected[i], 1e-10 * expected.cwiseAbs().maxCoeff())
            << "joint " << i + 1 << " trial " << trial;
    }
  }
}

TEST(Compliance, VerticalFirstAxisCarriesNoGravityTorque) {
  const SerialDH arm = ur5(kDefaultGravity);
  Eigen::VectorXd q(6);
  q << 0.3, -1.0, 1.4, -0.5, 0.9, 0.2;
  EXPECT_NEAR(arm.gravityTorques(ur5Nominal(), q, {})[0], 0.0, 1e-12);
}

// A prismatic joint's force is the weight beyond it along its axis (N), payload included; the
// names and units of the block.
TEST(Compliance, PrismaticJointsFeelTheWeightAlongTheirAxis) {
  ComplianceSpec spec;
  spec.masses = {{2.0, Eigen::Vector3d(0, 0, 0)}, {3.0, Eigen::Vector3d(0, 0, 0)}};
  spec.gravity = Eigen::Vector3d(0, 0, -9.81);
  // A vertical lift (prismatic along z) carrying a revolute joint about x.
  const SerialDH arm({{JointKind::Prismatic, false}, {JointKind::Revolute, false}},
                     DHConvention::Standard, spec);
  Eigen::VectorXd p = Eigen::VectorXd::Zero(arm.parameterCount());
  p[3] = std::numbers::pi / 2;  // j1.alpha: joint 2's axis horizontal
  p[6] = 100.0;                 // j2.a
  Eigen::VectorXd q(2);
  q << 50.0, 0.4;
  const Payload payload{1.5, Eigen::Vector3d(20.0, 0, 0)};
  const Eigen::VectorXd tau = arm.gravityTorques(p, q, payload);
  EXPECT_NEAR(tau[0], -(2.0 + 3.0 + 1.5) * 9.81, 1e-12);  // N, along +z
  EXPECT_EQ(arm.parameters()[static_cast<std::size_t>(arm.parameterCount() - 2)].name,
            "j1.compliance");
  EXPECT_EQ(arm.parameters().back().name, "j2.compliance");
  EXPECT_EQ(arm.parameters().back().quantity.unit, "deg/(N m)");
  EXPECT_EQ(arm.parameters()[static_cast<std::size_t>(arm.parameterCount() - 2)].quantity.unit,
            "mm/N");
}

// A mimic's torque reaches its master's reading times its multiplier (virtual work): the chain
// with the mimic equals the chain with that joint read on its own, at the same joint values.
TEST(Compliance, AMimicAddsItsTorqueTimesItsMultiplier) {
  auto joints = [](bool mimic) {
    std::vector<ChainJoint> out{{"a", ChainJointType::Revolute, Eigen::Vector3d::UnitZ()},
                                {"b", ChainJointType::Revolute, Eigen::Vector3d::UnitY()},
                                {"c", ChainJointType::Revolute, Eigen::Vector3d::UnitY()}};
    if (mimic) out[2].mimic = ChainMimic{"b", -0.7, 0.1};
    return out;
  };
  ComplianceSpec spec;
  spec.masses = {{1.0, Eigen::Vector3d(10, 0, 50)},
                 {2.0, Eigen::Vector3d(150, 5, 0)},
                 {1.5, Eigen::Vector3d(120, 0, 10)}};
  const Chain coupled(joints(true), {}, spec), free(joints(false), {}, spec);
  Eigen::VectorXd p = Eigen::VectorXd::Zero(coupled.parameterCount());
  p[7 + 0] = 200.0;   // b.x
  p[14 + 0] = 300.0;  // c.x
  Eigen::VectorXd p_free = Eigen::VectorXd::Zero(free.parameterCount());
  p_free.head(21) = p.head(21);
  Eigen::VectorXd q(2), q_free(3);
  q << 0.3, 0.5;
  q_free << 0.3, 0.5, -0.7 * 0.5 + 0.1;
  const Eigen::VectorXd tau = coupled.gravityTorques(p, q, {});
  const Eigen::VectorXd own = free.gravityTorques(p_free, q_free, {});
  ASSERT_EQ(tau.size(), 2);
  EXPECT_GT(std::abs(own[2]), 0.5);
  EXPECT_NEAR(tau[1], own[1] - 0.7 * own[2], 1e-12);
  EXPECT_NEAR(tau[0], own[0], 1e-12);
  EXPECT_EQ(coupled.parameters().back().name, "b.compliance");
}

// x = f(p, q + C tau), d x / d C_r = (d x / d q_r) tau_r, against central differences with tau
// held fixed, position and orientation.
TEST(Compliance, DeflectedForwardKinematicsAndItsColumns) {
  const SerialDH arm = ur5(kDefaultGravity);
  Eigen::VectorXd p = ur5Nominal();
  p.tail(6) << 1e-3, 5e-3, 3e-3, 2e-3, 4e-3, 6e-3;  // rad/(N m)
  Eigen::VectorXd q(6);
  q << 0.3, -1.0, 1.4, -0.5, 0.9, 0.2;
  const Eigen::VectorXd tau = arm.gravityTorques(ur5Nominal(), q, {2.0, Eigen::Vector3d(0, 0, 50)});
  Eigen::VectorXd x, x_plain;
  Eigen::MatrixXd J_x_p, J_x_q;
  ASSERT_EQ(forwardLoaded(arm, 0, p, q, tau, x, &J_x_p, &J_x_q), ForwardStatus::Ok);
  Eigen::VectorXd deflected = q;
  for (int i = 0; i < 6; ++i) deflected[i] += p[27 + i] * tau[i];
  ASSERT_EQ(arm.forward(p, deflected, x_plain), ForwardStatus::Ok);
  EXPECT_LT((x - x_plain).norm(), 1e-12);
  auto of_p = [&](const Eigen::VectorXd& v) {
    Eigen::VectorXd y;
    EXPECT_EQ(forwardLoaded(arm, 0, v, q, tau, y), ForwardStatus::Ok);
    return y;
  };
  expectJacobianNear(J_x_p, centralDifferenceJacobian(of_p, p, 1e-6), 1e-6, "J_x_p");
  // Without torques: the geometric model, its compliance columns zero.
  ASSERT_EQ(arm.forward(p, q, x, &J_x_p), ForwardStatus::Ok);
  EXPECT_EQ(J_x_p.rightCols(6).norm(), 0.0);
}

}  // namespace compliance_test
}  // namespace artcal
