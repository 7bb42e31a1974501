#include "artcal/core/linear_algebra.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

namespace artcal {

SymmetricEigenSolver::SymmetricEigenSolver(const Eigen::MatrixXd& A, int options) {
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
