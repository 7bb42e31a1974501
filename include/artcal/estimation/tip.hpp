#pragma once
// Tip uncertainty over the workspace (docs/method.md section 4, seed eq. 10 and Fig. 6):
//   S_m(q)^2 = tr(J_p V_p J_p^T),  S_q(q)^2 = tr(J_q Sigma_q J_q^T),  S = sqrt(S_m^2 + S_q^2).
// The workspace's Jacobians are prepared once. S_m^2 = tr(V_p J_p^T J_p) is then, for a new V_p,
// one matrix-vector product with the prepared Gram matrices J_p^T J_p (their lower triangles,
// N(p)(N(p)+1)/2 numbers per configuration); for many parameters, where those would take too
// much memory, the product (J_p stacked) * chol(V_p), whose row norms give S_m.
// When the Jacobians span a space of few matrices over the workspace, J_p(q) = sum_i c_i(q) B_i
// (a Cartesian CMM's are polynomials of the readings: about 20 basis matrices for 50
// parameters), S_m^2 = c^T W c with W_ii' = tr(B_i V_p B_i'^T): r numbers per configuration,
// the basis found once from a subset, checked on every configuration to 1e-10.
// Where the Gram matrices' varying entries outnumber J_p's (a 6-axis arm's 21 parameters: 185
// against 63 per configuration), S_m^2 = |J_p L|_F^2 is summed from J_p kept in panels, each
// panel's product made and consumed in cache (estimation/tip_kernel.hpp): a third of the data.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "artcal/estimation/evaluation_result.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// The joint configurations of a workspace spec (internal units). Samples are uniform within
/// the joint limits from a fixed generator (std::mt19937_64), identical on every platform.
/// Task-space samples (docs/models.md section 5) are uniform in the region (rejection from its
/// bounding box), each in the first of up to 24 random postures (posturesFor; the hexapod: a
/// platform orientation within spec.tilt of home) that reaches it within the joint limits.
/// Configurations whose forward kinematics fails or lands elsewhere than the sampled point are
/// dropped as well; `drops`, when given, counts both.
std::vector<Eigen::VectorXd> workspaceConfigurations(const Machine& machine,
                                                     const WorkspaceSpec& spec,
                                                     WorkspaceDrops* drops = nullptr);

/// How often a TipEvaluator will be asked: the prepared forms above (Gram, factored, panels)
/// cost about one evaluation to build, and pay off from the second (the optimizer's thousands);
/// one evaluation (`evaluate`, the report) is the direct product J_p L.
enum class TipUse { Once, Repeated };

/// The workspace's samples before the forward-kinematics check of workspaceConfigurations
/// (task-space samples are checked as they are drawn): for TipEvaluator::ofSamples, which makes
/// that check with the Jacobians rather than apart.
std::vector<Eigen::VectorXd> workspaceSamples(const Machine& machine, const WorkspaceSpec& spec,
                                              WorkspaceDrops* drops = nullptr);

class TipEvaluator {
 public:
  /// The tip uncertainty of stylus `stylus` (a chain's tip, Mechanism::forwardStylus).
  TipEvaluator(const Machine& machine, const Noise& noise,
               std::vector<Eigen::VectorXd> configurations, int stylus = 0,
               TipUse use = TipUse::Repeated);
  /// Several tips at once (a machine with named tips, docs/urdf.md): configuration g of stylus
  /// styluses[g] (the optimizer's worst over every tip).
  TipEvaluator(const Machine& machine, const Noise& noise,
               std::vector<Eigen::VectorXd> configurations, std::vector<int> styluses,
               TipUse use = TipUse::Repeated);
  /// Over workspace samples (workspaceSamples) at stylus 0: a sample whose forward kinematics
  /// fails at nominal, or lands on no finite point, is left out and counted in `drops.failed`
  /// (workspaceConfigurations' check, made once with the Jacobians).
  static TipEvaluator ofSamples(const Machine& machine, const Noise& noise,
                                std::vector<Eigen::VectorXd> samples, WorkspaceDrops& drops,
                                TipUse use = TipUse::Repeated);
  /// The stylus of each configuration.
  const std::vector<int>& styluses() const { return styluses_; }

  int size() const { return static_cast<int>(configurations_.size()); }
  const std::vector<Eigen::VectorXd>& configurations() const { return configurations_; }
  /// r, the number of basis matrices of the factored form (above); 0 when it is not used.
  int factorRank() const { return static_cast<int>(factor_coefficients_.rows()); }
  /// S_q^2 per configuration.
  const Eigen::VectorXd& encoderVariance() const { return S_q2_; }
  /// The calibrated parameters (indices into machine.calibrated) that move the tip at some
  /// configuration: the columns of J_p that are not zero.
  std::vector<int> movingParameters() const;

  /// S_m^2 per configuration for a parameter covariance V_p (N(p) x N(p)).
  void kinematicVariance(const Eigen::MatrixXd& V_p, Eigen::VectorXd& S_m2) const;
  TipSummary summarize(const Eigen::MatrixXd& V_p) const;
  /// The summary of S_m^2 per configuration already computed (kinematicVariance).
  TipSummary summarizeVariance(const Eigen::VectorXd& S_m2) const;
  TipPoint at(int configuration, const Eigen::MatrixXd& V_p) const;

 private:
  /// `styluses` empty: every configuration's is `stylus`.
  TipEvaluator(const Machine& machine, const Noise& noise,
               std::vector<Eigen::VectorXd> configurations, std::vector<int> styluses, int stylus,
               TipUse use, WorkspaceDrops* drops);
  void prepareRepeated(int n_p);
  void prepareGram(int n_p);
  void preparePanels(int n_p);
  bool prepareFactored(int n_p, long cost_to_beat);
  void factoredVariance(const Eigen::MatrixXd& V_p, Eigen::VectorXd& S_m2) const;
  int dimension_;
  std::vector<Eigen::VectorXd> configurations_;
  std::vector<int> styluses_;
  Eigen::MatrixXd J_p_;
  /// Per configuration (column): the entries of vech(J_p^T J_p) (off-diagonal doubled) that vary
  /// over the workspace; `gram_rows_` says which, `gram_constant_` holds the others (0 where
  /// varying).
  Eigen::MatrixXd gram_;
  std::vector<int> gram_rows_;
  Eigen::VectorXd gram_constant_;
  Eigen::VectorXd S_q2_;
  /// Blocked form: J_p in panels (tip_kernel.hpp), padded with zero rows; empty when not used.
  std::vector<double> panels_;
  int panel_count_ = 0;
  mutable std::vector<double> row_squares_;
  /// Factored form: coefficients c(q) per configuration (column) and, per tip coordinate, the
  /// basis matrices' rows (r x N(p)); empty when not used.
  Eigen::MatrixXd factor_coefficients_;
  std::vector<Eigen::MatrixXd> factor_rows_;
  mutable Eigen::MatrixXd factor_W_, factor_WC_;
  mutable Eigen::VectorXd packed_V_, packed_varying_;
  mutable Eigen::MatrixXd scratch_;
  mutable Eigen::VectorXd S_m2_;
};

/// Tip uncertainty of a point at one configuration (no preparation).
TipPoint tipUncertainty(const Machine& machine, const Noise& noise, const Eigen::VectorXd& q,
                        const Eigen::MatrixXd& V_p);

/// S_m, S_q and S against reach (seed Fig. 6) for a model whose tip uncertainty depends on the
/// reach alone (Mechanism::reachRange; planar2r), `steps` rows from the inner to the outer reach;
/// every branch within the joint limits (Mechanism::configurationsAtReach), the largest value
/// kept. Empty for other models.
std::vector<ProfilePoint> reachProfile(const Machine& machine, const Noise& noise,
                                       const Eigen::MatrixXd& V_p, int steps = 21);

}  // namespace artcal
