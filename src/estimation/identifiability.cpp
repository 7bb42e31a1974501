#include "artcal/estimation/identifiability.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

namespace artcal {

CountingCondition countingCondition(const Plan& plan, const std::vector<Placement>& placements) {
  CountingCondition count;
  count.N_p = plan.machine.calibratedCount();
  for (const Placement& placement : placements) {
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    count.N_b += artifact.valuedPerFeature() * static_cast<int>(placement.measurements.size());
    count.N_r += artifact.rigidDof();
  }
  count.satisfied = count.N_b - count.N_r >= count.N_p;
  if (!placements.empty()) {
    const Placement& first = placements.front();
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(first.artifact)];
    const int per = artifact.valuedPerFeature() * static_cast<int>(first.measurements.size()) -
                    artifact.rigidDof();
    if (per > 0) count.minimum_alike = (count.N_p + per - 1) / per;
  }
  return count;
}

namespace {

// A diagonal of the information below this fraction of the largest is rounding, not information.
constexpr double kUnobservedDiagonal = 1e-20;

// Reduced row-echelon form of the rows of B (each row a null vector), pivots taken in parameter
// order: a canonical, sparse basis of the null space.
Eigen::MatrixXd reducedRowEchelon(Eigen::MatrixXd B, double tolerance) {
  int row = 0;
  for (int col = 0; col < B.cols() && row < B.rows(); ++col) {
    Eigen::Index pivot;
    const double magnitude = B.col(col).tail(B.rows() - row).cwiseAbs().maxCoeff(&pivot);
    if (magnitude <= tolerance) continue;
    B.row(row).swap(B.row(row + static_cast<int>(pivot)));
    B.row(row) /= B(row, col);
    for (int r = 0; r < B.rows(); ++r) {
      if (r != row) B.row(r) -= B(r, col) * B.row(row);
    }
    ++row;
  }
  return B;
}

}  // namespace

Identifiability analyseIdentifiability(const Plan& plan, const std::vector<Placement>& placements,
                                       const Eigen::MatrixXd& information, double tolerance) {
  Identifiability result;
  result.counting = countingCondition(plan, placements);
  result.tolerance = tolerance;
  const int n = static_cast<int>(information.rows());
  // Scale to unit diagonal; a parameter nothing observes keeps a zero row and column. "Nothing"
  // includes rounding: a column that vanishes identically (a serial arm's last alpha with the
  // probe on that joint's x axis) leaves a diagonal some 1e-30 of the others, which scaling
  // would otherwise blow up to 1. Units (mm, rad) move diagonals by a few orders, never 1e20.
  const double largest_diagonal = n > 0 ? information.diagonal().cwiseAbs().maxCoeff() : 0.0;
  Eigen::VectorXd scale(n);
  for (int i = 0; i < n; ++i) {
    const double d = information(i, i);
    const bool observed = d > kUnobservedDiagonal * largest_diagonal && std::isfinite(d);
    scale[i] = observed ? 1.0 / std::sqrt(d) : 0.0;
  }
  const Eigen::MatrixXd scaled = scale.asDiagonal() * information * scale.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled);
  const Eigen::VectorXd& lambda = eig.eigenvalues();  // ascending
  const double largest = n > 0 ? lambda[n - 1] : 0.0;
  const double cutoff = tolerance * largest;
  std::vector<int> null;
  for (int i = 0; i < n; ++i) {
    if (!(lambda[i] > cutoff)) null.push_back(i);
  }
  result.deficiency = static_cast<int>(null.size());
  result.rank = n - result.deficiency;
  result.condition_number = result.deficiency == 0 && lambda[0] > 0.0
                                ? largest / lambda[0]
                                : std::numeric_limits<double>::infinity();
  if (null.empty()) return result;
  Eigen::MatrixXd basis(static_cast<int>(null.size()), n);
  for (std::size_t k = 0; k < null.size(); ++k) {
    basis.row(static_cast<int>(k)) = eig.eigenvectors().col(null[k]).transpose();
  }
  const Eigen::MatrixXd rref = reducedRowEchelon(basis, 1e-6);
  const auto& params = plan.machine.mechanism->parameters();
  for (int r = 0; r < rref.rows(); ++r) {
    const double largest_coefficient = rref.row(r).cwiseAbs().maxCoeff();
    if (largest_coefficient <= 0.0) continue;
    Combination combination;
    for (int i = 0; i < n; ++i) {
      const double c = rref(r, i) / largest_coefficient;
      if (std::abs(c) < 1e-6) continue;
      combination.names.push_back(
          params[static_cast<std::size_t>(plan.machine.calibrated[i])].name);
      combination.coefficients.push_back(c);
    }
    result.unidentifiable.push_back(std::move(combination));
  }
  return result;
}

}  // namespace artcal
