#pragma once
// A serial arm in Denavit-Hartenberg form (docs/plan-format.md; docs/models.md section 2). Joint i
// contributes, with the joint variable added to theta_i (revolute) or d_i (prismatic),
//   standard (default):  A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i) [Ry(beta_i)]
//   modified (Craig):    A_i = Rx(alpha_i) Tx(a_i) [Ry(beta_i)] Rz(theta_i) Tz(d_i)
// where the Hayati tilt beta_i exists only on joints that carry it (it describes a small tilt
// between nearly parallel consecutive axes, where d is ill-defined). The probe centre sits at
// `probe` in the last frame. Parameters: j1.theta, j1.d, j1.a, j1.alpha[, j1.beta], ..., probe.x,
// probe.y, probe.z. Jacobians are the geometric ones (rotation about / translation along each
// elementary transform's axis), exact.
//
// With a compliance block (docs/compliance.md, model/joint_compliance.hpp): j1.compliance, ...,
// jn.compliance follow the probe; link k's mass centre is in frame k, the frame after A_k (beta
// included; modified convention alike), and the payload's in frame n.

#include <optional>

#include "artcal/core/enum_names.hpp"
#include "artcal/model/joint_compliance.hpp"
#include "artcal/model/mechanism.hpp"

namespace artcal {

enum class DHConvention { Standard, Modified };
/// The names of the machine block's "convention".
inline constexpr EnumNames<DHConvention, 2> kDHConventionNames{
    {{DHConvention::Standard, "standard"}, {DHConvention::Modified, "modified"}}};

struct DHJoint {
  JointKind kind = JointKind::Revolute;
  bool has_beta = false;  ///< the joint carries a Hayati beta parameter
};

class SerialDH final : public Mechanism, public JointCompliance {
 public:
  static constexpr int kMaxJoints = 32;

  /// Standard convention, no beta (4n + 3 parameters).
  explicit SerialDH(const std::vector<JointKind>& joints);
  /// Throws std::invalid_argument beyond kMaxJoints joints, or with a compliance block whose
  /// masses are not one per joint.
  SerialDH(std::vector<DHJoint> joints, DHConvention convention,
           std::optional<ComplianceSpec> compliance = std::nullopt);

  std::string modelName() const override { return "serial-dh"; }
  int dimension() const override { return 3; }
  int jointCount() const override { return static_cast<int>(joints_.size()); }
  JointKind jointKind(int joint) const override { return joints_[joint].kind; }
  const std::vector<ParameterInfo>& parameters() const override { return parameters_; }
  ForwardStatus forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x,
                        Eigen::MatrixXd* J_x_p = nullptr,
                        Eigen::MatrixXd* J_x_q = nullptr) const override;
  bool hasOrientation() const override { return true; }
  /// The tip frame is the last joint frame (the probe offset does not turn it).
  ForwardStatus forwardPose(const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x,
                            Eigen::Matrix3d& R, Eigen::MatrixXd* J_x_p = nullptr,
                            Eigen::MatrixXd* J_x_q = nullptr, Eigen::MatrixXd* J_w_p = nullptr,
                            Eigen::MatrixXd* J_w_q = nullptr) const override;
  /// The base, the origin of each joint frame (and the foot of its offset d), the probe.
  std::vector<Eigen::VectorXd> skeleton(const Eigen::VectorXd& p,
                                        const Eigen::VectorXd& q) const override;

  const JointCompliance* jointCompliance() const override { return compliance_ ? this : nullptr; }
  const std::vector<int>& complianceParameters() const override { return compliance_index_; }
  const ComplianceSpec& complianceSpec() const override { return *compliance_; }
  GravityGeometry gravityGeometry(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                  const Payload& payload) const override;

  DHConvention convention() const { return convention_; }
  bool hasBeta(int joint) const { return joints_[joint].has_beta; }
  /// Index in p of joint i's first parameter (theta); d, a, alpha[, beta] follow.
  int parameterOffset(int joint) const { return offsets_[joint]; }
  int probeParameterOffset() const { return offsets_.back(); }

 private:
  std::vector<DHJoint> joints_;
  DHConvention convention_;
  std::vector<int> offsets_;  ///< per joint, then the probe's
  std::vector<ParameterInfo> parameters_;
  std::optional<ComplianceSpec> compliance_;
  std::vector<int> compliance_index_;  ///< per joint, into p
};

}  // namespace artcal
