// The serial chain with URDF semantics (models.md section 1) and serial-dh with Hayati beta and
// the modified convention (models.md section 2): forward kinematics against homogeneous
// transforms written out independently (the Franka Panda as a URDF chain and as Craig's modified
// DH table), exact Jacobians through the finite-difference battery, parameter names.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>
#include <random>

#include "artcal/model/chain.hpp"
#include "artcal/model/inverse_kinematics.hpp"
#include "artcal/model/serial_dh.hpp"
#include "finite_difference.hpp"
#include "random_vectors.hpp"

namespace artcal {
namespace chain_test {

using testing::centralDifferenceJacobian;
using testing::expectJacobianNear;

constexpr double kPi = std::numbers::pi;

using test_support::randomVector;

// The battery every model goes through (as tests/model/test_mechanism.cpp does).
void checkJacobians(const Mechanism& model, const Eigen::VectorXd& p, int configurations,
                    std::uint64_t seed) {
  for (int c = 0; c < configurations; ++c) {
    const Eigen::VectorXd q = randomVector(model.jointCount(), seed + c, kPi);
    Eigen::VectorXd x;
    Eigen::MatrixXd J_x_p, J_x_q;
    ASSERT_EQ(model.forward(p, q, x, &J_x_p, &J_x_q), ForwardStatus::Ok);
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
    Eigen::VectorXd x_alone;
    forwardOrThrow(model, p, q, x_alone);
    EXPECT_EQ(x_alone, x);
  }
}

Eigen::Matrix4d translation(const Eigen::Vector3d& v) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.block<3, 1>(0, 3) = v;
  return T;
}

Eigen::Matrix4d rotation(const Eigen::Vector3d& axis, double angle) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.block<3, 3>(0, 0) = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  return T;
}

Eigen::Matrix4d rotX(double a) {
  return rotation(Eigen::Vector3d::UnitX(), a);
}
Eigen::Matrix4d rotY(double a) {
  return rotation(Eigen::Vector3d::UnitY(), a);
}
Eigen::Matrix4d rotZ(double a) {
  return rotation(Eigen::Vector3d::UnitZ(), a);
}

// ---- the Franka Panda, panda_link0 -> ball_link (tests/data/ref-chain-panda-2placements.json)

struct Origin {
  Eigen::Vector3d xyz_mm;
  Eigen::Vector3d rpy_deg;
};

const std::vector<Origin>& pandaOrigins() {
  static const std::vector<Origin> origins = {
      {{0, 0, 333}, {0, 0, 0}},
      {{0, 0, 0}, {-90, 0, 0}},
      {{0, -316, 0}, {90, 0, 0}},
      {{82.5, 0, 0}, {90, 0, 0}},
      {{-82.5, 384, 0}, {-90, 0, 0}},
      {{0, 0, 0}, {90, 0, 0}},
      {{88, 0, 0}, {90, 0, 0}},
      {{0, 0, 107}, {0, 0, 0}},
      {{0, 0, 0}, {0, 0, -45}},
      {{0, 0, 103.4}, {0, 0, 0}},
      {{0.07773732, -0.042140225, 30.128297908}, {0, 0, 0}}};
  return origins;
}

Chain pandaChain() {
  std::vector<ChainJoint> joints;
  const char* names[] = {"panda_joint1",     "panda_joint2",         "panda_joint3", "panda_joint4",
                         "panda_joint5",     "panda_joint6",         "panda_joint7", "panda_joint8",
                         "panda_hand_joint", "panda_hand_tcp_joint", "ball_joint"};
  for (int i = 0; i < 11; ++i) {
    joints.push_back({names[i], i < 7 ? ChainJointType::Revolute : ChainJointType::Fixed,
                      Eigen::Vector3d::UnitZ()});
  }
  return Chain(joints);
}

Eigen::VectorXd pandaNominal(const Chain& chain) {
  Eigen::VectorXd p = Eigen::VectorXd::Zero(chain.parameterCount());
  for (int i = 0; i < 11; ++i) {
    const int k = chain.parameterOffset(i);
    p.segment<3>(k) = pandaOrigins()[i].xyz_mm;
    p.segment<3>(k + 3) = pandaOrigins()[i].rpy_deg * (kPi / 180.0);
  }
  return p;
}

// Craig's modified DH table of the Panda (Franka's documentation), mm and rad: a, d, alpha.
struct CraigRow {
  double a, d, alpha;
};
const CraigRow kPandaCraig[7] = {{0, 333, 0},        {0, 0, -kPi / 2},       {0, 316, kPi / 2},
                                 {82.5, 0, kPi / 2}, {-82.5, 384, -kPi / 2}, {0, 0, kPi / 2},
                                 {88, 0, kPi / 2}};

// The ball centre in the frame of joint 7: flange 107 mm, hand turned -45 deg, TCP 103.4 mm,
// then the ball's offset.
Eigen::Vector3d pandaBallInFrame7() {
  const Eigen::Vector3d ball(0.07773732, -0.042140225, 30.128297908);
  return Eigen::Vector3d(0, 0, 107) + Eigen::AngleAxisd(-kPi / 4, Eigen::Vector3d::UnitZ()) *
                                          (Eigen::Vector3d(0, 0, 103.4) + ball);
}

Eigen::Vector3d pandaByCraigTable(const Eigen::VectorXd& q) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  for (int i = 0; i < 7; ++i) {
    const CraigRow& r = kPandaCraig[i];
    T = T * rotX(r.alpha) * translation({r.a, 0, 0}) * rotZ(q[i]) * translation({0, 0, r.d});
  }
  return (T * pandaBallInFrame7().homogeneous()).head<3>();
}

TEST(Chain, PandaForwardEqualsCraigsModifiedDHTable) {
  const Chain chain = pandaChain();
  const Eigen::VectorXd p = pandaNominal(chain);
  ASSERT_EQ(chain.jointCount(), 7);
  ASSERT_EQ(chain.parameterCount(), 11 * 6 + 7);  // 73, as the issue counts
  for (int c = 0; c < 6; ++c) {
    const Eigen::VectorXd q = randomVector(7, 40 + c, kPi);
    Eigen::VectorXd x;
    forwardOrThrow(chain, p, q, x);
    EXPECT_LT((x - pandaByCraigTable(q)).norm(), 1e-9) << "configuration " << c;
  }
}

TEST(SerialDH, ModifiedConventionPandaEqualsCraigsTable) {
  std::vector<DHJoint> joints(7, DHJoint{JointKind::Revolute, false});
  const SerialDH arm(joints, DHConvention::Modified);
  Eigen::VectorXd p(4 * 7 + 3);
  for (int i = 0; i < 7; ++i) {
    p.segment<4>(4 * i) << 0.0, kPandaCraig[i].d, kPandaCraig[i].a, kPandaCraig[i].alpha;
  }
  p.tail<3>() = pandaBallInFrame7();
  // The chain (URDF) model of the same robot: an independent route to the same point.
  const Chain chain = pandaChain();
  const Eigen::VectorXd p_chain = pandaNominal(chain);
  for (int c = 0; c < 6; ++c) {
    const Eigen::VectorXd q = randomVector(7, 60 + c, kPi);
    Eigen::VectorXd x, x_chain;
    forwardOrThrow(arm, p, q, x);
    forwardOrThrow(chain, p_chain, q, x_chain);
    EXPECT_LT((x - pandaByCraigTable(q)).norm(), 1e-9);
    EXPECT_LT((x - x_chain).norm(), 1e-9);
  }
}

TEST(Chain, ParameterNamesOrderAndUnits) {
  const Chain chain({{"base", ChainJointType::Fixed, {}},
                     {"slide", ChainJointType::Prismatic, {1, 0, 0}},
                     {"turn", ChainJointType::Revolute, {0, 0, 1}}});
  ASSERT_EQ(chain.parameterCount(), 6 + 7 + 7);
  EXPECT_EQ(chain.jointCount(), 2);
  EXPECT_EQ(chain.jointKind(0), JointKind::Prismatic);
  EXPECT_EQ(chain.jointKind(1), JointKind::Revolute);
  const char* expected[] = {"base.x",      "base.y",    "base.z",       "base.roll", "base.pitch",
                            "base.yaw",    "slide.x",   "slide.y",      "slide.z",   "slide.roll",
                            "slide.pitch", "slide.yaw", "slide.offset", "turn.x",    "turn.y",
                            "turn.z",      "turn.roll", "turn.pitch",   "turn.yaw",  "turn.offset"};
  for (int i = 0; i < chain.parameterCount(); ++i) {
    EXPECT_EQ(chain.parameters()[i].name, expected[i]);
  }
  EXPECT_EQ(chain.parameters()[12].quantity, Quantity::Length);  // prismatic offset, mm
  EXPECT_EQ(chain.parameters()[19].quantity, Quantity::Angle);   // revolute offset
  EXPECT_EQ(chain.parameters()[3].quantity, Quantity::Angle);
  EXPECT_EQ(chain.parameterOffset(2), 13);
}

TEST(Chain, RefusesMalformedChains) {
  EXPECT_THROW(Chain({}), std::invalid_argument);
  EXPECT_THROW(Chain({{"a", ChainJointType::Revolute, Eigen::Vector3d::Zero()}}),
               std::invalid_argument);
  EXPECT_THROW(Chain({{"a", ChainJointType::Fixed, {}}, {"a", ChainJointType::Fixed, {}}}),
               std::invalid_argument);
  EXPECT_THROW(Chain({{"", ChainJointType::Fixed, {}}}), std::invalid_argument);
  std::vector<ChainJoint> many;
  for (int i = 0; i <= Chain::kMaxJoints; ++i) {
    std::string name = std::to_string(i);  // not "j" + ...: GCC 12 -Wrestrict false positive
    name.insert(name.begin(), 'j');
    many.push_back({name, ChainJointType::Fixed, {}});
  }
  EXPECT_THROW(Chain{many}, std::invalid_argument);
}

// A chain of every joint type with skew, non-normalised axes, non-zero origins, rpy and offsets,
// against the product of homogeneous transforms built with Eigen's AngleAxis.
std::vector<ChainJoint> mixedJoints() {
  return {{"a", ChainJointType::Revolute, {0.3, -0.2, 2.0}},
          {"b", ChainJointType::Prismatic, {1.0, 0.5, -0.4}},
          {"c", ChainJointType::Fixed, {}},
          {"d", ChainJointType::Revolute, {-1.0, 0.2, 0.1}},
          {"e", ChainJointType::Revolute, {0.0, 1.0, 0.0}},
          {"tool", ChainJointType::Fixed, {}}};
}

Eigen::VectorXd mixedParameters(const Chain& chain) {
  Eigen::VectorXd p = randomVector(chain.parameterCount(), 7, 1.0);
  for (int i = 0; i < static_cast<int>(chain.joints().size()); ++i) {
    p.segment<3>(chain.parameterOffset(i)) *= 150.0;  // mm-sized origins
  }
  return p;
}

TEST(Chain, ForwardEqualsProductOfHomogeneousTransforms) {
  const Chain chain(mixedJoints());
  const Eigen::VectorXd p = mixedParameters(chain);
  const Eigen::VectorXd q = randomVector(chain.jointCount(), 11, 2.0);
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  int reading = 0;
  for (int i = 0; i < static_cast<int>(chain.joints().size()); ++i) {
    const ChainJoint& joint = chain.joints()[i];
    const int k = chain.parameterOffset(i);
    T = T * translation(p.segment<3>(k)) * rotZ(p[k + 5]) * rotY(p[k + 4]) * rotX(p[k + 3]);
    if (joint.type == ChainJointType::Fixed) continue;
    const double value = q[reading++] + p[k + 6];
    const Eigen::Vector3d axis = joint.axis.normalized();
    T = T * (joint.type == ChainJointType::Revolute ? rotation(axis, value)
                                                    : translation(axis * value));
  }
  Eigen::VectorXd x;
  forwardOrThrow(chain, p, q, x);
  EXPECT_LT((x - T.block<3, 1>(0, 3)).norm(), 1e-10);
}

TEST(Chain, JacobiansMatchFiniteDifferencesMixedJoints) {
  const Chain chain(mixedJoints());
  checkJacobians(chain, mixedParameters(chain), 8, 100);
}

TEST(Chain, JacobiansMatchFiniteDifferencesPanda) {
  const Chain chain = pandaChain();
  Eigen::VectorXd p = pandaNominal(chain);
  checkJacobians(chain, p, 4, 200);
  p += randomVector(p.size(), 3, 0.01);  // offsets and small tilts everywhere
  checkJacobians(chain, p, 4, 300);
}

TEST(Chain, RpyFromMatrixInvertsRpyToMatrixIncludingGimbalLock) {
  std::vector<Eigen::Vector3d> cases;
  for (int i = 0; i < 200; ++i) cases.push_back(randomVector(3, 500 + i, kPi));
  for (double pitch : {kPi / 2, -kPi / 2, kPi / 2 - 1e-9, -kPi / 2 + 1e-13, kPi / 2 + 1e-7}) {
    cases.push_back({0.3, pitch, -1.1});
    cases.push_back({-2.0, pitch, 0.0});
  }
  for (const Eigen::Vector3d& rpy : cases) {
    const Eigen::Matrix3d R = rpyToMatrix(rpy);
    const Eigen::Matrix3d byAngleAxis = (Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) *
                                         Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
                                         Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX()))
                                            .toRotationMatrix();
    EXPECT_LT((R - byAngleAxis).cwiseAbs().maxCoeff(), 1e-15);
    const Eigen::Vector3d back = rpyFromMatrix(R);
    EXPECT_LT((rpyToMatrix(back) - R).cwiseAbs().maxCoeff(), 1e-15) << rpy.transpose();
    EXPECT_LE(std::abs(back[1]), kPi / 2);
  }
}

// The generic damped least squares serves the chain: several genuinely different postures of the
// Panda put the ball on one point, each within the joint limits.
TEST(Chain, PandaPosturesReachAPointWithinTheJointLimits) {
  Machine machine;
  machine.mechanism = std::make_shared<Chain>(pandaChain());
  machine.nominal = pandaNominal(static_cast<const Chain&>(*machine.mechanism));
  const double limits_deg[7][2] = {{-166, 166}, {-101, 101}, {-166, 166}, {-176, -4},
                                   {-166, 166}, {-1, 215},   {-166, 166}};
  for (const auto& l : limits_deg)
    machine.joint_limits.push_back({l[0] * kPi / 180, l[1] * kPi / 180});
  const Eigen::Vector3d target(450.0, -120.0, 380.0);
  std::mt19937_64 rng(5);
  const std::vector<Eigen::VectorXd> postures =
      diversePostures(machine, machine.nominal, target, 4, rng);
  ASSERT_EQ(postures.size(), 4u);
  for (const Eigen::VectorXd& q : postures) {
    Eigen::VectorXd x;
    forwardOrThrow(*machine.mechanism, machine.nominal, q, x);
    EXPECT_LT((x - target).norm(), 1e-9);
    EXPECT_TRUE(machine.withinLimits(q));
  }
  EXPECT_GT((postures[0] - postures[1]).norm(), 0.1);
}

// ---- serial-dh with beta and the modified convention (models.md section 2)

std::vector<DHJoint> betaJoints() {
  return {{JointKind::Revolute, false},
          {JointKind::Revolute, true},
          {JointKind::Prismatic, true},
          {JointKind::Revolute, false}};
}

Eigen::VectorXd betaParameters(const SerialDH& arm) {
  Eigen::VectorXd p = randomVector(arm.parameterCount(), 21, 1.0);
  for (int i = 0; i < arm.jointCount(); ++i) {
    p.segment<2>(arm.parameterOffset(i) + 1) *= 200.0;  // d, a in mm
  }
  p.tail<3>() *= 100.0;
  return p;
}

TEST(SerialDH, BetaParameterOnlyOnJointsCarryingIt) {
  const SerialDH arm(betaJoints(), DHConvention::Standard);
  ASSERT_EQ(arm.parameterCount(), 4 * 4 + 2 + 3);
  EXPECT_EQ(arm.parameterIndex("j1.beta"), -1);
  EXPECT_EQ(arm.parameterIndex("j2.beta"), 8);
  EXPECT_EQ(arm.parameterIndex("j3.theta"), 9);
  EXPECT_EQ(arm.parameterIndex("j3.beta"), 13);
  EXPECT_EQ(arm.parameterIndex("j4.alpha"), 17);
  EXPECT_EQ(arm.parameterIndex("probe.x"), 18);
  EXPECT_EQ(arm.parameters()[8].quantity, Quantity::Angle);
}

Eigen::Vector3d dhByHomogeneousTransforms(const SerialDH& arm, const Eigen::VectorXd& p,
                                          const Eigen::VectorXd& q) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  for (int i = 0; i < arm.jointCount(); ++i) {
    const int k = arm.parameterOffset(i);
    double theta = p[k], d = p[k + 1];
    (arm.jointKind(i) == JointKind::Revolute ? theta : d) += q[i];
    const double beta = arm.hasBeta(i) ? p[k + 4] : 0.0;
    if (arm.convention() == DHConvention::Standard) {
      T = T * rotZ(theta) * translation({0, 0, d}) * translation({p[k + 2], 0, 0}) *
          rotX(p[k + 3]) * rotY(beta);
    } else {
      T = T * rotX(p[k + 3]) * translation({p[k + 2], 0, 0}) * rotY(beta) * rotZ(theta) *
          translation({0, 0, d});
    }
  }
  return (T * p.tail<3>().homogeneous()).head<3>();
}

TEST(SerialDH, BetaAndModifiedForwardEqualHomogeneousTransforms) {
  for (DHConvention convention : {DHConvention::Standard, DHConvention::Modified}) {
    const SerialDH arm(betaJoints(), convention);
    const Eigen::VectorXd p = betaParameters(arm);
    for (int c = 0; c < 4; ++c) {
      const Eigen::VectorXd q = randomVector(4, 30 + c, 2.0);
      Eigen::VectorXd x;
      forwardOrThrow(arm, p, q, x);
      EXPECT_LT((x - dhByHomogeneousTransforms(arm, p, q)).norm(), 1e-10);
    }
  }
}

TEST(SerialDH, BetaAndModifiedJacobiansMatchFiniteDifferences) {
  for (DHConvention convention : {DHConvention::Standard, DHConvention::Modified}) {
    const SerialDH arm(betaJoints(), convention);
    checkJacobians(arm, betaParameters(arm), 6, convention == DHConvention::Standard ? 400 : 500);
    // Nominal beta exactly 0 (the usual case) also has an exact beta column.
    Eigen::VectorXd p = betaParameters(arm);
    p[arm.parameterIndex("j2.beta")] = 0.0;
    checkJacobians(arm, p, 2, 600);
  }
}

// Without beta the standard convention is the model plans have always used.
TEST(SerialDH, NoBetaStandardEqualsTheKindsConstructor) {
  const SerialDH a(std::vector<JointKind>{JointKind::Revolute, JointKind::Prismatic});
  const SerialDH b({{JointKind::Revolute, false}, {JointKind::Prismatic, false}},
                   DHConvention::Standard);
  ASSERT_EQ(a.parameterCount(), b.parameterCount());
  const Eigen::VectorXd p = randomVector(a.parameterCount(), 5, 100.0);
  const Eigen::VectorXd q = randomVector(2, 6, 1.0);
  Eigen::VectorXd xa, xb;
  forwardOrThrow(a, p, q, xa);
  forwardOrThrow(b, p, q, xb);
  EXPECT_EQ(xa, xb);
}

}  // namespace chain_test
}  // namespace artcal
