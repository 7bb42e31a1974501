#include "artcal/model/joint_compliance.hpp"

#include <Eigen/Geometry>
#include <algorithm>

namespace artcal {

// docs/compliance.md section 2: lengths in m for the moment arm (mm / 1000).
Eigen::VectorXd torquesFromGeometry(const GravityGeometry& geometry, const Eigen::Vector3d& gravity,
                                    int readings) {
  Eigen::VectorXd tau = Eigen::VectorXd::Zero(readings);
  for (const GravityGeometry::Axis& axis : geometry.axes) {
    double own = 0.0;
    for (const GravityGeometry::Body& body : geometry.bodies) {
      if (body.position < axis.position) continue;
      const Eigen::Vector3d force = body.mass * gravity;
      own += axis.revolute ? ((body.centre - axis.point) / 1000.0).cross(force).dot(axis.direction)
                           : force.dot(axis.direction);
    }
    tau[axis.reading] += axis.scale * own;
  }
  return tau;
}

Eigen::VectorXd JointCompliance::gravityTorques(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                                const Payload& payload) const {
  return torquesFromGeometry(gravityGeometry(p, q, payload), complianceSpec().gravity,
                             static_cast<int>(q.size()));
}

bool isComplianceParameter(const Mechanism& mechanism, int index) {
  const JointCompliance* compliance = mechanism.jointCompliance();
  if (!compliance) return false;
  const std::vector<int>& c = compliance->complianceParameters();
  return std::find(c.begin(), c.end(), index) != c.end();
}

void appendComplianceParameters(const std::vector<std::string>& reading_names,
                                const std::vector<bool>& revolute,
                                std::vector<ParameterInfo>& parameters, std::vector<int>& indices) {
  indices.clear();
  for (std::size_t r = 0; r < reading_names.size(); ++r) {
    indices.push_back(static_cast<int>(parameters.size()));
    std::string name = reading_names[r];  // appended: GCC 12's -Wrestrict false positive
    name.append(".compliance");
    parameters.push_back({name, revolute[r] ? kDegreePerNewtonMetre : kMillimetrePerNewton});
  }
}

namespace {

// q + C tau (internal units), or nothing to do (no compliance, no load).
bool deflect(const Mechanism& mechanism, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
             const Eigen::VectorXd& tau, Eigen::VectorXd& deflected) {
  const JointCompliance* compliance = mechanism.jointCompliance();
  if (!compliance || tau.size() == 0) return false;
  const std::vector<int>& index = compliance->complianceParameters();
  deflected = q;
  for (int r = 0; r < q.size(); ++r) deflected[r] += p[index[static_cast<std::size_t>(r)]] * tau[r];
  return true;
}

// d/dC_r = (d/dq_r) tau_r (docs/compliance.md section 3).
void complianceColumns(const Mechanism& mechanism, const Eigen::VectorXd& tau,
                       const Eigen::MatrixXd& J_q, Eigen::MatrixXd& J_p) {
  const std::vector<int>& index = mechanism.jointCompliance()->complianceParameters();
  for (int r = 0; r < J_q.cols(); ++r)
    J_p.col(index[static_cast<std::size_t>(r)]) = J_q.col(r) * tau[r];
}

}  // namespace

ForwardStatus forwardLoaded(const Mechanism& mechanism, int stylus, const Eigen::VectorXd& p,
                            const Eigen::VectorXd& q, const Eigen::VectorXd& tau,
                            Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p, Eigen::MatrixXd* J_x_q) {
  thread_local Eigen::VectorXd deflected;
  if (!deflect(mechanism, p, q, tau, deflected))
    return mechanism.forwardStylus(stylus, p, q, x, J_x_p, J_x_q);
  thread_local Eigen::MatrixXd own_J_q;
  Eigen::MatrixXd* J_q = J_x_q ? J_x_q : (J_x_p ? &own_J_q : nullptr);
  const ForwardStatus status = mechanism.forwardStylus(stylus, p, deflected, x, J_x_p, J_q);
  if (status == ForwardStatus::Ok && J_x_p) complianceColumns(mechanism, tau, *J_q, *J_x_p);
  return status;
}

ForwardStatus forwardLoadedPose(const Mechanism& mechanism, int stylus, const Eigen::VectorXd& p,
                                const Eigen::VectorXd& q, const Eigen::VectorXd& tau,
                                Eigen::VectorXd& x, Eigen::Matrix3d& R, Eigen::MatrixXd* J_x_p,
                                Eigen::MatrixXd* J_x_q, Eigen::MatrixXd* J_w_p,
                                Eigen::MatrixXd* J_w_q) {
  thread_local Eigen::VectorXd deflected;
  if (!deflect(mechanism, p, q, tau, deflected))
    return mechanism.forwardStylusPose(stylus, p, q, x, R, J_x_p, J_x_q, J_w_p, J_w_q);
  thread_local Eigen::MatrixXd own_J_q, own_J_w_q;
  Eigen::MatrixXd* J_q = J_x_q ? J_x_q : (J_x_p ? &own_J_q : nullptr);
  Eigen::MatrixXd* J_wq = J_w_q ? J_w_q : (J_w_p ? &own_J_w_q : nullptr);
  const ForwardStatus status =
      mechanism.forwardStylusPose(stylus, p, deflected, x, R, J_x_p, J_q, J_w_p, J_wq);
  if (status != ForwardStatus::Ok) return status;
  if (J_x_p) complianceColumns(mechanism, tau, *J_q, *J_x_p);
  if (J_w_p) complianceColumns(mechanism, tau, *J_wq, *J_w_p);
  return status;
}

}  // namespace artcal
