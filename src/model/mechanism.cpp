#include "artcal/model/mechanism.hpp"

#include <stdexcept>

namespace artcal {

std::string forwardStatusName(ForwardStatus status) {
  return nameOf(kForwardStatusNames, status);
}

std::string jointLabel(const Mechanism& mechanism, int joint) {
  const std::vector<std::string> labels = mechanism.jointLabels();
  if (joint >= 0 && joint < static_cast<int>(labels.size()))
    return labels[static_cast<std::size_t>(joint)];
  std::string label = "q";  // appended, not "q" + ...: GCC 12's -Wrestrict false positive
  label += std::to_string(joint + 1);
  return label;
}

void forwardOrThrow(const Mechanism& mechanism, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                    Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p, Eigen::MatrixXd* J_x_q,
                    int stylus) {
  const ForwardStatus status = mechanism.forwardStylus(stylus, p, q, x, J_x_p, J_x_q);
  if (status != ForwardStatus::Ok) throw KinematicsError(forwardStatusName(status));
}

void forwardPoseOrThrow(const Mechanism& mechanism, const Eigen::VectorXd& p,
                        const Eigen::VectorXd& q, Eigen::VectorXd& x, Eigen::Matrix3d& R,
                        Eigen::MatrixXd* J_x_p, Eigen::MatrixXd* J_x_q, Eigen::MatrixXd* J_w_p,
                        Eigen::MatrixXd* J_w_q, int stylus) {
  const ForwardStatus status =
      mechanism.forwardStylusPose(stylus, p, q, x, R, J_x_p, J_x_q, J_w_p, J_w_q);
  if (status != ForwardStatus::Ok) throw KinematicsError(forwardStatusName(status));
}

int Mechanism::parameterIndex(const std::string& name) const {
  const auto& params = parameters();
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (params[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

std::vector<Eigen::VectorXd> Mechanism::closedFormInverse(const Eigen::VectorXd&,
                                                          const Eigen::VectorXd&, int) const {
  return {};
}

std::optional<std::array<double, 2>> Mechanism::reachRange(const Eigen::VectorXd&) const {
  return std::nullopt;
}

std::vector<Eigen::VectorXd> Mechanism::configurationsAtReach(
    const Eigen::VectorXd&, double, const std::vector<std::array<double, 2>>&) const {
  return {};
}

ForwardStatus Mechanism::forwardPose(const Eigen::VectorXd&, const Eigen::VectorXd&,
                                     Eigen::VectorXd&, Eigen::Matrix3d&, Eigen::MatrixXd*,
                                     Eigen::MatrixXd*, Eigen::MatrixXd*, Eigen::MatrixXd*) const {
  throw std::logic_error("model " + modelName() + " gives no orientation (hasOrientation())");
}

std::vector<Eigen::VectorXd> Mechanism::skeleton(const Eigen::VectorXd&,
                                                 const Eigen::VectorXd&) const {
  return {};
}

}  // namespace artcal
