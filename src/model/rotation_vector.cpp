#include "artcal/model/rotation_vector.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "artcal/model/frame_turns.hpp"

namespace artcal {

Eigen::Matrix3d rotationFromVector(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

Eigen::Vector3d rotationVector(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd turn(R);
  return turn.angle() * turn.axis();
}

// J_l^-1(phi) = I - [phi]x / 2 + (1 / t^2 - (1 + cos t) / (2 t sin t)) [phi]x^2, t = |phi|; the
// coefficient tends to 1/12 + t^2/720 as t -> 0 (its series, used below 1e-4 rad).
Eigen::Matrix3d inverseLeftJacobian(const Eigen::Vector3d& phi) {
  const double t = phi.norm();
  const double coefficient = t < 1e-4
                                 ? 1.0 / 12.0 + t * t / 720.0
                                 : 1.0 / (t * t) - (1.0 + std::cos(t)) / (2.0 * t * std::sin(t));
  const Eigen::Matrix3d S = skew(phi);
  return Eigen::Matrix3d::Identity() - 0.5 * S + coefficient * S * S;
}

Eigen::Vector3d orientationResidual(const Eigen::Matrix3d& R_predicted,
                                    const Eigen::Vector3d& measured, Eigen::Matrix3d* J_e_w) {
  const Eigen::Vector3d e = rotationVector(R_predicted * rotationFromVector(measured).transpose());
  if (J_e_w) *J_e_w = inverseLeftJacobian(e);
  return e;
}

}  // namespace artcal
