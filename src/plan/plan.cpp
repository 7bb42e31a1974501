#include "artcal/plan/plan.hpp"

#include <filesystem>
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
  }
  throw std::logic_error("unknown criterion");
}

ReadingLocation readingLocation(const Plan& plan, std::size_t placement, std::size_t reading) {
  const Measurement& m = plan.placements.at(placement).measurements.at(reading);
  if (m.csv_row > 0) {
    const std::filesystem::path csv(m.csv);
    const std::filesystem::path file =
        csv.is_absolute() ? csv : std::filesystem::path(plan.source).parent_path() / csv;
    return {file.lexically_normal().string(), "row " + std::to_string(m.csv_row)};
  }
  return {plan.source,
          "/placements/" + std::to_string(placement) + "/measurements/" + std::to_string(reading)};
}

}  // namespace artcal
