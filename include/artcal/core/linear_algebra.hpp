#pragma once
// Eigen's dense decompositions that artcal uses in many files, compiled once.
//
// Naming Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> or Eigen::JacobiSVD<Eigen::MatrixXd> in a
// source file instantiates the whole solver there, several seconds of compile time per file and
// per build (Release, sanitizers, fuzzing). These thin classes have the same interface as
// Eigen's for what artcal needs and instantiate Eigen's solvers once, in
// src/core/linear_algebra.cpp. They are Eigen's algorithms, not copies of them.

#include <Eigen/Core>

namespace artcal {

/// Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>: eigenvalues in increasing order; the
/// eigenvectors (columns, orthonormal) unless `options` is Eigen::EigenvaluesOnly. A matrix with
/// a NaN or an infinite entry is not decomposed: info() is Eigen::NumericalIssue and every value
/// NaN (the sizes those of A).
class SymmetricEigenSolver {
 public:
  explicit SymmetricEigenSolver(const Eigen::MatrixXd& A, int options = Eigen::ComputeEigenvectors);

  const Eigen::VectorXd& eigenvalues() const { return eigenvalues_; }
  const Eigen::MatrixXd& eigenvectors() const { return eigenvectors_; }
  Eigen::ComputationInfo info() const { return info_; }

 private:
  Eigen::VectorXd eigenvalues_;
  Eigen::MatrixXd eigenvectors_;
  Eigen::ComputationInfo info_ = Eigen::Success;
};

/// The singular values of A, in decreasing order (Eigen::JacobiSVD).
Eigen::VectorXd singularValues(const Eigen::MatrixXd& A);

/// The numerical rank of A as Eigen::JacobiSVD::rank() with setThreshold(relative_threshold):
/// the singular values not below relative_threshold times the largest.
int numericalRank(const Eigen::MatrixXd& A, double relative_threshold);

}  // namespace artcal
