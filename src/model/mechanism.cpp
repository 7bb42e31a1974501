#include "artcal/model/mechanism.hpp"

namespace artcal {

std::string forwardStatusName(ForwardStatus status) {
  switch (status) {
    case ForwardStatus::Ok:
      return "ok";
    case ForwardStatus::NotConverged:
      return "forward kinematics did not converge";
    case ForwardStatus::Singular:
      return "singular configuration";
  }
  return "unknown status";
}

void forwardOrThrow(const Mechanism& mechanism, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                    Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p, Eigen::MatrixXd* J_x_q) {
  const ForwardStatus status = mechanism.forward(p, q, x, J_x_p, J_x_q);
  if (status != ForwardStatus::Ok) throw KinematicsError(forwardStatusName(status));
}

int Mechanism::parameterIndex(const std::string& name) const {
  const auto& params = parameters();
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (params[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace artcal
