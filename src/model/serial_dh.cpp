#include "artcal/model/serial_dh.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

#include "artcal/model/frame_turns.hpp"

namespace artcal {

namespace {

// Per-joint axes kept on the stack (no allocation per call).
using DhColumns =
    Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, SerialDH::kMaxJoints>;
using Jacobian = Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic>>;

std::vector<DHJoint> withoutBeta(const std::vector<JointKind>& kinds) {
  std::vector<DHJoint> out;
  for (JointKind kind : kinds) out.push_back({kind, false});
  return out;
}

// The world axes (and pivots, for rotations) of one joint's elementary transforms: what the
// geometric Jacobian needs once the tip is known.
struct JointAxes {
  DhColumns theta_axis,
      theta_pivot;        // Rz(theta) about theta_axis through theta_pivot; Tz(d) along it
  DhColumns a_direction;  // Tx(a)
  DhColumns alpha_axis, alpha_pivot;  // Rx(alpha)
  DhColumns beta_axis, beta_pivot;    // Ry(beta)
  explicit JointAxes(int n)
      : theta_axis(3, n),
        theta_pivot(3, n),
        a_direction(3, n),
        alpha_axis(3, n),
        alpha_pivot(3, n),
        beta_axis(3, n),
        beta_pivot(3, n) {}
};

}  // namespace

SerialDH::SerialDH(const std::vector<JointKind>& joints)
    : SerialDH(withoutBeta(joints), DHConvention::Standard) {}

SerialDH::SerialDH(std::vector<DHJoint> joints, DHConvention convention,
                   std::optional<ComplianceSpec> compliance)
    : joints_(std::move(joints)), convention_(convention), compliance_(std::move(compliance)) {
  if (joints_.size() > static_cast<std::size_t>(kMaxJoints)) {
    throw std::invalid_argument("serial-dh: at most " + std::to_string(kMaxJoints) + " joints");
  }
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    offsets_.push_back(static_cast<int>(parameters_.size()));
    // Built by insert/push_back: GCC 12 warns (-Wrestrict, falsely) on "j" + to_string(...).
    std::string prefix = std::to_string(i + 1);
    prefix.insert(prefix.begin(), 'j');
    prefix.push_back('.');
    parameters_.push_back({prefix + "theta", Quantity::Angle});
    parameters_.push_back({prefix + "d", Quantity::Length});
    parameters_.push_back({prefix + "a", Quantity::Length});
    parameters_.push_back({prefix + "alpha", Quantity::Angle});
    if (joints_[i].has_beta) parameters_.push_back({prefix + "beta", Quantity::Angle});
  }
  offsets_.push_back(static_cast<int>(parameters_.size()));
  parameters_.push_back({"probe.x", Quantity::Length});
  parameters_.push_back({"probe.y", Quantity::Length});
  parameters_.push_back({"probe.z", Quantity::Length});
  if (!compliance_) return;
  if (compliance_->masses.size() != joints_.size())
    throw std::invalid_argument("serial-dh: the compliance block needs one mass per joint");
  std::vector<std::string> names;
  std::vector<bool> revolute;
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    std::string name = std::to_string(i + 1);
    name.insert(name.begin(), 'j');
    names.push_back(name);
    revolute.push_back(joints_[i].kind == JointKind::Revolute);
  }
  appendComplianceParameters(names, revolute, parameters_, compliance_index_);
}

// Geometric Jacobian of the probe centre x: each elementary rotation contributes
// axis x (x - pivot), each translation its direction, all in the world frame at the moment the
// transform is applied; a revolute joint variable acts like theta_i, a prismatic one like d_i.
ForwardStatus SerialDH::forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p,
                                Eigen::MatrixXd* J_x_q) const {
  Eigen::Matrix3d R;
  return forwardPose(p, q, x, R, J_x_p, J_x_q);
}

// The angular Jacobians: each elementary rotation turns the tip frame about its world axis; the
// translations (d, a, the probe) do not turn it.
ForwardStatus SerialDH::forwardPose(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                    Eigen::VectorXd& x, Eigen::Matrix3d& R, Eigen::MatrixXd* J_x_p,
                                    Eigen::MatrixXd* J_x_q, Eigen::MatrixXd* J_w_p,
                                    Eigen::MatrixXd* J_w_q) const {
  const int n = jointCount();
  R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d o = Eigen::Vector3d::Zero();
  JointAxes axes(n);
  for (int i = 0; i < n; ++i) {
    const int k = offsets_[i];
    double theta = p[k], d = p[k + 1];
    (joints_[i].kind == JointKind::Revolute ? theta : d) += q[i];
    const double a = p[k + 2], alpha = p[k + 3];
    const double beta = joints_[i].has_beta ? p[k + 4] : 0.0;
    auto rotateZTranslateZ = [&] {
      axes.theta_axis.col(i) = R.col(2);
      axes.theta_pivot.col(i) = o;
      turnAboutZ(R, theta);
      o += R.col(2) * d;
    };
    auto translateXRotateX = [&] {
      axes.a_direction.col(i) = R.col(0);
      o += R.col(0) * a;
      axes.alpha_axis.col(i) = R.col(0);
      axes.alpha_pivot.col(i) = o;
      turnAboutX(R, alpha);
    };
    auto rotateY = [&] {
      axes.beta_axis.col(i) = R.col(1);
      axes.beta_pivot.col(i) = o;
      if (beta != 0.0) turnAboutY(R, beta);
    };
    if (convention_ == DHConvention::Standard) {
      rotateZTranslateZ();
      translateXRotateX();
      rotateY();
    } else {
      // Rx(alpha) Tx(a): alpha turns about the incoming x axis at the incoming origin.
      axes.alpha_axis.col(i) = R.col(0);
      axes.alpha_pivot.col(i) = o;
      turnAboutX(R, alpha);
      axes.a_direction.col(i) = R.col(0);
      o += R.col(0) * a;
      rotateY();
      rotateZTranslateZ();
    }
  }
  const Eigen::Vector3d tip = o + R * p.segment<3>(probeParameterOffset());
  x.resize(3);
  Eigen::Map<Eigen::Vector3d>(x.data()) = tip;
  auto turning = [&](const DhColumns& axis, const DhColumns& pivot, int i) -> Eigen::Vector3d {
    return tipColumn(true, axis.col(i), pivot.col(i), tip);
  };
  // Written through fixed-row maps: GCC 12 warns (-Warray-bounds, falsely) when fixed-size
  // vectors are assigned into blocks of a dynamic matrix under -march=native.
  if (J_x_p) {
    J_x_p->resize(3, parameterCount());
    Jacobian J(J_x_p->data(), 3, parameterCount());
    for (int i = 0; i < n; ++i) {
      const int k = offsets_[i];
      J.col(k) = turning(axes.theta_axis, axes.theta_pivot, i);
      J.col(k + 1) = axes.theta_axis.col(i);
      J.col(k + 2) = axes.a_direction.col(i);
      J.col(k + 3) = turning(axes.alpha_axis, axes.alpha_pivot, i);
      if (joints_[i].has_beta) J.col(k + 4) = turning(axes.beta_axis, axes.beta_pivot, i);
    }
    J.middleCols<3>(probeParameterOffset()) = R;
    for (const int c : compliance_index_) J.col(c).setZero();  // forwardLoaded writes them
  }
  if (J_x_q) {
    J_x_q->resize(3, n);
    Jacobian J(J_x_q->data(), 3, n);
    for (int i = 0; i < n; ++i) {
      J.col(i) = tipColumn(joints_[i].kind == JointKind::Revolute, axes.theta_axis.col(i),
                           axes.theta_pivot.col(i), tip);
    }
  }
  if (J_w_p) {
    J_w_p->setZero(3, parameterCount());
    Jacobian J(J_w_p->data(), 3, parameterCount());
    for (int i = 0; i < n; ++i) {
      const int k = offsets_[i];
      J.col(k) = axes.theta_axis.col(i);
      J.col(k + 3) = axes.alpha_axis.col(i);
      if (joints_[i].has_beta) J.col(k + 4) = axes.beta_axis.col(i);
    }
  }
  if (J_w_q) {
    J_w_q->setZero(3, n);
    Jacobian J(J_w_q->data(), 3, n);
    for (int i = 0; i < n; ++i) {
      if (joints_[i].kind == JointKind::Revolute) J.col(i) = axes.theta_axis.col(i);
    }
  }
  return ForwardStatus::Ok;
}

// docs/compliance.md section 2: joint i's axis is where Rz(theta_i) turns (standard: frame i-1's
// z; modified: after Rx Tx Ry), link i's centre in the frame after A_i, the payload's in frame n.
GravityGeometry SerialDH::gravityGeometry(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                          const Payload& payload) const {
  GravityGeometry out;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d o = Eigen::Vector3d::Zero();
  const int n = jointCount();
  for (int i = 0; i < n; ++i) {
    const int k = offsets_[i];
    double theta = p[k], d = p[k + 1];
    (joints_[i].kind == JointKind::Revolute ? theta : d) += q[i];
    const double a = p[k + 2], alpha = p[k + 3];
    const double beta = joints_[i].has_beta ? p[k + 4] : 0.0;
    auto rotateZTranslateZ = [&] {
      out.axes.push_back({o, R.col(2), joints_[i].kind == JointKind::Revolute, i, i, 1.0});
      turnAboutZ(R, theta);
      o += R.col(2) * d;
    };
    if (convention_ == DHConvention::Standard) {
      rotateZTranslateZ();
      o += R.col(0) * a;
      turnAboutX(R, alpha);
      if (beta != 0.0) turnAboutY(R, beta);
    } else {
      turnAboutX(R, alpha);
      o += R.col(0) * a;
      if (beta != 0.0) turnAboutY(R, beta);
      rotateZTranslateZ();
    }
    const MassPoint& link = compliance_->masses[static_cast<std::size_t>(i)];
    if (link.mass != 0.0) out.bodies.push_back({o + R * link.centre, link.mass, i});
  }
  if (payload.mass != 0.0 && n > 0)
    out.bodies.push_back({o + R * payload.centre, payload.mass, n - 1});
  return out;
}

// The frames of forward() without the Jacobians, for drawings.
std::vector<Eigen::VectorXd> SerialDH::skeleton(const Eigen::VectorXd& p,
                                                const Eigen::VectorXd& q) const {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d o = Eigen::Vector3d::Zero();
  std::vector<Eigen::VectorXd> points{o};
  for (int i = 0; i < jointCount(); ++i) {
    const int k = offsets_[i];
    double theta = p[k], d = p[k + 1];
    (joints_[i].kind == JointKind::Revolute ? theta : d) += q[i];
    const double a = p[k + 2], alpha = p[k + 3];
    const double beta = joints_[i].has_beta ? p[k + 4] : 0.0;
    if (convention_ == DHConvention::Standard) {
      turnAboutZ(R, theta);
      o += R.col(2) * d;
      points.push_back(o);
      o += R.col(0) * a;
      turnAboutX(R, alpha);
      if (beta != 0.0) turnAboutY(R, beta);
    } else {
      turnAboutX(R, alpha);
      o += R.col(0) * a;
      points.push_back(o);
      if (beta != 0.0) turnAboutY(R, beta);
      turnAboutZ(R, theta);
      o += R.col(2) * d;
    }
    points.push_back(o);
  }
  points.push_back(o + R * p.segment<3>(probeParameterOffset()));
  return points;
}

}  // namespace artcal
