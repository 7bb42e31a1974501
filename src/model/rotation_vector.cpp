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

Eigen::Matrix3d rpyToMatrix(const Eigen::Vector3d& rpy) {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  turnAboutZ(R, rpy[2]);
  turnAboutY(R, rpy[1]);
  turnAboutX(R, rpy[0]);
  return R;
}

// R = Rz(y) Ry(p) Rx(r): R(2,0) = -sin p, and cos p = |(R00, R10)| >= 0 (atan2, not asin: exact
// near +-90 deg). Yaw from the first column (R00, R10) = cos p (cos y, sin y); roll is then
// whatever is left, Rx(r) = Ry(p)^T Rz(y)^T R. Near the gimbal lock the yaw is poorly determined
// (error e ~ rounding / cos p), but there a z turn after Ry(+-90) is an x turn: roll absorbs e and
// the product misses R by only e cos p, i.e. rounding. At the lock itself atan2(0, 0) = 0 and
// roll takes all of yaw -+ roll, the one combination defined there.
Eigen::Vector3d rpyFromMatrix(const Eigen::Matrix3d& R) {
  const double cos_pitch = std::hypot(R(0, 0), R(1, 0));
  const double pitch = std::atan2(-R(2, 0), cos_pitch);
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  // rest <- Ry(-pitch) Rz(-yaw) R = (R^T Rz(yaw) Ry(pitch))^T.
  Eigen::Matrix3d T = R.transpose();
  turnAboutZ(T, yaw);
  turnAboutY(T, pitch);
  const Eigen::Matrix3d rest = T.transpose();
  const double roll = std::atan2(rest(2, 1), rest(1, 1));
  return {roll, pitch, yaw};
}

Eigen::Matrix3d axisAngleMatrix(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

}  // namespace artcal
