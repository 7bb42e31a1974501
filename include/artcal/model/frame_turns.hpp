#pragma once
// In-place rotations of a frame about its own axes, R <- R Rx/Ry/Rz(angle): two columns turn,
// the third stays. The serial models (serial-dh, chain) build their frames with them, and their
// geometric Jacobians with tipColumn.

#include <Eigen/Core>
#include <cmath>

namespace artcal {

// R <- R Rz: the x and y columns turn by the angle whose cosine and sine are c and s.
inline void turnAboutZ(Eigen::Matrix3d& R, double c, double s) {
  const Eigen::Vector3d x = R.col(0), y = R.col(1);
  R.col(0) = c * x + s * y;
  R.col(1) = c * y - s * x;
}

// R <- R Ry: the z and x columns turn.
inline void turnAboutY(Eigen::Matrix3d& R, double c, double s) {
  const Eigen::Vector3d x = R.col(0), z = R.col(2);
  R.col(0) = c * x - s * z;
  R.col(2) = c * z + s * x;
}

// R <- R Rx: the y and z columns turn.
inline void turnAboutX(Eigen::Matrix3d& R, double c, double s) {
  const Eigen::Vector3d y = R.col(1), z = R.col(2);
  R.col(1) = c * y + s * z;
  R.col(2) = c * z - s * y;
}

// R <- R Rz(angle), R Ry(angle), R Rx(angle); exactly R at angle 0 (most origins' angles are).
inline void turnAboutZ(Eigen::Matrix3d& R, double angle) {
  if (angle != 0.0) turnAboutZ(R, std::cos(angle), std::sin(angle));
}
inline void turnAboutY(Eigen::Matrix3d& R, double angle) {
  if (angle != 0.0) turnAboutY(R, std::cos(angle), std::sin(angle));
}
inline void turnAboutX(Eigen::Matrix3d& R, double angle) {
  if (angle != 0.0) turnAboutX(R, std::cos(angle), std::sin(angle));
}

/// The geometric Jacobian's column of one elementary motion of a serial model (docs/method.md
/// section 1), for the tip at `tip`: a rotation about the world axis `axis` through `pivot`
/// moves it by axis x (tip - pivot), a translation along `axis` by axis. chain and serial-dh
/// build their J_x_p and J_x_q from it.
inline Eigen::Vector3d tipColumn(bool rotation, const Eigen::Vector3d& axis,
                                 const Eigen::Vector3d& pivot, const Eigen::Vector3d& tip) {
  return rotation ? Eigen::Vector3d(axis.cross(tip - pivot)) : axis;
}

/// The cross-product matrix: skew(v) * w = v x w.
inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

}  // namespace artcal
