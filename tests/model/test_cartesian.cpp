// The Cartesian CMM model (models.md section 4): forward values worked out by hand, exact
// Jacobians through the finite-difference battery, how close to linear in p it is, and the
// inverse kinematics (nominal closed form, then Newton).

#include <gtest/gtest.h>

#include <random>

#include "artcal/model/cartesian.hpp"
#include "finite_difference.hpp"

namespace artcal {
namespace cartesian_test {

using testing::centralDifferenceJacobian;
using testing::expectJacobianNear;

// The moving-bridge CMM of models.md section 4: bridge y carries carriage x carries ram z.
Cartesian bridgeCmm(int degree) {
  return Cartesian({{"y", Eigen::Vector3d::UnitY(), {0.0, 700.0}},
                    {"x", Eigen::Vector3d::UnitX(), {0.0, 1000.0}},
                    {"z", Eigen::Vector3d::UnitZ(), {-600.0, 0.0}}},
                   degree, {Eigen::Vector3d(0, 0, -60), Eigen::Vector3d(40, 0, -60)});
}

// Coefficients of a real machine's size: translations `mm`, rotations `rad`, seeded.
Eigen::VectorXd randomErrors(const Cartesian& cmm, double mm, double rad, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd p(cmm.parameterCount());
  for (int i = 0; i < p.size(); ++i) p[i] = uniform(rng) * ((i % kAxisErrorCount) < 3 ? mm : rad);
  return p;
}

Eigen::Vector3d position(const Cartesian& cmm, const Eigen::VectorXd& p, const Eigen::VectorXd& u,
                         int stylus) {
  Eigen::VectorXd x;
  EXPECT_EQ(cmm.forwardStylus(stylus, p, u, x), ForwardStatus::Ok);
  return x;
}

TEST(Cartesian, ParametersPerAxisPerDegreeInErrorOrder) {
  const Cartesian cmm = bridgeCmm(3);
  ASSERT_EQ(cmm.parameterCount(), 54);
  EXPECT_EQ(cmm.parameters()[0].name, "y.tx.1");
  EXPECT_EQ(cmm.parameters()[5].name, "y.rz.1");
  EXPECT_EQ(cmm.parameters()[6].name, "y.tx.2");
  EXPECT_EQ(cmm.parameters()[18].name, "x.tx.1");
  EXPECT_EQ(cmm.parameters()[53].name, "z.rz.3");
  EXPECT_EQ(cmm.parameterIndex("x.ry.2"), cmm.parameterIndex(1, AxisError::Ry, 2));
  EXPECT_EQ(cmm.parameters()[3].quantity, kMicrometrePerMetre);
  EXPECT_EQ(toFileUnit(cmm.parameters()[3].quantity, 2e-6), 2.0);  // um/m
  EXPECT_EQ(cmm.parameters()[2].quantity, Quantity::Length);
}

TEST(Cartesian, LegendrePolynomialsAndDerivatives) {
  double P[5], dP[5];
  for (double s : {-1.0, -0.3, 0.0, 0.55, 1.0}) {
    legendre(4, s, P, dP);
    EXPECT_NEAR(P[2], (3 * s * s - 1) / 2, 1e-15);
    EXPECT_NEAR(P[3], (5 * s * s * s - 3 * s) / 2, 1e-15);
    EXPECT_NEAR(P[4], (35 * s * s * s * s - 30 * s * s + 3) / 8, 1e-15);
    EXPECT_NEAR(dP[3], (15 * s * s - 3) / 2, 1e-14);
    EXPECT_NEAR(dP[4], (140 * s * s * s - 60 * s) / 8, 1e-14);
  }
}

TEST(Cartesian, NominalMachineIsTheAxesPlusTheStylus) {
  const Cartesian cmm = bridgeCmm(2);
  const Eigen::VectorXd p = Eigen::VectorXd::Zero(cmm.parameterCount());
  const Eigen::Vector3d u(250.0, 400.0, -300.0);  // y, x, z readings
  EXPECT_TRUE(position(cmm, p, u, 0).isApprox(Eigen::Vector3d(400, 250, -360), 1e-15));
  EXPECT_TRUE(position(cmm, p, u, 1).isApprox(Eigen::Vector3d(440, 250, -360), 1e-15));
}

TEST(Cartesian, OneErrorFunctionMovesThePointAsWorkedOutByHand) {
  const Cartesian cmm = bridgeCmm(2);
  const Eigen::Vector3d u(175.0, 400.0, -150.0);  // s_y = -0.5, s_x = -0.2, s_z = 0.5
  Eigen::VectorXd p = Eigen::VectorXd::Zero(cmm.parameterCount());
  // The bridge's straightness in x, degree 2: 0.004 mm * P_2(-0.5) = 0.004 * -0.125.
  p[cmm.parameterIndex("y.tx.2")] = 0.004;
  const Eigen::Vector3d nominal(400.0, 175.0, -210.0);
  // (Differences of coordinates of hundreds of mm: rounding of 1e-13 mm.)
  EXPECT_NEAR((position(cmm, p, u, 0) - nominal).x(), -0.0005, 2e-13);
  // The ram's rotation about x, degree 1 (10 urad * P_1(0.5) = 5 urad): the stylus 60 mm below
  // the ram's origin swings by +5e-6 * 60 in y (Abbe), exactly 60 sin(5e-6) with the exact
  // rotation, and rises by 60 (1 - cos).
  p.setZero();
  p[cmm.parameterIndex("z.rx.1")] = 10e-6;
  const Eigen::Vector3d moved = position(cmm, p, u, 0) - nominal;
  EXPECT_NEAR(moved.y(), 60.0 * std::sin(5e-6), 2e-13);
  EXPECT_NEAR(moved.z(), 60.0 * (1.0 - std::cos(5e-6)), 2e-13);  // 7.5e-10: not linear
  // The bridge's yaw (rotation about z, degree 1, s_y = -0.5): everything it carries turns about
  // the bridge's origin: the stylus at (400 + 40, 0, ...) relative to it moves in y.
  p.setZero();
  p[cmm.parameterIndex("y.rz.1")] = 20e-6;
  EXPECT_NEAR((position(cmm, p, u, 1) - nominal).y(), 440.0 * std::sin(-10e-6), 1e-12);
}

TEST(Cartesian, JacobiansMatchFiniteDifferencesForEveryStylus) {
  const Cartesian cmm = bridgeCmm(3);
  // Large errors (1 mrad) so that the exact rotation's terms are exercised, not only the linear
  // ones; small ones (a real machine's).
  for (const double rad : {1e-3, 5e-6}) {
    const Eigen::VectorXd p = randomErrors(cmm, 0.005, rad, 7);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int c = 0; c < 6; ++c) {
      const Eigen::Vector3d u(700 * unit(rng), 1000 * unit(rng), -600 * unit(rng));
      for (int stylus = 0; stylus < cmm.stylusCount(); ++stylus) {
        Eigen::VectorXd x;
        Eigen::MatrixXd J_x_p, J_x_q;
        ASSERT_EQ(cmm.forwardStylus(stylus, p, u, x, &J_x_p, &J_x_q), ForwardStatus::Ok);
        const auto of_p = [&](const Eigen::VectorXd& pp) { return position(cmm, pp, u, stylus); };
        const auto of_q = [&](const Eigen::VectorXd& qq) {
          return Eigen::VectorXd(position(cmm, p, qq, stylus));
        };
        const auto of_p_vector = [&](const Eigen::VectorXd& pp) {
          return Eigen::VectorXd(of_p(pp));
        };
        const std::string where = "configuration " + std::to_string(c) + " stylus " +
                                  std::to_string(stylus) + " rad " + std::to_string(rad);
        expectJacobianNear(J_x_p, centralDifferenceJacobian(of_p_vector, p, 1e-6), 1e-7,
                           where + " J_x_p");
        expectJacobianNear(J_x_q, centralDifferenceJacobian(of_q, u, 1e-4), 1e-7, where + " J_x_q");
        EXPECT_EQ(position(cmm, p, u, stylus), Eigen::Vector3d(x));
      }
    }
  }
}

// Nearly linear in p (models.md section 4): f(p) - f(0) - J(0) p is second order. For a real
// machine's errors (5 um, 5 um/m) it stays below 1e-6 mm over the volume, and doubling p
// multiplies it by 4 (a quadratic remainder, not a Jacobian error).
TEST(Cartesian, NearlyLinearInTheErrorCoefficients) {
  const Cartesian cmm = bridgeCmm(3);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(cmm.parameterCount());
  const Eigen::VectorXd p = randomErrors(cmm, 0.005, 5e-6, 11);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst = 0.0;
  for (int c = 0; c < 50; ++c) {
    const Eigen::Vector3d u(700 * unit(rng), 1000 * unit(rng), -600 * unit(rng));
    Eigen::VectorXd x0;
    Eigen::MatrixXd J;
    ASSERT_EQ(cmm.forwardStylus(1, zero, u, x0, &J), ForwardStatus::Ok);
    const auto remainder = [&](const Eigen::VectorXd& pp) {
      return (position(cmm, pp, u, 1) - x0 - J * pp).norm();
    };
    const double r1 = remainder(p), r2 = remainder(2.0 * p);
    worst = std::max(worst, r1);
    EXPECT_LT(r1, 1e-6);
    if (r1 > 1e-11) {
      EXPECT_NEAR(r2 / r1, 4.0, 0.05) << "configuration " << c;
    }
  }
  EXPECT_GT(worst, 1e-10);  // the exact rotations are not linear: the test measures something
}

TEST(Cartesian, InverseKinematicsReachesTheTargetInAFewNewtonSteps) {
  const Cartesian cmm = bridgeCmm(3);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(cmm.parameterCount());
  const Eigen::VectorXd p = randomErrors(cmm, 0.005, 5e-6, 13);
  const Eigen::Vector3d target(612.5, 333.0, -421.0);
  for (int stylus = 0; stylus < 2; ++stylus) {
    const auto nominal = cmm.nominalInverse(target, stylus);
    ASSERT_TRUE(nominal);
    EXPECT_TRUE(position(cmm, zero, *nominal, stylus).isApprox(target, 1e-15));
    const auto u = cmm.inverse(p, target, stylus);
    ASSERT_TRUE(u);
    EXPECT_LT((position(cmm, p, *u, stylus) - target).norm(), 1e-10);
    // The errors move the readings by micrometres, not more.
    EXPECT_LT((*u - *nominal).cwiseAbs().maxCoeff(), 0.05);
    EXPECT_GT((*u - *nominal).cwiseAbs().maxCoeff(), 1e-4);
  }
}

TEST(Cartesian, ErrorFunctionsNamedAsAMetrologistReadsThem) {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), z = Eigen::Vector3d::UnitZ();
  EXPECT_EQ(axisErrorMeaning(x, AxisError::Tx), "positioning");
  EXPECT_EQ(axisErrorMeaning(x, AxisError::Ty), "straightness in y");
  EXPECT_EQ(axisErrorMeaning(x, AxisError::Rx), "roll");
  EXPECT_EQ(axisErrorMeaning(x, AxisError::Ry), "pitch");
  EXPECT_EQ(axisErrorMeaning(x, AxisError::Rz), "yaw");
  EXPECT_EQ(axisErrorMeaning(z, AxisError::Rz), "roll");
  EXPECT_EQ(axisErrorMeaning(z, AxisError::Tz), "positioning");
}

}  // namespace cartesian_test
}  // namespace artcal
