#include "artcal/core/linear_algebra.hpp"

#include "artcal/core/dense_decompositions.hpp"
#include <limits>

namespace artcal {

SymmetricEigenSolver::SymmetricEigenSolver(const Eigen::MatrixXd& A, int options) {
  if (A.size() == 0) return;  // nothing to decompose: empty results, info() Success
  if (!A.allFinite()) {
    // Eigen's QR iteration on NaN or inf does not converge and leaves its results unspecified
    // (issue 19: an out-of-bounds read downstream). Results of the right sizes, all NaN, and
    // info() NumericalIssue: a caller that checks info() or the values' finiteness can answer.
    info_ = Eigen::NumericalIssue;
    eigenvalues_ = Eigen::VectorXd::Constant(A.rows(), std::numeric_limits<double>::quiet_NaN());
    if ((options & Eigen::ComputeEigenvectors) != 0)
      eigenvectors_ =
          Eigen::MatrixXd::Constant(A.rows(), A.cols(), std::numeric_limits<double>::quiet_NaN());
    return;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(A, options);
  info_ = solver.info();
  eigenvalues_ = solver.eigenvalues();
  if ((options & Eigen::ComputeEigenvectors) != 0) eigenvectors_ = solver.eigenvectors();
}

Eigen::VectorXd singularValues(const Eigen::MatrixXd& A) {
  return Eigen::JacobiSVD<Eigen::MatrixXd>(A).singularValues();
}

int numericalRank(const Eigen::MatrixXd& A, double relative_threshold) {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A);
  svd.setThreshold(relative_threshold);
  return static_cast<int>(svd.rank());
}

}  // namespace artcal
