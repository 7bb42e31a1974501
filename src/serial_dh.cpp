#include "artcal/serial_dh.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace artcal {

SerialDH::SerialDH(std::vector<JointKind> joints) : joints_(std::move(joints)) {
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    std::string prefix = std::to_string(i + 1);
    prefix.insert(prefix.begin(), 'j');
    prefix.push_back('.');
    parameters_.push_back({prefix + "theta", Quantity::Angle});
    parameters_.push_back({prefix + "d", Quantity::Length});
    parameters_.push_back({prefix + "a", Quantity::Length});
    parameters_.push_back({prefix + "alpha", Quantity::Angle});
  }
  parameters_.push_back({"probe.x", Quantity::Length});
  parameters_.push_back({"probe.y", Quantity::Length});
  parameters_.push_back({"probe.z", Quantity::Length});
}

// Geometric Jacobian of the probe centre x. With frame i-1 (origin o, z axis z) before joint i
// and frame i (origin o_i, x axis x_i) after it:
//   d x / d theta_i = z x (x - o),   d x / d d_i = z,
//   d x / d a_i = x_i,               d x / d alpha_i = x_i x (x - o_i),
// and a revolute joint variable acts like theta_i, a prismatic one like d_i.
void SerialDH::forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x,
                       Eigen::MatrixXd* J_x_p, Eigen::MatrixXd* J_x_q) const {
  const int n = jointCount();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d o = Eigen::Vector3d::Zero();
  // Frames before each joint (index i) and after the last one (index n).
  Eigen::Matrix<double, 3, Eigen::Dynamic> origins(3, n + 1), z_axes(3, n + 1), x_axes(3, n + 1);
  origins.col(0) = o;
  z_axes.col(0) = R.col(2);
  x_axes.col(0) = R.col(0);
  for (int i = 0; i < n; ++i) {
    const int k = jointParameterOffset(i);
    double theta = p[k], d = p[k + 1];
    (joints_[i] == JointKind::Revolute ? theta : d) += q[i];
    const double a = p[k + 2], alpha = p[k + 3];
    const Eigen::Matrix3d Rz =
        Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Matrix3d Rx =
        Eigen::AngleAxisd(alpha, Eigen::Vector3d::UnitX()).toRotationMatrix();
    o += R.col(2) * d;
    R = R * Rz;
    o += R.col(0) * a;
    R = R * Rx;
    origins.col(i + 1) = o;
    z_axes.col(i + 1) = R.col(2);
    x_axes.col(i + 1) = R.col(0);
  }
  const Eigen::Vector3d probe = p.segment<3>(probeParameterOffset());
  const Eigen::Vector3d tip = o + R * probe;
  x = tip;
  if (!J_x_p && !J_x_q) return;
  if (J_x_p) J_x_p->resize(3, parameterCount());
  if (J_x_q) J_x_q->resize(3, n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d z = z_axes.col(i);
    const Eigen::Vector3d d_theta = z.cross(tip - origins.col(i));
    const Eigen::Vector3d d_d = z;
    if (J_x_p) {
      const int k = jointParameterOffset(i);
      const Eigen::Vector3d xi = x_axes.col(i + 1);
      J_x_p->col(k) = d_theta;
      J_x_p->col(k + 1) = d_d;
      J_x_p->col(k + 2) = xi;
      J_x_p->col(k + 3) = xi.cross(tip - origins.col(i + 1));
    }
    if (J_x_q) J_x_q->col(i) = joints_[i] == JointKind::Revolute ? d_theta : d_d;
  }
  if (J_x_p) J_x_p->middleCols<3>(probeParameterOffset()) = R;
}

}  // namespace artcal
