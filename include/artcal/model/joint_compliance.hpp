#pragma once
// Joint compliance under gravity and payload (docs/compliance.md): a serial family's optional
// block of non-geometric parameters, one compliance C_r per reading, after the geometric ones.
//
// How a reading's load reaches the forward kinematics. The torques are fixed numbers per reading
// (docs/compliance.md section 2): gravity on the links' masses and on the reading's payload, at
// the joints as read, with the machine's NOMINAL geometry. A family's forward(p, q) stays the
// geometric model at the joints it is given (its compliance columns of J_x_p are zero); the
// reading's deflection is applied outside it, once for every family, by forwardLoaded():
//   tau = model.gravityTorques(nominal, q, payload)     (once per reading: plan/plan.hpp,
//                                                         readingTorques)
//   x   = f(p, q + C tau),  dx/dC_r = (dx/dq_r) tau_r   (forwardLoaded below)
// C_r tau_r is in rad or mm (C inside in rad/(N m) or mm/N), added to the reading in internal
// units. The encoder term uses J_q at the deflected reading; the C dtau/dq term is neglected
// (docs/compliance.md section 3), so J_x_q is the geometric one at q + C tau.
//
// A family with compliance returns itself from Mechanism::jointCompliance() and lists its masses
// by body: a body is what rides on the frame reached after one of the family's elementary joints
// (a serial-dh joint, a chain joint fixed or not), folded there by the codec; bodies before the
// first moving joint exert no torque on any joint.

#include <Eigen/Core>
#include <string>
#include <string_view>
#include <vector>

#include "artcal/core/units.hpp"
#include "artcal/model/mechanism.hpp"

namespace artcal {

/// The standard gravity the machine file's compliance block defaults to, m/s^2, base frame.
inline const Eigen::Vector3d kDefaultGravity(0.0, 0.0, -9.81);

/// A mass at a centre: kg, and mm in the frame the owner states (a body's frame, the tip frame).
struct MassPoint {
  double mass = 0.0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
};

/// A payload (docs/compliance.md section 1): part of the last moving link, centre in the tip
/// frame. No mass: no payload.
using Payload = MassPoint;

/// The compliance block of a serial family as its codec reads it: the masses per body (the
/// family's joint order, massless where none is given) and gravity in the base frame (m/s^2).
struct ComplianceSpec {
  std::vector<MassPoint> masses;
  Eigen::Vector3d gravity = kDefaultGravity;
};

/// Units of a compliance parameter: deg per N m for a revolute reading, mm per N for a
/// prismatic one (internal: rad per N m, mm per N).
inline constexpr Quantity kDegreePerNewtonMetre =
    Quantity::coefficient(Quantity::Kind::Angle, "deg/(N m)", kDegree);
inline constexpr Quantity kMillimetrePerNewton =
    Quantity::coefficient(Quantity::Kind::Length, "mm/N", 1.0);
/// The unit of the torque (force) a compliance multiplies: "N m" or "N".
inline constexpr std::string_view torqueUnit(bool revolute) {
  return revolute ? "N m" : "N";
}

/// The base-frame geometry the torques need at one reading (docs/compliance.md section 2), as a
/// family computes it: each moving joint's axis and each body's centre, with their positions
/// along the chain (a body loads the joints at or before its position).
struct GravityGeometry {
  struct Axis {
    Eigen::Vector3d point;      ///< mm, base frame
    Eigen::Vector3d direction;  ///< unit, +z of the joint as the family defines it
    bool revolute = true;
    int position = 0;    ///< along the chain
    int reading = 0;     ///< the reading that drives it
    double scale = 1.0;  ///< d joint / d reading (a mimic's multiplier)
  };
  struct Body {
    Eigen::Vector3d centre;  ///< mm, base frame
    double mass = 0.0;       ///< kg
    int position = 0;        ///< the joint it rides after (along the chain)
  };
  std::vector<Axis> axes;
  std::vector<Body> bodies;
};

/// tau per reading (N m or N): tau_i = sum over bodies beyond joint i of ((r_k - o_i) x m_k g) .
/// z_i, lengths in m (revolute), f_i = sum of (m_k g) . z_i (prismatic); a reading's torque is the
/// sum over the joints it drives of scale times theirs (a mimic's, by virtual work).
Eigen::VectorXd torquesFromGeometry(const GravityGeometry& geometry, const Eigen::Vector3d& gravity,
                                    int readings);

/// The capability a serial family with a compliance block returns from
/// Mechanism::jointCompliance().
class JointCompliance {
 public:
  virtual ~JointCompliance() = default;
  /// Index in p of each reading's compliance C_r (rad/(N m) or mm/N inside).
  virtual const std::vector<int>& complianceParameters() const = 0;
  /// The masses and gravity the codec read.
  virtual const ComplianceSpec& complianceSpec() const = 0;
  /// The axes and bodies (the payload last, when it has a mass) at parameters p and readings q.
  virtual GravityGeometry gravityGeometry(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                          const Payload& payload) const = 0;
  /// tau per reading at q with the parameters p (the machine's nominal ones, section 2).
  Eigen::VectorXd gravityTorques(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                 const Payload& payload) const;
};

/// True when parameter `index` of `mechanism` is a compliance.
bool isComplianceParameter(const Mechanism& mechanism, int index);

/// The parameters of a compliance block: "<reading name>.compliance" per reading, after
/// `geometric` (appended to it).
void appendComplianceParameters(const std::vector<std::string>& reading_names,
                                const std::vector<bool>& revolute,
                                std::vector<ParameterInfo>& parameters, std::vector<int>& indices);

/// forwardStylus() of a reading under torques `tau` (per reading; empty: no load): the joints
/// deflected, q + C tau, and J_x_p's compliance columns (dx/dq_r) tau_r. A model without
/// compliance ignores tau.
[[nodiscard]] ForwardStatus forwardLoaded(const Mechanism& mechanism, int stylus,
                                          const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                          const Eigen::VectorXd& tau, Eigen::VectorXd& x,
                                          Eigen::MatrixXd* J_x_p = nullptr,
                                          Eigen::MatrixXd* J_x_q = nullptr);
/// forwardStylusPose() likewise (the angular columns of compliance: (dw/dq_r) tau_r).
[[nodiscard]] ForwardStatus forwardLoadedPose(const Mechanism& mechanism, int stylus,
                                              const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                              const Eigen::VectorXd& tau, Eigen::VectorXd& x,
                                              Eigen::Matrix3d& R, Eigen::MatrixXd* J_x_p = nullptr,
                                              Eigen::MatrixXd* J_x_q = nullptr,
                                              Eigen::MatrixXd* J_w_p = nullptr,
                                              Eigen::MatrixXd* J_w_q = nullptr);

}  // namespace artcal
