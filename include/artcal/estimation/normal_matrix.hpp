#pragma once
// The reduced normal matrix (docs/method.md section 3). The global unknowns are g = (p, c): the
// calibrated parameters and the artifacts' systematic errors. Each placement's rigid transform
// r_j is eliminated by its Schur complement as the block arrives,
//
//   N_red += A_g^T A_g - A_g^T A_r (A_r^T A_r)^+ A_r^T A_g,
//
// so the cost is linear in the number of placements and the full normal matrix is never formed.
// (A_r^T A_r)^+ is a pseudo-inverse: a direction of r_j that moves no valued coordinate to first
// order (a step gauge's tilt with every face probed on its axis) is simply not estimated.
//
// Rank policy (docs/method.md section 5, "Rank policy"): a rigid direction of placement j is
// observed when its eigenvalue of A_r^T A_r exceeds kRigidObservedTolerance times the block's
// largest eigenvalue (a singular value of A_r above 1e-5 of the largest). Unobserved directions are
// neither eliminated nor stepped (PlacementElimination::rigidStep moves none of them). The count
// of observed directions is the placement's effective N(r_j) (identifiability.hpp).
//
// The systematic errors c carry a prior (Sigma_c^-1 added to their block); eliminating them too
// leaves the information of p alone, whose inverse is V_p (seed eq. 9). A machine's parameter
// prior (`machine.prior`, nominal tolerances, docs/method.md section 3 "Priors") enters the same
// way as whitened prior rows: Sigma_p0^-1 added to the p block. Both are added in one place,
// addPriors / informationOfParameters below, which evaluate, optimize and calibrate all use.

#include <Eigen/Core>
#include <vector>

#include "artcal/estimation/design_matrix.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// Relative eigenvalue below which a placement's rigid direction is not observed.
inline constexpr double kRigidObservedTolerance = 1e-10;

/// Where each artifact's systematic errors sit in g = (p, c).
struct GlobalLayout {
  int parameters = 0;                ///< N(p)
  std::vector<int> artifact_offset;  ///< per artifact: first index of its c in g
  Eigen::VectorXd c_sigma;           ///< prior standard deviation of every c, in g order
  /// Sigma_p0^-1 of each calibrated parameter (1 / tolerance^2; 0 where it has no prior).
  Eigen::VectorXd p_prior_weight;
  int size() const { return parameters + static_cast<int>(c_sigma.size()); }
  /// Number of calibrated parameters with a prior (each adds one whitened row).
  int priorRows() const { return static_cast<int>((p_prior_weight.array() > 0.0).count()); }
  int systematicCount() const { return static_cast<int>(c_sigma.size()); }
  static GlobalLayout of(const Plan& plan);
};

/// Whether the machine's parameter prior is part of an information matrix.
enum class ParameterPrior { Included, Excluded };

/// N over g = (p, c) with the priors added to its diagonal: Sigma_c^-1 on c, Sigma_p0^-1 on p.
Eigen::MatrixXd addPriors(const Eigen::MatrixXd& information_g, const GlobalLayout& layout);

/// The information of p with the parameter prior Sigma_p0^-1 added (whitened prior rows).
Eigen::MatrixXd addParameterPrior(const Eigen::MatrixXd& information_p, const GlobalLayout& layout);

/// The information of p from N over g (docs/method.md section 3): the priors added (the parameter
/// prior only when Included), then c eliminated by its Schur complement. The one elimination of
/// the systematic errors behind evaluate, the optimizer's criteria and the calibrator.
Eigen::MatrixXd informationOfParameters(const Eigen::MatrixXd& information_g,
                                        const GlobalLayout& layout,
                                        ParameterPrior prior = ParameterPrior::Included);

/// What eliminating r_j leaves to recover it after the global step (calibrator).
struct PlacementElimination {
  Eigen::MatrixXd M_rr_pinv;  ///< (A_r^T A_r)^+
  Eigen::MatrixXd M_rg;       ///< A_r^T A_g over the placement's global columns
  Eigen::VectorXd g_r;        ///< A_r^T e
  std::vector<int> columns;   ///< the global columns A_g covers
  /// r_j step for a global step dg: dr = -(A_r^T A_r)^+ (A_r^T e + M_rg dg[columns]).
  Eigen::VectorXd rigidStep(const Eigen::VectorXd& dg) const;
};

/// A placement's whitened products before its rigid motion is eliminated: what reducing it
/// again under another rank policy needs, without its block (Calibrator::information).
struct BlockProducts {
  Eigen::MatrixXd M_rr;       ///< A_r^T A_r
  Eigen::MatrixXd M_rg;       ///< A_r^T A_g over the placement's global columns (p, then its c)
  Eigen::MatrixXd G;          ///< A_g^T A_g: its p block's lower triangle, its c rows (see .cpp)
  Eigen::VectorXd unreduced;  ///< diag(A_p^T A_p)
  int rigid_primary = 0;      ///< ObservationBlock::rigid_primary
};

/// Accumulates N_red (and, with residuals, the reduced right-hand side b = -A^T e reduced).
class NormalMatrixReducer {
 public:
  explicit NormalMatrixReducer(const GlobalLayout& layout);
  void reset();
  /// Adds one placement of artifact `artifact_index`. When `elimination` is given it receives
  /// what back-substitution needs. `max_rigid_rank` (>= 0) caps the observed rigid directions
  /// at that many, the best observed ones (the calibrator passes the rank at the nominal
  /// readings, so that noise cannot make an unseen direction look observed). `products`, when
  /// given, receives the block's products (add(products, ...) reduces them again).
  void add(const ObservationBlock& block, int artifact_index,
           PlacementElimination* elimination = nullptr, int max_rigid_rank = -1,
           BlockProducts* products = nullptr);
  /// Adds a placement from the products of its block (no residuals): the same N_red, unreduced
  /// diagonal and rigid rank as add() of that block, without multiplying its rows again.
  void add(const BlockProducts& products, int artifact_index, int max_rigid_rank = -1);

  const Eigen::MatrixXd& normal() const { return N_; }  ///< N_red over g, no prior yet
  const Eigen::VectorXd& rhs() const { return b_; }     ///< -reduced A^T e
  double chi2() const { return chi2_; }                 ///< sum of e^T e added
  /// diag(sum_j A_pj^T A_pj): the information of each parameter before any elimination, the
  /// scale of the parameter rank test (identifiability.hpp).
  const Eigen::VectorXd& unreducedDiagonal() const { return unreduced_diagonal_; }
  /// Observed rigid directions of each placement added since reset(), in order.
  const std::vector<int>& rigidRanks() const { return rigid_ranks_; }

  /// N_red with the priors: Sigma_c^-1 on the c block, Sigma_p0^-1 on the p block.
  Eigen::MatrixXd normalWithPrior() const;
  /// The information of p alone: c eliminated (with its prior) by its Schur complement, plus
  /// the parameter prior unless `prior` says Excluded (the readings' own information, for the
  /// identifiability tests).
  Eigen::MatrixXd parameterInformation(ParameterPrior prior = ParameterPrior::Included) const;

 private:
  GlobalLayout layout_;
  Eigen::MatrixXd N_;
  Eigen::VectorXd b_;
  double chi2_ = 0.0;
  Eigen::VectorXd unreduced_diagonal_;
  std::vector<int> rigid_ranks_;
  std::vector<int> columns_;
  BlockProducts products_;  ///< scratch of add(block) without `products`
  Eigen::MatrixXd X_;
  Eigen::VectorXd g_r_;

  class RigidBlockRoot;
  /// N_red += the placement's Schur complement from its products under the factor S; leaves
  /// Y = S M_rg in X_ and the global columns in columns_.
  void reduce(const BlockProducts& products, const RigidBlockRoot& S, int artifact_index);
};

/// The rigid directions the measured features of a placement can see, from the artifact's
/// calibrated feature coordinates alone (rank of the stacked dW_valued/dr at W*_i, singular values
/// above sqrt(kRigidObservedTolerance) of the largest). Noise-free: the calibrator caps each
/// placement's observed directions at this count, so that the micrometre lever arms noise gives
/// an unseen direction (a lone ball's rotations) are never stepped.
int rigidRankOfFeatures(const Artifact& artifact, const std::vector<Measurement>& measurements);

/// Pseudo-inverse of a small symmetric positive semi-definite matrix: eigenvalues below
/// `relative_tolerance` times the largest count as zero.
Eigen::MatrixXd symmetricPseudoInverse(const Eigen::MatrixXd& M, double relative_tolerance = 1e-12);

}  // namespace artcal
