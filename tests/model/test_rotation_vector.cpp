// Rotation vectors for "measures": "pose" (instruments.md): exp and log are inverse up to an
// angle of pi, and the orientation residual's Jacobian (J_l^-1, spatial steps) matches central
// differences at residuals from 1e-9 rad to nearly pi, the small-angle series included.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <random>
#include <stdexcept>

#include "artcal/model/planar2r.hpp"
#include "artcal/model/rotation_vector.hpp"
#include "finite_difference.hpp"

namespace artcal {
namespace rotation_vector_test {

using testing::centralDifferenceJacobian;
using testing::expectJacobianNear;

Eigen::Vector3d randomDirection(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
}

TEST(RotationVector, LogInvertsExpUpToPi) {
  std::mt19937_64 rng(21);
  for (double angle : {0.0, 1e-9, 1e-5, 0.3, 1.7, 3.0, 3.14}) {
    const Eigen::Vector3d w = angle * randomDirection(rng);
    const Eigen::Vector3d back = rotationVector(rotationFromVector(w));
    EXPECT_LT((back - w).norm(), 1e-12) << "angle " << angle;
  }
  // A rotation by 90 deg about z, written out.
  Eigen::Matrix3d Rz;
  Rz << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_LT((rotationVector(Rz) - Eigen::Vector3d(0, 0, M_PI / 2)).norm(), 1e-15);
}

TEST(RotationVector, ResidualJacobianIsExact) {
  std::mt19937_64 rng(22);
  for (double residual_angle : {0.0, 1e-9, 5e-5, 2e-4, 0.5, 2.0, 3.0}) {
    const Eigen::Matrix3d R = rotationFromVector(2.5 * randomDirection(rng));
    // measured such that R exp(measured)^T turns by residual_angle.
    const Eigen::Matrix3d turn = rotationFromVector(residual_angle * randomDirection(rng));
    const Eigen::Vector3d measured = rotationVector(turn.transpose() * R);
    Eigen::Matrix3d J;
    const Eigen::Vector3d e = orientationResidual(R, measured, &J);
    EXPECT_NEAR(e.norm(), residual_angle, 1e-12);
    auto F = [&](const Eigen::VectorXd& dw) {
      return Eigen::VectorXd(orientationResidual(rotationFromVector(dw) * R, measured));
    };
    expectJacobianNear(J, centralDifferenceJacobian(F, Eigen::VectorXd::Zero(3), 1e-6), 1e-7,
                       "residual angle " + std::to_string(residual_angle));
  }
}

TEST(RotationVector, ModelsWithoutOrientationSaySo) {
  const Planar2R arm;
  EXPECT_FALSE(arm.hasOrientation());
  Eigen::VectorXd x;
  Eigen::Matrix3d R;
  EXPECT_THROW((void)arm.forwardPose(Eigen::Vector2d(300, 200), Eigen::Vector2d(0.1, 0.2), x, R),
               std::logic_error);
}

}  // namespace rotation_vector_test
}  // namespace artcal
