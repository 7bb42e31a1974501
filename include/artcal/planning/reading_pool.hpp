#pragma once
// Candidate pools (issue 45, docs/optimize.md "Choosing readings from a pool"): which N of the
// readings a user already has (a readings plan of an earlier session, an imported CSV of joint
// readings) to calibrate with.
//
// Every reading of the pool plan is a candidate. Its whitened rows a_i over the augmented
// unknowns x = (p, c, r_1 .. r_m) (the calibrated parameters, the artifacts' systematic errors,
// each placement's rigid motion) are built once, at the nominal parameters with each placement's
// r_j fitted to all of its readings (design_matrix.hpp). The information of a subset S is
//   M(S) = P + sum_{i in S} a_i^T a_i,
// P the priors: Sigma_p0^-1 (the machine's prior, or `prior_tolerance` where it states none, so
// that a subset too small to identify every parameter leaves them at their tolerance instead of
// having no V_p), Sigma_c^-1, and a vanishing ridge on r (a placement with no chosen reading).
// V_p is the p block of M(S)^-1 (the Schur complement of r and c, docs/method.md section 3).
//
// Exchange (modified Fedorov: Cook and Nachtsheim, Technometrics 1980): each slot in turn is
// swapped for the candidate that lowers the criterion most, until a pass improves nothing. With
// slot i removed, M_- = M(S \ {i}) is inverted once; a candidate j then costs a rank-k update
// (Woodbury, k rows per reading): B = M_-^-1 a_j^T, K = (I + a_j B)^-1, V_p' = V_- - B_p K B_p^T,
// and each criterion is read from B_p and K alone:
//   A  tr(S V_p' S) = tr(S V_- S) - tr(K B_p^T S^2 B_p)
//   I  mean_q S(q)^2 = mean(S_q^2) + tr(V_p' Jbar),  Jbar = mean_q J_p^T J_p
//   D  log det V_p' = log det V_- + log det(I - K B_p^T V_-^-1 B_p)
//   G  S(q)^2 = S_-(q)^2 - tr(K (J_q B_p)^T (J_q B_p)) over an active set of configurations (the
//      lower bound optimizer.cpp ranks with), the best candidate confirmed on every one.
// Restarts from random subsets (start s seeded by (seed, s) alone); for G, start 0 is the D choice
// so that the G choice is never worse in G than the D choice.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

#include "artcal/plan/plan.hpp"
#include "artcal/planning/optimizer.hpp"

namespace artcal {

/// Where a candidate reading sits in the pool plan.
struct PoolReading {
  int placement = 0;
  int measurement = 0;
};

struct PoolOptions {
  Criterion criterion = Criterion::WorstTip;  ///< worst-tip (G), mean-tip (I), D or A
  std::uint64_t seed = 1;
  int starts = 8;
  int exchange_passes = 12;  ///< at most, per start
  /// Candidates tried per slot: 0 all of them; otherwise a fresh random subset of this many.
  int slot_candidates = 0;
  double time_limit = 60.0;  ///< s, whole search (start 0 always runs, cut short if need be)
  int threads = 0;           ///< 0: the hardware's
  std::function<void(const OptimizerProgress&)> progress;  ///< after each start
};

struct PoolChoice {
  std::vector<int> chosen;  ///< candidate indices, ascending
  double value = 0.0;       ///< the criterion, mm
  Criterion criterion = Criterion::WorstTip;
  int starts = 0;
  int starts_done = 0;
  int best_start = -1;
  bool timed_out = false;
  double seconds = 0.0;
};

/// Where the tip criteria (G, I) look: the plan's workspace (what evaluate's tip map uses), or the
/// pool's own configurations (where the machine was recorded working).
enum class PoolWorkspace { Plan, Pool };

class ReadingPool {
 public:
  /// `prior_tolerance` (mm; an angle's is this at the machine's reach): the standard deviation of
  /// the nominal values of parameters the machine gives no prior. InputError when a placement's
  /// readings do not each give the artifact's rows per reading (plane touches).
  ReadingPool(const Plan& plan, double prior_tolerance = 1.0,
              PoolWorkspace workspace = PoolWorkspace::Plan);

  int size() const { return static_cast<int>(readings_.size()); }
  const std::vector<PoolReading>& readings() const { return readings_; }
  /// The pool plan with the prior tolerance in its machine prior: what the criteria read.
  const Plan& criterionPlan() const { return criterion_plan_; }
  int parameterCount() const { return n_p_; }
  int unknownCount() const { return static_cast<int>(prior_.size()); }
  int rowsPerReading() const { return k_; }

  /// a_i (rows per reading x unknowns), whitened.
  Eigen::Ref<const Eigen::MatrixXd> rows(int candidate) const;
  /// M(S) = P + sum a_i^T a_i over the augmented unknowns.
  Eigen::MatrixXd information(const std::vector<int>& subset) const;
  /// V_p of a subset (the p block of M(S)^-1), internal units.
  Eigen::MatrixXd covariance(const std::vector<int>& subset) const;
  /// The criterion (mm) of a subset, from V_p directly.
  double value(const std::vector<int>& subset, Criterion criterion) const;
  double valueOfCovariance(const Eigen::MatrixXd& V_p, Criterion criterion) const;

  /// The workspace the tip criteria read (the plan's), its stacked J_p (dimension rows each),
  /// S_q^2 per configuration, and the scale that puts angles in mm (the reach) for D and A.
  const Eigen::MatrixXd& workspaceJacobians() const { return J_; }
  const Eigen::VectorXd& encoderVariance() const { return S_q2_; }
  const Eigen::VectorXd& scale() const { return scale_; }
  int dimension() const { return dimension_; }
  /// S(q)^2 at every workspace configuration for V_p.
  Eigen::VectorXd tipVariance(const Eigen::MatrixXd& V_p) const;

  /// The pool plan with only the chosen readings (placements left without any dropped). Its
  /// `"calibrate": "identifiable"` is resolved on the whole pool (the set every
  /// subset is compared on) or again on the subset's own readings, as loading them alone would.
  enum class CalibratedSet { Pool, Subset };
  Plan subsetPlan(const std::vector<int>& subset, CalibratedSet set = CalibratedSet::Subset) const;

 private:
  void buildRows(const Plan& plan);
  void buildWorkspace(PoolWorkspace workspace);
  Plan criterion_plan_;
  Eigen::VectorXd plan_prior_;  ///< the plan's own machine prior (subsetPlan keeps it)
  std::vector<PoolReading> readings_;
  int n_p_ = 0;
  int k_ = 0;
  int dimension_ = 0;
  Eigen::MatrixXd rows_;    ///< k_ rows per candidate
  Eigen::VectorXd prior_;   ///< diagonal of P
  Eigen::MatrixXd J_;       ///< workspace J_p, dimension_ rows per configuration
  Eigen::VectorXd S_q2_;    ///< per configuration
  Eigen::MatrixXd J_mean_;  ///< mean_q J_p^T J_p (I criterion)
  Eigen::VectorXd scale_;
  friend class PoolSearch;
};

/// Chooses `count` readings of `pool` minimising options.criterion by exchange with restarts.
/// InputError when count is not in [1, pool size] or the criterion is not G, I, D or A.
PoolChoice chooseReadings(const ReadingPool& pool, int count, const PoolOptions& options);

/// `count` readings spread in joint space: greedy farthest points (the first the reading nearest
/// the joints' mean; then each the one farthest from those chosen, each joint scaled by its
/// range over the pool). The heuristic `compare-designs` measures against.
std::vector<int> farthestReadings(const ReadingPool& pool, int count);

/// `count` distinct readings drawn uniformly (generator (seed, draw)).
std::vector<int> randomReadings(const ReadingPool& pool, int count, std::uint64_t seed, int draw);

}  // namespace artcal
