#include "artcal/plan/plan.hpp"

#include <stdexcept>

namespace artcal {

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
    case Criterion::Pass:
      return "pass";
  }
  throw std::logic_error("unknown criterion");
}

}  // namespace artcal
