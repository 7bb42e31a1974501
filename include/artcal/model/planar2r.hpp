#pragma once
// The seed's planar two-link arm (seed eq. 15):
//   x = l1 cos t1 + l2 cos(t1 + t2 + dt2),  y = l1 sin t1 + l2 sin(t1 + t2 + dt2)
// Parameters (l1, l2, dt2); joints (t1, t2), both revolute.

#include "artcal/model/mechanism.hpp"

namespace artcal {

class Planar2R final : public Mechanism {
 public:
  Planar2R();
  std::string modelName() const override { return "planar2r"; }
  int dimension() const override { return 2; }
  int jointCount() const override { return 2; }
  JointKind jointKind(int) const override { return JointKind::Revolute; }
  const std::vector<ParameterInfo>& parameters() const override { return parameters_; }
  ForwardStatus forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x,
                        Eigen::MatrixXd* J_x_p = nullptr,
                        Eigen::MatrixXd* J_x_q = nullptr) const override;

  /// Both elbow branches for a target, joint limits not applied; empty when out of reach.
  static std::vector<Eigen::VectorXd> elbowBranches(const Eigen::VectorXd& p,
                                                    const Eigen::Vector2d& target);

  bool hasClosedFormInverse() const override { return true; }
  std::vector<Eigen::VectorXd> closedFormInverse(const Eigen::VectorXd& p,
                                                 const Eigen::VectorXd& target,
                                                 int stylus) const override;
  int posturesPerPoint() const override { return 2; }
  std::optional<std::array<double, 2>> reachRange(const Eigen::VectorXd& p) const override;
  std::vector<Eigen::VectorXd> configurationsAtReach(
      const Eigen::VectorXd& p, double reach,
      const std::vector<std::array<double, 2>>& limits) const override;
  /// Base, elbow, probe.
  std::vector<Eigen::VectorXd> skeleton(const Eigen::VectorXd& p,
                                        const Eigen::VectorXd& q) const override;

 private:
  std::vector<ParameterInfo> parameters_;
};

}  // namespace artcal
