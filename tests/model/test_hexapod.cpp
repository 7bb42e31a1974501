// The hexapod and the closed-chain path (models.md section 3): forward kinematics against the
// closed-form inverse, exact Jacobians against the finite-difference battery, reported failures.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "artcal/core/units.hpp"
#include "artcal/model/hexapod.hpp"
#include "finite_difference.hpp"

namespace artcal {
namespace {

using testing::centralDifferenceJacobian;
using testing::expectJacobianNear;

// The reference hexapod of tests/data/ref-hexapod-6bars.json: base radius 400, platform radius
// 150, joint pairs +-10 deg about 0, 120, 240 deg (platform turned by 60 deg), probe (0, 0, -100).
Eigen::VectorXd referenceParameters() {
  Eigen::VectorXd p(45);
  const double base_angles[6] = {10, 110, 130, -130, -110, -10};
  const double platform_angles[6] = {50, 70, 170, -170, -70, -50};
  for (int i = 0; i < 6; ++i) {
    const double b = degToRad(base_angles[i]), a = degToRad(platform_angles[i]);
    p.segment<3>(Hexapod::baseOffset(i)) << 400.0 * std::cos(b), 400.0 * std::sin(b), 0.0;
    p.segment<3>(Hexapod::platformOffset(i)) << 150.0 * std::cos(a), 150.0 * std::sin(a), 0.0;
    p[Hexapod::legOffsetIndex(i)] = 0.0;
  }
  p.tail<3>() << 0.0, 0.0, -100.0;
  return p;
}

Hexapod referenceHexapod() {
  ChainPose home;
  home.t << 0.0, 0.0, 600.0;
  return Hexapod(home, 150.0);
}

// A perturbed machine: every joint centre and leg offset moved by up to 1 mm.
Eigen::VectorXd perturbed(const Eigen::VectorXd& p, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Eigen::VectorXd out = p;
  for (int i = 0; i < out.size(); ++i)
    out[i] += 2.0 * (static_cast<double>(rng() >> 11) * 0x1.0p-53) - 1.0;
  return out;
}

struct Reading {
  Eigen::Vector3d target;
  Eigen::Matrix3d R;
  Eigen::VectorXd q;
};

// Random probe targets in a 300 mm cube around (0, 0, 500) with platform tilts up to 15 deg.
std::vector<Reading> randomReadings(const Hexapod& hexapod, const Eigen::VectorXd& p, int count,
                                    std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Reading> out;
  for (int c = 0; c < count; ++c) {
    Reading r;
    for (int k = 0; k < 3; ++k)
      r.target[k] =
          (k == 2 ? 500.0 : 0.0) + 300.0 * (static_cast<double>(rng() >> 11) * 0x1.0p-53 - 0.5);
    r.R = randomTilt(hexapod.homePose().R, degToRad(15.0), rng);
    r.q = hexapod.legReadings(p, r.target, r.R);
    out.push_back(r);
  }
  return out;
}

TEST(Hexapod, HasTheFortyFiveParametersOfTheSpecInOrder) {
  const Hexapod hexapod = referenceHexapod();
  ASSERT_EQ(hexapod.parameterCount(), 45);
  EXPECT_EQ(hexapod.parameters()[0].name, "b1.x");
  EXPECT_EQ(hexapod.parameters()[5].name, "a1.z");
  EXPECT_EQ(hexapod.parameters()[6].name, "l1.offset");
  EXPECT_EQ(hexapod.parameters()[41].name, "l6.offset");
  EXPECT_EQ(hexapod.parameters()[44].name, "probe.z");
  EXPECT_EQ(hexapod.jointKind(3), JointKind::Prismatic);
}

TEST(Hexapod, ForwardKinematicsInvertsTheClosedFormInverse) {
  const Hexapod hexapod = referenceHexapod();
  for (std::uint64_t seed : {0u, 7u}) {
    const Eigen::VectorXd p =
        seed == 0 ? referenceParameters() : perturbed(referenceParameters(), seed);
    for (const Reading& r : randomReadings(hexapod, p, 50, seed + 1)) {
      Eigen::VectorXd x;
      ASSERT_EQ(hexapod.forward(p, r.q, x), ForwardStatus::Ok);
      EXPECT_LT((x - r.target).norm(), 1e-9);
      ChainPose pose;
      ASSERT_EQ(hexapod.solvePose(p, r.q, pose), ForwardStatus::Ok);
      EXPECT_LT((pose.R - r.R).norm(), 1e-12);
    }
  }
}

TEST(Hexapod, JacobiansMatchFiniteDifferences) {
  const Hexapod hexapod = referenceHexapod();
  const Eigen::VectorXd p = perturbed(referenceParameters(), 3);
  int index = 0;
  for (const Reading& r : randomReadings(hexapod, p, 8, 11)) {
    Eigen::VectorXd x;
    Eigen::MatrixXd J_x_p, J_x_q;
    ASSERT_EQ(hexapod.forward(p, r.q, x, &J_x_p, &J_x_q), ForwardStatus::Ok);
    const auto of_p = [&](const Eigen::VectorXd& pp) {
      Eigen::VectorXd y;
      EXPECT_EQ(hexapod.forward(pp, r.q, y), ForwardStatus::Ok);
      return y;
    };
    const auto of_q = [&](const Eigen::VectorXd& qq) {
      Eigen::VectorXd y;
      EXPECT_EQ(hexapod.forward(p, qq, y), ForwardStatus::Ok);
      return y;
    };
    // Steps of 1e-3 mm: the solver's rounding (1e-13 mm) stays far below the differences.
    const std::string where = "reading " + std::to_string(index++);
    expectJacobianNear(J_x_p, centralDifferenceJacobian(of_p, p, 1e-3), 1e-7, where + " J_x_p");
    expectJacobianNear(J_x_q, centralDifferenceJacobian(of_q, r.q, 1e-3), 1e-7, where + " J_x_q");
    Eigen::VectorXd x_alone;
    ASSERT_EQ(hexapod.forward(p, r.q, x_alone), ForwardStatus::Ok);
    EXPECT_EQ(x_alone, x);
  }
}

TEST(Hexapod, ProbeJacobianIsThePlatformRotation) {
  const Hexapod hexapod = referenceHexapod();
  const Eigen::VectorXd p = referenceParameters();
  const Reading r = randomReadings(hexapod, p, 1, 5).front();
  Eigen::VectorXd x;
  Eigen::MatrixXd J_x_p;
  ASSERT_EQ(hexapod.forward(p, r.q, x, &J_x_p), ForwardStatus::Ok);
  // Moving the probe in the platform frame with the legs held: the platform does not move.
  EXPECT_LT((J_x_p.middleCols<3>(Hexapod::kProbeOffset) - r.R).norm(), 1e-12);
  // A leg offset and its reading enter only through their sum.
  Eigen::MatrixXd J_x_q;
  ASSERT_EQ(hexapod.forward(p, r.q, x, nullptr, &J_x_q), ForwardStatus::Ok);
  for (int i = 0; i < 6; ++i)
    EXPECT_LT((J_x_p.col(Hexapod::legOffsetIndex(i)) - J_x_q.col(i)).norm(), 1e-12);
}

TEST(Hexapod, LegsThatCannotCloseAreAReportedFailure) {
  const Hexapod hexapod = referenceHexapod();
  const Eigen::VectorXd p = referenceParameters();
  Eigen::VectorXd x;
  // Legs of 100 mm cannot span a base 400 mm wide to a platform 150 mm wide.
  EXPECT_NE(hexapod.forward(p, Eigen::VectorXd::Constant(6, 100.0), x), ForwardStatus::Ok);
  // Wildly unequal legs: no pose near home closes them.
  Eigen::VectorXd q(6);
  q << 450, 3000, 450, 3000, 450, 3000;
  EXPECT_NE(hexapod.forward(p, q, x), ForwardStatus::Ok);
}

TEST(Hexapod, CoincidentJointsAreSingular) {
  // Every leg meets the platform at one point: the platform may spin about it.
  ChainPose home;
  home.t << 0.0, 0.0, 600.0;
  const Hexapod hexapod(home, 150.0);
  Eigen::VectorXd p = referenceParameters();
  for (int i = 0; i < 6; ++i) p.segment<3>(Hexapod::platformOffset(i)).setZero();
  const Eigen::VectorXd q = hexapod.legReadings(p, Eigen::Vector3d(0, 0, 500), home.R);
  Eigen::VectorXd x;
  EXPECT_EQ(hexapod.forward(p, q, x), ForwardStatus::Singular);
}

TEST(ClosedChain, RetractTurnsByTheExactExponential) {
  ChainPose pose;
  Eigen::VectorXd ds(6);
  ds << 1.0, 2.0, 3.0, 0.0, 0.0, std::numbers::pi / 2;
  retractPose(pose, ds);
  EXPECT_EQ(pose.t, Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_LT((pose.R * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-15);
  Eigen::VectorXd planar(2);
  planar << 0.5, -0.5;
  retractPose(pose, planar);
  EXPECT_EQ(pose.t, Eigen::Vector3d(1.5, 1.5, 3.0));
}

}  // namespace
}  // namespace artcal
