#pragma once
// Mechanism models: forward kinematics x = f(p, q) with exact Jacobians (docs/method.md section 1).
//
// A Mechanism is immutable. Parameters p are the model's full parameter vector in internal units
// (mm, rad); which of them are calibrated is the Machine's business, not the model's.

#include <Eigen/Core>
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "artcal/core/enum_names.hpp"
#include "artcal/core/error.hpp"
#include "artcal/core/units.hpp"

namespace artcal {

enum class JointKind { Revolute, Prismatic };

inline Quantity jointQuantity(JointKind kind) {
  return kind == JointKind::Revolute ? Quantity::Angle : Quantity::Length;
}

/// Outcome of a forward kinematics evaluation.
enum class ForwardStatus {
  Ok,
  NotConverged,  ///< the numerical solution did not reach its tolerance in its iterations
  Singular,      ///< the configuration is singular (no unique pose, no Jacobian)
};

/// What each status says in messages ("singular configuration").
inline constexpr EnumNames<ForwardStatus, 3> kForwardStatusNames{
    {{ForwardStatus::Ok, "ok"},
     {ForwardStatus::NotConverged, "forward kinematics did not converge"},
     {ForwardStatus::Singular, "singular configuration"}}};
/// "forward kinematics did not converge", "singular configuration".
std::string forwardStatusName(ForwardStatus status);

class AxisErrorFunctions;  // axis_error_functions.hpp
class OrientedPostures;    // closed_chain.hpp
class JointCompliance;     // joint_compliance.hpp

struct ParameterInfo {
  std::string name;
  Quantity quantity;
};

class Mechanism {
 public:
  virtual ~Mechanism() = default;

  /// The model's name in plan files ("planar2r", "serial-dh").
  virtual std::string modelName() const = 0;
  /// Dimension of the probe position x: 2 or 3.
  virtual int dimension() const = 0;
  virtual int jointCount() const = 0;
  virtual JointKind jointKind(int joint) const = 0;
  /// The readings' names, one per joint reading in order (a URDF chain's driving joints); empty
  /// when the model does not name them. Files of readings may select their columns by them.
  virtual std::vector<std::string> readingNames() const { return {}; }
  /// Every parameter of the model, in the order of p.
  virtual const std::vector<ParameterInfo>& parameters() const = 0;

  /// x = f(p, q). J_x_p (dimension x parameters) and J_x_q (dimension x joints) are filled when
  /// not null; they are resized as needed (no allocation when already the right size). A model
  /// whose forward kinematics is numerical (a closed chain solved by Newton) may fail: it says so
  /// in the status, and x and the Jacobians are then unspecified. Every caller handles it.
  [[nodiscard]] virtual ForwardStatus forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                              Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p = nullptr,
                                              Eigen::MatrixXd* J_x_q = nullptr) const = 0;

  /// Styli (probe offsets) a reading may choose (a Cartesian CMM's, docs/models.md section 4); 1
  /// for models with one probe.
  virtual int stylusCount() const { return 1; }
  /// The names a reading may choose its stylus by ("tip": a chain's tips, docs/urdf.md), one per
  /// stylus; empty when the model names none (its styli are chosen by index).
  virtual std::vector<std::string> stylusNames() const { return {}; }
  /// forward() through stylus `stylus` (0 .. stylusCount() - 1); single-probe models ignore it.
  [[nodiscard]] virtual ForwardStatus forwardStylus(int stylus, const Eigen::VectorXd& p,
                                                    const Eigen::VectorXd& q, Eigen::VectorXd& x,
                                                    Eigen::MatrixXd* J_x_p = nullptr,
                                                    Eigen::MatrixXd* J_x_q = nullptr) const {
    (void)stylus;
    return forward(p, q, x, J_x_p, J_x_q);
  }

  /// True when forwardPose() gives the tip frame's orientation besides its point (chain,
  /// serial-dh): the models an instrument with "measures": "pose" may read (instruments.md).
  virtual bool hasOrientation() const { return false; }
  /// forward() plus the tip frame's orientation R (base frame) and its spatial angular
  /// Jacobians: a step dp turns the frame by R <- exp([J_w_p dp]x) R (3 x parameters; J_w_q
  /// 3 x joints). Only for models with hasOrientation(); the others raise std::logic_error.
  [[nodiscard]] virtual ForwardStatus forwardPose(
      const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x, Eigen::Matrix3d& R,
      Eigen::MatrixXd* J_x_p = nullptr, Eigen::MatrixXd* J_x_q = nullptr,
      Eigen::MatrixXd* J_w_p = nullptr, Eigen::MatrixXd* J_w_q = nullptr) const;
  /// forwardPose() through stylus `stylus` (a chain's tip, docs/urdf.md); models with one
  /// probe frame ignore it.
  [[nodiscard]] virtual ForwardStatus forwardStylusPose(
      int stylus, const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x,
      Eigen::Matrix3d& R, Eigen::MatrixXd* J_x_p = nullptr, Eigen::MatrixXd* J_x_q = nullptr,
      Eigen::MatrixXd* J_w_p = nullptr, Eigen::MatrixXd* J_w_q = nullptr) const {
    (void)stylus;
    return forwardPose(p, q, x, R, J_x_p, J_x_q, J_w_p, J_w_q);
  }

  int parameterCount() const { return static_cast<int>(parameters().size()); }
  /// Index of a parameter by name, or -1.
  int parameterIndex(const std::string& name) const;

  // Capabilities. Every numerical module asks the model, never its name; the defaults suit a
  // general model (numerical IK, any number of postures, no reach profile, nothing drawn, no
  // family analysis).
  // How to add a family: include/artcal/io/model_registry.hpp.

  /// True when closedFormInverse() gives every solution for a target.
  virtual bool hasClosedFormInverse() const { return false; }
  /// Every joint vector putting probe `stylus` on `target`, joint limits not applied (e.g. both
  /// elbow branches of planar2r); empty when the target is out of reach. Models with
  /// hasClosedFormInverse() override it.
  virtual std::vector<Eigen::VectorXd> closedFormInverse(const Eigen::VectorXd& p,
                                                         const Eigen::VectorXd& target,
                                                         int stylus) const;
  /// The most distinct postures one point can be read in (planar2r: 2, its elbow branches);
  /// 0 when unbounded (redundant arms: any number, spread by the posture generator).
  virtual int posturesPerPoint() const { return 0; }
  /// [inner, outer] reach (distance of the probe from the base axis) when the tip uncertainty
  /// depends on the reach alone, so that a profile against reach describes the whole workspace
  /// (planar2r: |l1 - l2|, l1 + l2; seed Fig. 6); std::nullopt otherwise (no profile).
  virtual std::optional<std::array<double, 2>> reachRange(const Eigen::VectorXd& p) const;
  /// The configurations within `limits` that put the probe at distance `reach` from the base, one
  /// per branch, for the reach profile (whose rows take the worst of them).
  virtual std::vector<Eigen::VectorXd> configurationsAtReach(
      const Eigen::VectorXd& p, double reach,
      const std::vector<std::array<double, 2>>& limits) const;
  /// The model's postures are orientations of its moving body (the hexapod's platform): inverse
  /// kinematics and the posture generator draw orientations (inverse_kinematics.hpp); null for
  /// the others. The model returns itself, so that no caller names its family.
  virtual const OrientedPostures* orientedPostures() const { return nullptr; }
  /// The model's parameters are error functions of its axes' positions (a Cartesian CMM;
  /// axis_error_functions.hpp): the error-function bands and frame rotations of
  /// estimation/error_functions.hpp and the ISO 10360-2 length test ask for it; null for the
  /// others.
  virtual const AxisErrorFunctions* axisErrorFunctions() const { return nullptr; }
  /// The machine carries joint compliance (docs/compliance.md; a serial family whose machine
  /// block has a compliance block): its compliance parameters and gravity torques, applied to a
  /// reading by forwardLoaded (joint_compliance.hpp); null for the others.
  virtual const JointCompliance* jointCompliance() const { return nullptr; }
  /// The parameters are the ISO 230-7 location errors of a machine tool's axes, named
  /// E_<error>0<axis> (E_X0C, E_A0C, ...; docs/five-axis.md): evaluate and calibrate add the
  /// engineer's table (u in urad / um, the confounding index, the controller table).
  virtual bool hasLocationErrors() const { return false; }
  /// The joints a probing cycle commands (a machine tool's rotary axes, docs/five-axis.md): a
  /// planned reading holds them at their planned values and the other joints are solved for the
  /// point (inverse_kinematics.hpp, solveHoldingJoints); the planner chooses them as design
  /// variables (design_space.hpp) and `simulate` reads them exactly as planned. Empty for the
  /// others (every joint solved).
  virtual std::vector<int> commandedJoints() const { return {}; }
  /// The names an operator reads the joints by in a procedure (a machine tool's axis letters X,
  /// Y, Z, A, C); empty: q1, q2, ... (jointLabel).
  virtual std::vector<std::string> jointLabels() const { return {}; }
  /// Points to draw the mechanism by, from its base to the probe (e.g. joint-frame origins),
  /// each of dimension(); empty when the model is not drawn (the report then draws the probe
  /// positions only).
  virtual std::vector<Eigen::VectorXd> skeleton(const Eigen::VectorXd& p,
                                                const Eigen::VectorXd& q) const;
};

using MechanismPtr = std::shared_ptr<const Mechanism>;

/// The operator's name of joint `joint` (from 0): the model's jointLabels(), or "q1", "q2", ...
std::string jointLabel(const Mechanism& mechanism, int joint);

/// forward() for callers with no way to go on without x: a failure raises KinematicsError.
void forwardOrThrow(const Mechanism& mechanism, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                    Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p = nullptr,
                    Eigen::MatrixXd* J_x_q = nullptr, int stylus = 0);
/// forwardStylusPose() likewise: a failure raises KinematicsError.
void forwardPoseOrThrow(const Mechanism& mechanism, const Eigen::VectorXd& p,
                        const Eigen::VectorXd& q, Eigen::VectorXd& x, Eigen::Matrix3d& R,
                        Eigen::MatrixXd* J_x_p = nullptr, Eigen::MatrixXd* J_x_q = nullptr,
                        Eigen::MatrixXd* J_w_p = nullptr, Eigen::MatrixXd* J_w_q = nullptr,
                        int stylus = 0);

}  // namespace artcal
