#pragma once
// A serial arm in standard Denavit-Hartenberg form: each joint i contributes
//   T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)
// with the joint variable added to theta_i (revolute) or d_i (prismatic), and the probe centre
// sits at `probe` in the last frame. Parameters: j1.theta, j1.d, j1.a, j1.alpha, ..., probe.x,
// probe.y, probe.z (4n + 3). Jacobians are the geometric ones (rotation about / translation along
// the joint axes), exact.

#include "artcal/model/mechanism.hpp"

namespace artcal {

class SerialDH final : public Mechanism {
 public:
  explicit SerialDH(std::vector<JointKind> joints);
  std::string modelName() const override { return "serial-dh"; }
  int dimension() const override { return 3; }
  int jointCount() const override { return static_cast<int>(joints_.size()); }
  JointKind jointKind(int joint) const override { return joints_[joint]; }
  const std::vector<ParameterInfo>& parameters() const override { return parameters_; }
  ForwardStatus forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x,
                        Eigen::MatrixXd* J_x_p = nullptr,
                        Eigen::MatrixXd* J_x_q = nullptr) const override;

  /// Index in p of joint i's first parameter (theta); d, a, alpha follow.
  static int jointParameterOffset(int joint) { return 4 * joint; }
  int probeParameterOffset() const { return 4 * jointCount(); }

 private:
  std::vector<JointKind> joints_;
  std::vector<ParameterInfo> parameters_;
};

}  // namespace artcal
