#include "artcal/artifact/rigid_transform.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace artcal {

RigidTransform RigidTransform::identity(int dimension) {
  return {Eigen::MatrixXd::Identity(dimension, dimension), Eigen::VectorXd::Zero(dimension)};
}

RigidTransform RigidTransform::inverse() const {
  return {R.transpose(), -(R.transpose() * t)};
}

namespace {

Eigen::MatrixXd rotationOf(int dimension, const Eigen::VectorXd& rotation) {
  if (dimension == 2) return Eigen::Rotation2Dd(rotation[0]).toRotationMatrix();
  const Eigen::Vector3d w = rotation.head<3>();
  const double angle = w.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

}  // namespace

RigidTransform RigidTransform::perturbed(const Eigen::VectorXd& delta) const {
  const int d = dimension();
  const Eigen::MatrixXd dR = rotationOf(d, delta.tail(d == 2 ? 1 : 3));
  return {dR * R, dR * t + delta.head(d)};
}

RigidTransform fitRigid(const Eigen::MatrixXd& machine, const Eigen::MatrixXd& artifact) {
  const int d = static_cast<int>(machine.rows());
  RigidTransform T = RigidTransform::identity(d);
  if (machine.cols() >= 2) {
    const Eigen::MatrixXd H = Eigen::umeyama(machine, artifact, false);
    T.R = H.topLeftCorner(d, d);
    T.t = H.topRightCorner(d, 1);
  } else if (machine.cols() == 1) {
    T.t = artifact.col(0) - machine.col(0);
  }
  return T;
}

RigidTransform placePlanar(const Eigen::Vector2d& center, double angle) {
  // Artifact frame to machine frame: x = Rot(angle) W + center; we store the inverse.
  const Eigen::Matrix2d Rt = Eigen::Rotation2Dd(-angle).toRotationMatrix();
  return {Rt, -(Rt * center)};
}

RigidTransform placeSpatial(const Eigen::Vector3d& center, const Eigen::Vector3d& direction,
                            double roll) {
  const Eigen::Vector3d ex = direction.normalized();
  Eigen::Vector3d ey = Eigen::Vector3d::UnitZ().cross(ex);
  if (ey.norm() < 1e-9) ey = Eigen::Vector3d::UnitY();
  ey.normalize();
  ey = Eigen::AngleAxisd(roll, ex) * ey;
  Eigen::Matrix3d Rp;
  Rp.col(0) = ex;
  Rp.col(1) = ey;
  Rp.col(2) = ex.cross(ey);
  const Eigen::Matrix3d Rt = Rp.transpose();
  return {Rt, -(Rt * center)};
}

}  // namespace artcal
