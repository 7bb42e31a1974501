#include "artcal/plan.hpp"

#include <stdexcept>

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

bool Region::contains(const Eigen::VectorXd& x) const {
  if (reach) {
    const double r = x.norm();
    if (r < (*reach)[0] || r > (*reach)[1]) return false;
  }
  if (box) {
    for (int i = 0; i < x.size(); ++i) {
      const double lo = std::min((*box)[0][i], (*box)[1][i]);
      const double hi = std::max((*box)[0][i], (*box)[1][i]);
      if (x[i] < lo || x[i] > hi) return false;
    }
  }
  return true;
}

int Plan::artifactIndex(const std::string& id) const {
  for (std::size_t i = 0; i < artifacts.size(); ++i) {
    if (artifacts[i].id == id) return static_cast<int>(i);
  }
  return -1;
}

std::string criterionName(Criterion criterion) {
  switch (criterion) {
    case Criterion::WorstTip:
      return "worst-tip";
    case Criterion::MeanTip:
      return "mean-tip";
    case Criterion::D:
      return "D";
    case Criterion::A:
      return "A";
    case Criterion::E:
      return "E";
  }
  throw std::logic_error("unknown criterion");
}

}  // namespace artcal
