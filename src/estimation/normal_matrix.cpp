#include "artcal/estimation/normal_matrix.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>
#include <cmath>
#include <optional>
#include <utility>

#include "artcal/core/linear_algebra.hpp"

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
  const Machine& machine = plan.machine;
  layout.p_prior_weight = Eigen::VectorXd::Zero(layout.parameters);
  if (machine.prior_sigma.size() > 0) {
    const Eigen::VectorXd sigma = machine.calibratedValues(machine.prior_sigma);
    for (int k = 0; k < layout.parameters; ++k) {
      if (sigma[k] > 0.0) layout.p_prior_weight[k] = 1.0 / (sigma[k] * sigma[k]);
    }
  }
  return layout;
}

namespace {

// The priors as whitened rows (docs/method.md section 3): each adds 1 / sigma^2 to its diagonal.
Eigen::MatrixXd withPriors(const Eigen::MatrixXd& information_g, const GlobalLayout& layout,
                           ParameterPrior prior) {
  Eigen::MatrixXd N = information_g;
  if (prior == ParameterPrior::Included)
    N.diagonal().head(layout.parameters) += layout.p_prior_weight;
  N.diagonal().tail(layout.systematicCount()) += layout.c_sigma.array().square().inverse().matrix();
  return N;
}

}  // namespace

Eigen::MatrixXd addParameterPrior(const Eigen::MatrixXd& information_p,
                                  const GlobalLayout& layout) {
  Eigen::MatrixXd N = information_p;
  N.diagonal() += layout.p_prior_weight;
  return N;
}

Eigen::MatrixXd addPriors(const Eigen::MatrixXd& information_g, const GlobalLayout& layout) {
  return withPriors(information_g, layout, ParameterPrior::Included);
}

Eigen::MatrixXd informationOfParameters(const Eigen::MatrixXd& information_g,
                                        const GlobalLayout& layout, ParameterPrior prior) {
  const int n_p = layout.parameters;
  const int n_c = layout.systematicCount();
  const Eigen::MatrixXd N = withPriors(information_g, layout, prior);
  if (n_c == 0) return N;
  const Eigen::LLT<Eigen::MatrixXd> llt(N.bottomRightCorner(n_c, n_c));
  return N.topLeftCorner(n_p, n_p) -
         N.topRightCorner(n_p, n_c) * llt.solve(N.bottomLeftCorner(n_c, n_p));
}

Eigen::VectorXd PlacementElimination::rigidStep(const Eigen::VectorXd& dg) const {
  Eigen::VectorXd local(static_cast<int>(columns.size()));
  for (std::size_t i = 0; i < columns.size(); ++i) local[static_cast<int>(i)] = dg[columns[i]];
  return -(M_rr_pinv * (g_r + M_rg * local));
}

int rigidRankOfFeatures(const Artifact& artifact, const std::vector<Measurement>& measurements) {
  // A plane's features are faces, touched anywhere: the faces' normals decide (the table).
  if (artifact.kind().touches_faces) return artifact.rigidDof();
  const int k = artifact.valuedPerFeature();
  const Eigen::VectorXd no_c;
  Eigen::MatrixXd J(k * static_cast<int>(measurements.size()), artifact.fullRigidDof());
  for (std::size_t i = 0; i < measurements.size(); ++i) {
    artifact.fullRigidJacobian(artifact.feature(measurements[i].feature, no_c),
                               J.middleRows(k * static_cast<int>(i), k));
  }
  return numericalRank(J, std::sqrt(kRigidObservedTolerance));
}

Eigen::MatrixXd symmetricPseudoInverse(const Eigen::MatrixXd& M, double relative_tolerance) {
  const SymmetricEigenSolver eig(M);
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  const double cutoff = relative_tolerance * std::max(lambda.cwiseAbs().maxCoeff(), 0.0);
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(lambda.size());
  for (int i = 0; i < lambda.size(); ++i) {
    if (lambda[i] > cutoff && lambda[i] > 0.0) inverse[i] = 1.0 / lambda[i];
  }
  return eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
}

namespace {

// At most 6 rigid-motion unknowns per placement: the small matrices live on the stack.
using RigidMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, 6>;
using RigidVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 6, 1>;

// L^-1 of the Cholesky factor L L^T = M of a small symmetric block (at most 6 x 6: by loops, not
// through the blocked solvers whose set-up costs more than the arithmetic); false when M is not
// positive definite (a pivot not above 0, or not finite).
template <typename Block>
bool inverseCholeskyFactor(const Block& M, RigidMatrix& L_inverse) {
  const int n = static_cast<int>(M.rows());
  RigidMatrix L = RigidMatrix::Zero(n, n);
  for (int j = 0; j < n; ++j) {
    double pivot = M(j, j);
    for (int k = 0; k < j; ++k) pivot -= L(j, k) * L(j, k);
    if (!(pivot > 0.0) || !std::isfinite(pivot)) return false;
    L(j, j) = std::sqrt(pivot);
    for (int i = j + 1; i < n; ++i) {
      double sum = M(i, j);
      for (int k = 0; k < j; ++k) sum -= L(i, k) * L(j, k);
      L(i, j) = sum / L(j, j);
    }
  }
  // Forward substitution, column by column: L L^-1 = I.
  L_inverse.setZero(n, n);
  for (int j = 0; j < n; ++j) {
    L_inverse(j, j) = 1.0 / L(j, j);
    for (int i = j + 1; i < n; ++i) {
      double sum = 0.0;
      for (int k = j; k < i; ++k) sum -= L(i, k) * L_inverse(k, j);
      L_inverse(i, j) = sum / L(i, i);
    }
  }
  return true;
}

// A factor S of (A_r^T A_r)^+ = S^T S over the observed rigid directions only (rank policy,
// docs/method.md section 5): a direction is observed when its eigenvalue exceeds
// kRigidObservedTolerance times the block's largest, never by a pivot against its own column's
// diagonal (a column zero in exact arithmetic but carrying rounding, a step gauge's rotation,
// would pass that test and its elimination would destroy real information about p).
//
// The block's columns are the artifact's estimated directions (the `primary` ones) and then the
// rest of the full rigid motion (design_matrix.hpp). Fast path, a block LDL^T: when the primary
// block M11 is certainly well conditioned by that global test (lambda_min >= 1 / ||L^-1||_F^2,
// lambda_max <= trace), its Cholesky factor L eliminates it; the rest is eliminated only along
// the eigen-directions of its Schur complement M22 - M21 M11^-1 M12 that exceed the tolerance
// times trace(M): zero on consistent points (a ball bar's roll), so the result is exactly the
// primary elimination; the mismatch of real readings on the roll, so a rigid motion of the whole
// machine is absorbed entirely. Otherwise the eigen-decomposition of the whole block decides.
// `max_rank` (>= 0) keeps at most that many directions (the calibrator: the number of observed
// directions is a property of the design, decided at the calibrated features).
}  // namespace

class NormalMatrixReducer::RigidBlockRoot {
 public:
  RigidBlockRoot(const Eigen::MatrixXd& M, int primary, int max_rank) {
    const int n = static_cast<int>(M.rows());
    root_.setZero(n, n);
    const int n1 = std::min(primary, n);
    if (n1 > 0 && (max_rank < 0 || max_rank >= n1) && blockFactor(M, n1, max_rank)) return;
    eigenFactor(M, max_rank);
  }
  /// out = S X (out not X).
  template <typename Matrix, typename Out>
  void apply(const Matrix& X, Out& out) const {
    // At most 6 x 6 times 6 x (parameters): coefficient-wise, not through a general GEMM whose
    // set-up costs more than the product; into `out`, which keeps its storage between calls.
    out.noalias() = root_.lazyProduct(X);
  }
  /// S^T S.
  Eigen::MatrixXd pseudoInverse() const { return root_.transpose().lazyProduct(root_); }
  /// The observed rigid directions.
  int rank() const { return rank_; }

 private:
  // The block LDL^T path; false when M11 is not certainly well conditioned.
  bool blockFactor(const Eigen::MatrixXd& M, int n1, int max_rank) {
    const int n = static_cast<int>(M.rows());
    RigidMatrix L_inverse;
    if (!inverseCholeskyFactor(M.topLeftCorner(n1, n1), L_inverse)) return false;
    const double trace = M.trace();
    if (!(1.0 / L_inverse.squaredNorm() >
          kRigidObservedTolerance * M.topLeftCorner(n1, n1).trace()))
      return false;
    root_.topLeftCorner(n1, n1) = L_inverse;
    rank_ = n1;
    const int n2 = n - n1;
    if (n2 == 0 || (max_rank >= 0 && max_rank <= n1)) return true;
    // T = M21 L^-T: M21 M11^-1 = T L^-1. The rest's Schur complement M22 - T T^T.
    const RigidMatrix T = M.bottomLeftCorner(n2, n1) * L_inverse.transpose();
    const RigidMatrix schur = M.bottomRightCorner(n2, n2) - T * T.transpose();
    const Eigen::SelfAdjointEigenSolver<RigidMatrix> eig(schur);
    const auto& lambda = eig.eigenvalues();  // ascending
    RigidMatrix W = RigidMatrix::Zero(n2, n2);
    for (int i = n2 - 1; i >= 0; --i) {
      const bool observed =
          lambda[i] > kRigidObservedTolerance * trace && (max_rank < 0 || rank_ < max_rank);
      if (!observed) continue;
      W.row(i) = eig.eigenvectors().col(i).transpose() / std::sqrt(lambda[i]);
      ++rank_;
    }
    // S = [[L^-1, 0], [-W T L^-1, W]].
    root_.bottomLeftCorner(n2, n1) = -W * T * L_inverse;
    root_.bottomRightCorner(n2, n2) = W;
    return true;
  }

  // S = D^+1/2 U^T over the directions whose eigenvalue exceeds the tolerance (largest first).
  void eigenFactor(const Eigen::MatrixXd& M, int max_rank) {
    const int n = static_cast<int>(M.rows());
    const Eigen::SelfAdjointEigenSolver<RigidMatrix> eig{RigidMatrix(M)};
    const auto& lambda = eig.eigenvalues();  // ascending
    const double cutoff = kRigidObservedTolerance * std::max(lambda.cwiseAbs().maxCoeff(), 0.0);
    root_ = eig.eigenvectors().transpose();
    rank_ = 0;
    for (int i = n - 1; i >= 0; --i) {
      const bool observed =
          lambda[i] > cutoff && lambda[i] > 0.0 && (max_rank < 0 || rank_ < max_rank);
      if (observed) ++rank_;
      root_.row(i) *= observed ? 1.0 / std::sqrt(lambda[i]) : 0.0;
    }
  }

  int rank_ = 0;
  RigidMatrix root_;
};

namespace {

// Parameters up to which the normal matrix is updated by coefficient-wise products.
constexpr int kSmallProblem = 8;

// X^T Y (X with A columns, Y with as many rows) into `out`, each entry the dot product of two
// columns summed exactly as Eigen's lazy product sums it (its vectorised reduction over 2-lane
// packets: two accumulating packets over 4 rows at a time, added, a last packet, the two lanes,
// then the odd row), but the A dot products against one column of Y at once: independent chains
// instead of one latency-bound chain per entry, each column of Y loaded once.
template <int A, typename Out>
void transposeProductColumns(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y, Out& out) {
  using Packet = Eigen::internal::packet_traits<double>::type;
  using Eigen::internal::padd;
  using Eigen::internal::ploadu;
  using Eigen::internal::pmul;
  const Eigen::Index n = X.rows();
  const Eigen::Index n4 = (n / 4) * 4, n2 = (n / 2) * 2;
  const double* x0 = X.data();
  for (Eigen::Index j = 0; j < Y.cols(); ++j) {
    const double* y = Y.data() + j * n;
    Packet acc0[A], acc1[A];
    for (int i = 0; i < A; ++i) {
      acc0[i] = pmul(ploadu<Packet>(x0 + i * n), ploadu<Packet>(y));
      acc1[i] = pmul(ploadu<Packet>(x0 + i * n + 2), ploadu<Packet>(y + 2));
    }
    for (Eigen::Index r = 4; r < n4; r += 4) {
      const Packet y0 = ploadu<Packet>(y + r), y1 = ploadu<Packet>(y + r + 2);
      for (int i = 0; i < A; ++i) {
        acc0[i] = padd(acc0[i], pmul(ploadu<Packet>(x0 + i * n + r), y0));
        acc1[i] = padd(acc1[i], pmul(ploadu<Packet>(x0 + i * n + r + 2), y1));
      }
    }
    for (int i = 0; i < A; ++i) {
      const double* x = x0 + i * n;
      Packet acc = padd(acc0[i], acc1[i]);
      if (n2 > n4) acc = padd(acc, pmul(ploadu<Packet>(x + n4), ploadu<Packet>(y + n4)));
      double sum = Eigen::internal::predux(acc);
      for (Eigen::Index r = n2; r < n; ++r) sum += x[r] * y[r];
      out(i, j) = sum;
    }
  }
}

// out = X^T Y, the numbers of X.transpose().lazyProduct(Y): by transposeProductColumns where its
// summation order is Eigen's (2-lane packets, at least 4 rows, X of at most 8 columns), otherwise
// by the lazy product itself.
template <typename Out>
void transposeProduct(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y, Out&& out) {
  constexpr bool two_lanes = Eigen::internal::packet_traits<double>::Vectorizable &&
                             Eigen::internal::packet_traits<double>::size == 2;
  if constexpr (two_lanes) {
    if (X.rows() >= 4 && X.rows() == Y.rows()) {
      // X.cols() in 1..8: the kernel of that width (a fold over the widths).
      const auto kernel = [&]<int... W>(std::integer_sequence<int, W...>) {
        return ((X.cols() == W + 1 && (transposeProductColumns<W + 1>(X, Y, out), true)) || ...);
      };
      if (kernel(std::make_integer_sequence<int, 8>{})) return;
    }
  }
  out.noalias() = X.transpose().lazyProduct(Y);
}

// The lower triangle of a symmetric block copied into its upper triangle.
template <typename Block>
void mirrorLower(Block&& N) {
  for (int j = 1; j < N.cols(); ++j) {
    for (int i = 0; i < j; ++i) N(i, j) = N(j, i);
  }
}

}  // namespace

NormalMatrixReducer::NormalMatrixReducer(const GlobalLayout& layout) : layout_(layout) {
  reset();
}

void NormalMatrixReducer::reset() {
  N_.setZero(layout_.size(), layout_.size());
  b_.setZero(layout_.size());
  unreduced_diagonal_.setZero(layout_.parameters);
  rigid_ranks_.clear();
  chi2_ = 0.0;
}

// Schur complement of r_j (docs/method.md section 3), as symmetric rank updates without forming it:
//   N_red += A_g^T A_g - Y^T Y,   Y = S A_r^T A_g,   S^T S = (A_r^T A_r)^+.
// The global columns are p (0..n_p) and the artifact's c (c_offset..): the c rows lie below p.
// The block's products (A_r^T A_r, A_r^T A_g, A_g^T A_g) are formed first (BlockProducts), then
// reduced: N_red += G - Y^T Y adds the same numbers as the rank updates into N_red did.
void NormalMatrixReducer::add(const ObservationBlock& block, int artifact_index,
                              PlacementElimination* elimination, int max_rigid_rank,
                              BlockProducts* products) {
  BlockProducts& P = products ? *products : products_;
  const int n_p = layout_.parameters;
  const int n_c = static_cast<int>(block.A_c.cols());
  const int n_g = n_p + n_c;
  const auto& A_p = block.A_p;
  const auto& A_c = block.A_c;
  const auto& A_r = block.A_r;

  P.rigid_primary = block.rigid_primary;
  P.M_rr.resize(A_r.cols(), A_r.cols());
  transposeProduct(A_r, A_r, P.M_rr);
  P.unreduced = A_p.colwise().squaredNorm().transpose();
  // A_c has a few non-zeros per column (the readings of one feature, whitened within each
  // reading: 6 of 150 rows for a plate read with two styli): its products as a sparse matrix.
  // Without systematic errors none is made (even an empty one allocates).
  std::optional<Eigen::SparseMatrix<double>> sparse;
  if (n_c > 0) sparse.emplace(A_c.sparseView());
  P.M_rg.resize(A_r.cols(), n_g);
  transposeProduct(A_r, A_p, P.M_rg.leftCols(n_p));
  if (n_c > 0) P.M_rg.rightCols(n_c) = (sparse->transpose() * A_r).transpose();
  // G = A_g^T A_g: its p block (the lower triangle, or all of it for a few parameters), its c
  // block and its c x p block (the p x c block is not formed).
  P.G.resize(n_g, n_g);
  auto G_pp = P.G.topLeftCorner(n_p, n_p);
  if (n_p <= kSmallProblem) {
    // A few parameters (the seed's arm: 3): coefficient-wise products; the blocked symmetric
    // rank update's set-up costs more than the arithmetic there.
    transposeProduct(A_p, A_p, G_pp);
  } else {
    G_pp.setZero();
    G_pp.selfadjointView<Eigen::Lower>().rankUpdate(A_p.transpose());
  }
  if (n_c > 0) {
    const Eigen::SparseMatrix<double>& A_c_sparse = *sparse;
    P.G.bottomRightCorner(n_c, n_c) = Eigen::MatrixXd(A_c_sparse.transpose() * A_c_sparse);
    P.G.bottomLeftCorner(n_c, n_p).noalias() = A_c_sparse.transpose() * A_p;
  }
  const RigidBlockRoot S(P.M_rr, P.rigid_primary, max_rigid_rank);
  reduce(P, S, artifact_index);

  const bool with_residuals = block.e.size() == block.rows();
  if (with_residuals) {
    // b -= A_g^T e - Y^T S A_r^T e
    g_r_.noalias() = A_r.transpose() * block.e;
    RigidVector s_g_r;
    S.apply(g_r_, s_g_r);
    Eigen::VectorXd reduced = X_.transpose() * s_g_r;
    reduced.head(n_p).noalias() -= A_p.transpose() * block.e;
    if (n_c > 0) reduced.tail(n_c).noalias() -= A_c.transpose() * block.e;
    for (int i = 0; i < n_g; ++i) b_[columns_[static_cast<std::size_t>(i)]] += reduced[i];
    chi2_ += block.e.squaredNorm();
  }
  if (elimination) {
    elimination->M_rr_pinv = S.pseudoInverse();
    elimination->M_rg = P.M_rg;
    elimination->g_r = with_residuals ? g_r_ : Eigen::VectorXd::Zero(P.M_rr.rows());
    elimination->columns = columns_;
  }
}

void NormalMatrixReducer::add(const BlockProducts& products, int artifact_index,
                              int max_rigid_rank) {
  const RigidBlockRoot S(products.M_rr, products.rigid_primary, max_rigid_rank);
  reduce(products, S, artifact_index);
}

void NormalMatrixReducer::reduce(const BlockProducts& products, const RigidBlockRoot& S,
                                 int artifact_index) {
  const int n_p = layout_.parameters;
  const int n_g = static_cast<int>(products.M_rg.cols());
  const int n_c = n_g - n_p;
  const int c_offset = layout_.artifact_offset[static_cast<std::size_t>(artifact_index)];
  rigid_ranks_.push_back(S.rank());
  unreduced_diagonal_ += products.unreduced;
  S.apply(products.M_rg, X_);  // Y
  const auto Y_p = X_.leftCols(n_p);
  auto N_pp = N_.topLeftCorner(n_p, n_p);
  const auto G_pp = products.G.topLeftCorner(n_p, n_p);
  if (n_p <= kSmallProblem) {
    N_pp += G_pp;
    N_pp.noalias() -= Y_p.transpose().lazyProduct(Y_p);
  } else {
    N_pp.triangularView<Eigen::Lower>() += G_pp;
    N_pp.selfadjointView<Eigen::Lower>().rankUpdate(Y_p.transpose(), -1.0);
    mirrorLower(N_pp);
  }
  if (n_c > 0) {
    const auto Y_c = X_.rightCols(n_c);
    auto N_cc = N_.block(c_offset, c_offset, n_c, n_c);
    N_cc += products.G.bottomRightCorner(n_c, n_c);
    N_cc.selfadjointView<Eigen::Lower>().rankUpdate(Y_c.transpose(), -1.0);
    mirrorLower(N_cc);
    auto N_cp = N_.block(c_offset, 0, n_c, n_p);
    N_cp += products.G.bottomLeftCorner(n_c, n_p);
    N_cp.noalias() -= Y_c.transpose() * Y_p;
    N_.block(0, c_offset, n_p, n_c) = N_cp.transpose();
  }
  columns_.resize(static_cast<std::size_t>(n_g));
  for (int i = 0; i < n_p; ++i) columns_[static_cast<std::size_t>(i)] = i;
  for (int i = 0; i < n_c; ++i) columns_[static_cast<std::size_t>(n_p + i)] = c_offset + i;
}

Eigen::MatrixXd NormalMatrixReducer::normalWithPrior() const {
  return addPriors(N_, layout_);
}

Eigen::MatrixXd NormalMatrixReducer::parameterInformation(ParameterPrior prior) const {
  return informationOfParameters(N_, layout_, prior);
}

}  // namespace artcal
