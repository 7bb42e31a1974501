#include "artcal/normal_matrix.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace artcal {

GlobalLayout GlobalLayout::of(const Plan& plan) {
  GlobalLayout layout;
  layout.parameters = plan.machine.calibratedCount();
  std::vector<double> sigmas;
  for (const Artifact& artifact : plan.artifacts) {
    layout.artifact_offset.push_back(layout.parameters + static_cast<int>(sigmas.size()));
    for (const SystematicError& err : artifact.systematic) sigmas.push_back(err.sigma);
  }
  layout.c_sigma = Eigen::Map<Eigen::VectorXd>(sigmas.data(), static_cast<int>(sigmas.size()));
  return layout;
}

Eigen::VectorXd PlacementElimination::rigidStep(const Eigen::VectorXd& dg) const {
  Eigen::VectorXd local(static_cast<int>(columns.size()));
  for (std::size_t i = 0; i < columns.size(); ++i) local[static_cast<int>(i)] = dg[columns[i]];
  return -(M_rr_pinv * (g_r + M_rg * local));
}

Eigen::MatrixXd symmetricPseudoInverse(const Eigen::MatrixXd& M, double relative_tolerance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(M);
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  const double cutoff = relative_tolerance * std::max(lambda.cwiseAbs().maxCoeff(), 0.0);
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(lambda.size());
  for (int i = 0; i < lambda.size(); ++i) {
    if (lambda[i] > cutoff && lambda[i] > 0.0) inverse[i] = 1.0 / lambda[i];
  }
  return eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
}

namespace {

// (A_r^T A_r)^-1 by Cholesky when every pivot keeps a fair share of its diagonal, otherwise the
// pseudo-inverse (a rigid direction that no valued coordinate sees).
void invertRigidBlock(const Eigen::MatrixXd& M, Eigen::MatrixXd& inverse) {
  const Eigen::LLT<Eigen::MatrixXd> llt(M);
  bool well_posed = llt.info() == Eigen::Success;
  if (well_posed) {
    const Eigen::VectorXd pivots = llt.matrixLLT().diagonal().array().square();
    well_posed = (pivots.array() > 1e-10 * M.diagonal().array()).all();
  }
  if (well_posed) {
    inverse.setIdentity(M.rows(), M.cols());
    llt.solveInPlace(inverse);
  } else {
    inverse = symmetricPseudoInverse(M);
  }
}

}  // namespace

NormalMatrixReducer::NormalMatrixReducer(const GlobalLayout& layout) : layout_(layout) {
  reset();
}

void NormalMatrixReducer::reset() {
  N_.setZero(layout_.size(), layout_.size());
  b_.setZero(layout_.size());
  chi2_ = 0.0;
}

void NormalMatrixReducer::add(const ObservationBlock& block, int artifact_index,
                              PlacementElimination* elimination) {
  const int n_p = layout_.parameters;
  const int n_c = static_cast<int>(block.A_c.cols());
  const int n_g = n_p + n_c;
  const int c_offset = layout_.artifact_offset[static_cast<std::size_t>(artifact_index)];
  A_g_.resize(block.rows(), n_g);
  A_g_.leftCols(n_p) = block.A_p;
  if (n_c > 0) A_g_.rightCols(n_c) = block.A_c;

  M_rr_.noalias() = block.A_r.transpose() * block.A_r;
  invertRigidBlock(M_rr_, M_rr_pinv_);
  M_rg_.noalias() = block.A_r.transpose() * A_g_;
  X_.noalias() = M_rr_pinv_ * M_rg_;
  // Schur complement of r_j (method.md section 3).
  Eigen::MatrixXd contribution = A_g_.transpose() * A_g_;
  contribution.noalias() -= M_rg_.transpose() * X_;

  columns_.resize(static_cast<std::size_t>(n_g));
  for (int i = 0; i < n_p; ++i) columns_[static_cast<std::size_t>(i)] = i;
  for (int i = 0; i < n_c; ++i) columns_[static_cast<std::size_t>(n_p + i)] = c_offset + i;
  if (n_c == 0) {
    N_.topLeftCorner(n_p, n_p) += contribution;
  } else {
    for (int i = 0; i < n_g; ++i) {
      for (int j = 0; j < n_g; ++j) N_(columns_[i], columns_[j]) += contribution(i, j);
    }
  }
  if (block.e.size() == block.rows()) {
    g_r_.noalias() = block.A_r.transpose() * block.e;
    const Eigen::VectorXd reduced = A_g_.transpose() * block.e - X_.transpose() * g_r_;
    for (int i = 0; i < n_g; ++i) b_[columns_[i]] -= reduced[i];
    chi2_ += block.e.squaredNorm();
  }
  if (elimination) {
    elimination->M_rr_pinv = M_rr_pinv_;
    elimination->M_rg = M_rg_;
    elimination->g_r = block.e.size() == block.rows() ? g_r_ : Eigen::VectorXd::Zero(M_rr_.rows());
    elimination->columns = columns_;
  }
}

Eigen::MatrixXd NormalMatrixReducer::normalWithPrior() const {
  Eigen::MatrixXd N = N_;
  const int n_p = layout_.parameters;
  for (int i = 0; i < layout_.systematicCount(); ++i) {
    N(n_p + i, n_p + i) += 1.0 / (layout_.c_sigma[i] * layout_.c_sigma[i]);
  }
  return N;
}

Eigen::MatrixXd NormalMatrixReducer::parameterInformation() const {
  const int n_p = layout_.parameters;
  const int n_c = layout_.systematicCount();
  if (n_c == 0) return N_;
  const Eigen::MatrixXd N = normalWithPrior();
  const Eigen::LLT<Eigen::MatrixXd> llt(N.bottomRightCorner(n_c, n_c));
  return N.topLeftCorner(n_p, n_p) -
         N.topRightCorner(n_p, n_c) * llt.solve(N.bottomLeftCorner(n_c, n_p));
}

}  // namespace artcal
