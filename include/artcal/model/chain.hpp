#pragma once
// A serial chain with URDF semantics (docs/models.md section 1). Joint i contributes
//   T_i(q_i) = Trans(xyz_i) Rot(rpy_i) M_i(q_i + offset_i),   Rot(r, p, y) = Rz(y) Ry(p) Rx(r),
// where M_i is a rotation about axis_i (revolute), a translation along it (prismatic) or nothing
// (fixed). x = f(p, q) is the origin of the last frame of T_1(q_1) ... T_n(q_n); the readings q are
// the movable joints' in chain order. Parameters per joint, named after it: NAME.x NAME.y NAME.z
// (mm), NAME.roll NAME.pitch NAME.yaw (rad inside) and, for a movable joint, NAME.offset. The axis
// is a unit vector and not a parameter (its tilt is the next frame's rpy). The chain is heavily
// over-parameterised on purpose; "calibrate": "identifiable" chooses what the data separates.
//
// Mimic joints (URDF <mimic>, instruments.md): a movable joint with a mimic has the value
// m q_J + c + offset_i, J its master; it is no reading of its own. The readings are one per
// driving joint: the movable joints that are not mimics, in chain order, with each master that
// is not on the chain (a virtual lifting column on a branch of its own) inserted where its first
// mimic joint stands. A mimic and its master are of one type (both revolute or both prismatic).
//
// A reversed joint is traversed from its URDF child link to its parent (a chain that runs up
// the URDF tree: a humanoid from its sole): it contributes the inverse
//   T_i(q_i)^-1 = M_i(-(q_i + offset_i)) Rot(rpy_i)^T Trans(-xyz_i),
// with the URDF's own parameters and reading (docs/urdf.md).
//
// Several tips (docs/urdf.md, "one machine, several tips"): each tip is a path of the chain's
// joints from the base (a shared torso, then one arm). The joints are listed once; each tip's
// forward kinematics runs along its own path (forwardStylus(tip, ...); forward() is tip 0), and
// the readings are every driving joint of the list. Without tips, one tip runs every joint.
//
// With a compliance block (docs/compliance.md, model/joint_compliance.hpp; one tip only): one
// parameter READING.compliance per reading after the geometric ones; the mass of chain joint i
// is the body on the frame reached after T_i (its URDF child link's, with the links folded into
// it; a reversed joint's URDF parent), its centre in that frame; the payload's in the last frame.
// A joint's torque is about the axis its reading turns (a reversed joint's negated); a mimic adds
// its torque times its multiplier to its master's reading (an off-chain master has none of its
// own).

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "artcal/core/enum_names.hpp"
#include "artcal/model/joint_compliance.hpp"
#include "artcal/model/mechanism.hpp"
#include "artcal/model/rotation_vector.hpp"

namespace artcal {

enum class ChainJointType { Revolute, Prismatic, Fixed };
/// The names of the machine block's joint "type".
inline constexpr EnumNames<ChainJointType, 3> kChainJointTypeNames{
    {{ChainJointType::Revolute, "revolute"},
     {ChainJointType::Prismatic, "prismatic"},
     {ChainJointType::Fixed, "fixed"}}};

/// A joint's coupling to its master: value = multiplier * q_master + offset.
struct ChainMimic {
  std::string joint;        ///< the master: a movable joint of the chain, or one off it
  double multiplier = 1.0;  ///< dimensionless (a mimic and its master are of one type)
  double offset = 0.0;      ///< rad (revolute) or mm (prismatic)
};

struct ChainJoint {
  std::string name;
  ChainJointType type = ChainJointType::Fixed;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  ///< normalised by the model; unused if fixed
  std::optional<ChainMimic> mimic = std::nullopt;   ///< movable joints only
  bool reversed = false;  ///< traversed child to parent: contributes T(q)^-1 (URDF parameters)
};

/// One tip of a machine with several: its name and its path, chain joint indices from the base.
struct ChainTip {
  std::string name;
  std::vector<int> joints;
};

/// Why a chain's mimics do not resolve: the chain index of the mimic joint and what to check.
struct ChainMimicProblem {
  int joint = 0;
  std::string message;
};

/// One reading of the chain: a driving joint (on the chain, or a master off it).
struct ChainReading {
  std::string name;
  ChainJointType type = ChainJointType::Revolute;
  int chain_joint = -1;  ///< its index among joints(); -1 for a master off the chain
};

class Chain final : public Mechanism, public JointCompliance {
 public:
  static constexpr int kMaxJoints = 64;
  static constexpr int kOriginParameters = 6;  ///< x y z roll pitch yaw

  /// Throws std::invalid_argument on an empty chain, more than kMaxJoints joints, an empty or
  /// repeated name, a zero axis of a movable joint, or a mimic that is not a coupling of two
  /// movable joints of one type (on a fixed joint, of itself, of a fixed joint or of a mimic).
  /// `tips` (none: one tip through every joint in order) must each name a non-empty path of
  /// distinct joint indices, the names distinct and non-empty, and every joint on some path.
  /// A compliance block needs one tip and one mass per joint.
  explicit Chain(std::vector<ChainJoint> joints, std::vector<ChainTip> tips = {},
                 std::optional<ComplianceSpec> compliance = std::nullopt);

  std::string modelName() const override { return "chain"; }
  int dimension() const override { return 3; }
  int jointCount() const override { return static_cast<int>(readings_.size()); }
  JointKind jointKind(int joint) const override;
  std::vector<std::string> readingNames() const override {
    std::vector<std::string> names;
    for (const ChainReading& reading : readings_) names.push_back(reading.name);
    return names;
  }
  const std::vector<ParameterInfo>& parameters() const override { return parameters_; }
  ForwardStatus forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x,
                        Eigen::MatrixXd* J_x_p = nullptr,
                        Eigen::MatrixXd* J_x_q = nullptr) const override;
  /// One stylus per tip (tip 0 when the machine names none).
  int stylusCount() const override { return static_cast<int>(tips_.size()); }
  /// The tips' names when the machine names them.
  std::vector<std::string> stylusNames() const override;
  ForwardStatus forwardStylus(int stylus, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                              Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p = nullptr,
                              Eigen::MatrixXd* J_x_q = nullptr) const override;
  bool hasOrientation() const override { return true; }
  /// The tip frame is the last joint's frame (its origin is the probe); tip 0's.
  ForwardStatus forwardPose(const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x,
                            Eigen::Matrix3d& R, Eigen::MatrixXd* J_x_p = nullptr,
                            Eigen::MatrixXd* J_x_q = nullptr, Eigen::MatrixXd* J_w_p = nullptr,
                            Eigen::MatrixXd* J_w_q = nullptr) const override;
  /// forwardTipPose(stylus, ...): the tip frame of tip `stylus`.
  ForwardStatus forwardStylusPose(int stylus, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                  Eigen::VectorXd& x, Eigen::Matrix3d& R,
                                  Eigen::MatrixXd* J_x_p = nullptr,
                                  Eigen::MatrixXd* J_x_q = nullptr,
                                  Eigen::MatrixXd* J_w_p = nullptr,
                                  Eigen::MatrixXd* J_w_q = nullptr) const override {
    return forwardTipPose(stylus, p, q, x, R, J_x_p, J_x_q, J_w_p, J_w_q);
  }
  /// The base, each joint frame's origin in turn, the probe (for drawings).
  std::vector<Eigen::VectorXd> skeleton(const Eigen::VectorXd& p,
                                        const Eigen::VectorXd& q) const override;

  const JointCompliance* jointCompliance() const override { return compliance_ ? this : nullptr; }
  const std::vector<int>& complianceParameters() const override { return compliance_index_; }
  const ComplianceSpec& complianceSpec() const override { return *compliance_; }
  GravityGeometry gravityGeometry(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                  const Payload& payload) const override;

  /// Every joint of the chain (fixed ones included), in order.
  const std::vector<ChainJoint>& joints() const { return joints_; }
  /// Index in p of chain joint i's x; y z roll pitch yaw follow, then offset if it is movable.
  int parameterOffset(int chain_joint) const { return offsets_[chain_joint]; }
  static bool isMovable(ChainJointType type) { return type != ChainJointType::Fixed; }
  /// The first mimic of `joints` that is not a coupling of two movable joints of one type (on a
  /// fixed joint, of itself, of a fixed joint or of a mimic, of another type; the mimics of a
  /// master off the chain of different types); std::nullopt when every mimic resolves.
  static std::optional<ChainMimicProblem> mimicProblem(const std::vector<ChainJoint>& joints);
  /// The readings (driving joints), in order.
  const std::vector<ChainReading>& readings() const { return readings_; }
  /// The tips (one, unnamed and through every joint, when the machine names none).
  const std::vector<ChainTip>& tips() const { return tips_; }
  /// True when the machine names its tips (the machine block's "tips").
  bool namesTips() const { return named_tips_; }
  /// forwardPose() along tip `tip`'s path.
  ForwardStatus forwardTipPose(int tip, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                               Eigen::VectorXd& x, Eigen::Matrix3d& R,
                               Eigen::MatrixXd* J_x_p = nullptr, Eigen::MatrixXd* J_x_q = nullptr,
                               Eigen::MatrixXd* J_w_p = nullptr,
                               Eigen::MatrixXd* J_w_q = nullptr) const;

 private:
  /// How a movable joint's value follows the readings: scale * q[reading] + bias + its offset.
  struct Coupling {
    int reading = 0;
    double scale = 1.0;
    double bias = 0.0;
  };
  void resolveReadings();
  void checkTips();
  double jointValue(int chain_joint, const Eigen::VectorXd& p, const Eigen::VectorXd& q) const;

  std::vector<ChainJoint> joints_;
  std::vector<ChainReading> readings_;
  std::vector<Coupling> couplings_;  ///< per chain joint (unused for fixed ones)
  std::vector<ChainTip> tips_;
  bool named_tips_ = false;
  std::vector<int> offsets_;
  std::vector<ParameterInfo> parameters_;
  std::optional<ComplianceSpec> compliance_;
  std::vector<int> compliance_index_;  ///< per reading, into p
};

}  // namespace artcal
