#include "artcal/model/serial_dh.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

namespace artcal {

namespace {

// Frames are kept on the stack (no allocation per call); plan files allow at most 32 joints.
constexpr int kMaxJoints = 32;
using Columns = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, kMaxJoints + 1>;
using Jacobian = Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic>>;

// R <- R Rz(angle): only the x and y columns turn.
void turnAboutZ(Eigen::Matrix3d& R, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const Eigen::Vector3d x = R.col(0), y = R.col(1);
  R.col(0) = c * x + s * y;
  R.col(1) = c * y - s * x;
}

// R <- R Rx(angle): only the y and z columns turn.
void turnAboutX(Eigen::Matrix3d& R, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const Eigen::Vector3d y = R.col(1), z = R.col(2);
  R.col(1) = c * y + s * z;
  R.col(2) = c * z - s * y;
}

}  // namespace

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
  if (joints_.size() > static_cast<std::size_t>(kMaxJoints)) {
    throw std::invalid_argument("serial-dh: at most " + std::to_string(kMaxJoints) + " joints");
  }
}

// Geometric Jacobian of the probe centre x. With frame i-1 (origin o, z axis z) before joint i
// and frame i (origin o_i, x axis x_i) after it:
//   d x / d theta_i = z x (x - o),   d x / d d_i = z,
//   d x / d a_i = x_i,               d x / d alpha_i = x_i x (x - o_i),
// and a revolute joint variable acts like theta_i, a prismatic one like d_i.
ForwardStatus SerialDH::forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p,
                                Eigen::MatrixXd* J_x_q) const {
  const int n = jointCount();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d o = Eigen::Vector3d::Zero();
  // Frames before each joint (index i) and after the last one (index n).
  Columns origins(3, n + 1), z_axes(3, n + 1), x_axes(3, n + 1);
  origins.col(0) = o;
  z_axes.col(0) = R.col(2);
  x_axes.col(0) = R.col(0);
  for (int i = 0; i < n; ++i) {
    const int k = jointParameterOffset(i);
    double theta = p[k], d = p[k + 1];
    (joints_[i] == JointKind::Revolute ? theta : d) += q[i];
    o += R.col(2) * d;
    turnAboutZ(R, theta);
    o += R.col(0) * p[k + 2];
    turnAboutX(R, p[k + 3]);
    origins.col(i + 1) = o;
    z_axes.col(i + 1) = R.col(2);
    x_axes.col(i + 1) = R.col(0);
  }
  const Eigen::Vector3d tip = o + R * p.segment<3>(probeParameterOffset());
  x.resize(3);
  Eigen::Map<Eigen::Vector3d>(x.data()) = tip;
  // Written through fixed-row maps: GCC 12 warns (-Warray-bounds, falsely) when fixed-size
  // vectors are assigned into blocks of a dynamic matrix under -march=native.
  if (J_x_p) {
    J_x_p->resize(3, parameterCount());
    Jacobian J(J_x_p->data(), 3, parameterCount());
    for (int i = 0; i < n; ++i) {
      const int k = jointParameterOffset(i);
      J.col(k) = z_axes.col(i).cross(tip - origins.col(i));
      J.col(k + 1) = z_axes.col(i);
      J.col(k + 2) = x_axes.col(i + 1);
      J.col(k + 3) = x_axes.col(i + 1).cross(tip - origins.col(i + 1));
    }
    J.middleCols<3>(probeParameterOffset()) = R;
  }
  if (J_x_q) {
    J_x_q->resize(3, n);
    Jacobian J(J_x_q->data(), 3, n);
    for (int i = 0; i < n; ++i) {
      if (joints_[i] == JointKind::Revolute) {
        J.col(i) = z_axes.col(i).cross(tip - origins.col(i));
      } else {
        J.col(i) = z_axes.col(i);
      }
    }
  }
  return ForwardStatus::Ok;
}

}  // namespace artcal
