#include "artcal/model/machine.hpp"

namespace artcal {

Eigen::VectorXd Machine::calibratedValues(const Eigen::VectorXd& full) const {
  Eigen::VectorXd values(calibratedCount());
  for (int k = 0; k < calibratedCount(); ++k) values[k] = full[calibrated[k]];
  return values;
}

Eigen::VectorXd Machine::withCalibrated(const Eigen::VectorXd& full,
                                        const Eigen::VectorXd& values) const {
  Eigen::VectorXd out = full;
  for (int k = 0; k < calibratedCount(); ++k) out[calibrated[k]] = values[k];
  return out;
}

bool Machine::withinLimits(const Eigen::VectorXd& q) const {
  for (int i = 0; i < q.size(); ++i) {
    if (q[i] < joint_limits[i][0] || q[i] > joint_limits[i][1]) return false;
  }
  return true;
}

}  // namespace artcal
