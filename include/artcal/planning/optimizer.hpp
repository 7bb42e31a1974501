#pragma once
// The planner (docs/method.md section 7): places `design.placements` copies of the design's
// artifact (each feature probed in `design.postures` postures) so that the criterion is as small as
// it can be. Every criterion is a length in mm, smaller is better:
//   worst-tip  G = max_q S(q) over the plan's workspace (minimax, G-optimality)
//   mean-tip   sqrt(mean_q S(q)^2)  (the root of the I criterion)
//   D          det(V_s)^(1/(2 N_p)),  A  sqrt(tr V_s / N_p),  E  sqrt(lambda_max(V_s))
//   pass       1 - P(pass) of the plan's ISO 10360-2 acceptance test (dimensionless; the mean of
//              the exact P(pass | dp) over 256 fixed draws of dp,
//              acceptance/length_acceptance.hpp), or, where P(pass) saturates, the 95 % quantile
//              of max |E|/MPE (PassObjective below)
// where V_s is V_p with every angle parameter scaled by the machine's reach (mm per rad), so
// that all parameters share a unit.
//
// Search, per start (seeded by (seed, start index) alone, so that the plan does not depend on
// the thread count):
//  1. a random initial design drawn from a candidate pool (feasible placements, seeded);
//  2. Fedorov exchange: each placement adds an independent term to the reduced information
//     (docs/method.md section 3), so the pool's terms are computed once and a swap is a sum;
//  3. continuous refinement of all poses with a derivative-free NLopt algorithm on the
//     criterion (worst-tip: the max itself, or a p-norm smooth max), readings re-solved by IK
//     from the starting postures; an infeasible pose gets a penalty.
// The best start wins (ties: the lower start index). A start's result is never worse than its
// initial design. `time_limit` stops the search (start 0 always runs, cut short if need be):
// then the result depends on the timing and is reported as such.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "artcal/core/enum_names.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/plan/plan.hpp"
#include "artcal/planning/design_space.hpp"

namespace artcal {

enum class RefineAlgorithm { None, Subplex, Bobyqa, NelderMead, Cobyla };
/// The refinement algorithms by their names on the command line (`optimize --algorithm`).
inline constexpr EnumNames<RefineAlgorithm, 5> kRefineAlgorithmNames{
    {{RefineAlgorithm::None, "none"},
     {RefineAlgorithm::Subplex, "sbplx"},
     {RefineAlgorithm::Bobyqa, "bobyqa"},
     {RefineAlgorithm::NelderMead, "neldermead"},
     {RefineAlgorithm::Cobyla, "cobyla"}}};
std::string refineAlgorithmName(RefineAlgorithm algorithm);
std::optional<RefineAlgorithm> refineAlgorithmFromName(const std::string& name);

struct OptimizerProgress {
  int starts_done = 0;
  int starts = 0;
  double best = 0.0;     ///< criterion value of the best plan so far, mm
  double elapsed = 0.0;  ///< s
};

struct OptimizerOptions {
  Criterion criterion = Criterion::WorstTip;
  std::uint64_t seed = 1;
  int starts = 16;
  double time_limit = 60.0;  ///< s, whole search
  int pool_size = 0;         ///< candidate placements; 0: automatic
  int exchange_passes = 12;  ///< at most, per start
  RefineAlgorithm algorithm = RefineAlgorithm::Subplex;
  int refine_evaluations = 0;  ///< per start; 0: automatic (by the number of pose variables)
  double smooth_power = 0.0;   ///< worst-tip refinement: 0 the max itself, p > 0 a p-norm
  int polish = 0;   ///< the best designs polished at the end (refinement restarted, then kicked)
  int kicks = 0;    ///< iterated-local-search kicks per polished design
  int threads = 0;  ///< 0: the hardware's
  std::function<void(const OptimizerProgress&)> progress;  ///< called after each start

  /// The spec's design block (criterion, seed, starts, time_limit) over the defaults.
  static OptimizerOptions fromDesign(const DesignSpec& design);
  bool isValid(std::string* why) const;
};

/// The "pass" criterion (docs/method.md section 9, "Planning for the test"). P = P(pass) is the
/// mean of M = kPassDraws exact conditional probabilities p_m = P(pass | dp_m), each in [0, 1],
/// so its Monte-Carlo standard error is at most the binomial sqrt(P (1 - P) / M). P saturates
/// when it lies within that standard error of 1 or of 0, i.e. min(P, 1 - P) <= 1 / (M + 1): the
/// draws cannot tell it from certain success (or failure), and the search would have nothing to
/// improve. There the objective is q95, the 95 % quantile of max |E|/MPE under the same draws
/// (q95 <= 1 when P saturates at 1: the margin to the MPE; q95 >= 1 at 0: how far from passing).
/// One scalar ranks every design, smaller better, the regimes in disjoint ranges (eps = 1/(M+1)):
///   saturated at 1   eps q95          in [0, eps]
///   not saturated    1 - P            in (eps, 1 - eps)
///   saturated at 0   (1 - eps) q95    in [1 - eps, inf)
/// so a design that passes surely beats one that may fail, and one that may pass beats one that
/// surely fails.
inline constexpr int kPassDraws = 256;

struct PassObjective {
  enum class Quantity { FailProbability, Quantile95 };
  Quantity quantity = Quantity::FailProbability;
  double value = 0.0;  ///< 1 - P(pass), or q95 of max |E|/MPE
  /// "1 - P(pass)" or "q95 of max |E|/MPE".
  std::string name() const;
};

/// The criterion's scalar from P(pass) and q95 (q95 is only read when P saturates).
double passCriterionValue(double p_pass, double q95);
/// The quantity a criterion value stands for (the inverse of passCriterionValue's ranges).
PassObjective passObjectiveOf(double criterion_value);

/// The pass criterion's figures for one design.
struct PassEstimate {
  double p_pass = 0.0;
  double standard_error = 0.0;  ///< sqrt(P (1 - P) / M), the bound above
  double q95 = 0.0;             ///< of max |E|/MPE
  bool saturated = false;
  double value = 0.0;  ///< passCriterionValue(p_pass, q95)
};

struct StartResult {
  double initial = 0.0;    ///< the random initial design
  double exchanged = 0.0;  ///< after the exchange
  double refined = 0.0;    ///< after the continuous refinement (the start's result)
  /// The criterion of the refined design (the fixed placements' information included) where the
  /// polish started from it; 0 when the start was not polished.
  double polished_from = 0.0;
  bool done = false;
};

struct OptimizerSummary {
  enum class Termination { Completed, TimeLimit };
  Termination termination = Termination::Completed;
  std::vector<Placement> placements;  ///< the designed placements (the spec's fixed ones apart)
  double value = 0.0;  ///< criterion of the best plan, mm (pass: passCriterionValue, ranking)
  Criterion criterion = Criterion::WorstTip;
  std::optional<PassEstimate> pass;  ///< Criterion::Pass: the best plan's figures
  int best_start = -1;
  std::vector<StartResult> starts;
  int pool_size = 0;
  double seconds = 0.0;
  std::string message;
  int startsDone() const;
  std::string briefReport() const;
  /// The summary of a search's starts: the best finished start (lowest refined value), the
  /// termination and the time; without one, best_start -1 and the message says so. The search
  /// then fills the best start's placements (and the message, briefReport).
  static OptimizerSummary ofStarts(Criterion criterion, std::vector<StartResult> starts,
                                   int pool_size, bool timed_out, double seconds);
};

/// Evaluates the criterion of designs from their placements' additive information terms.
/// Holds prepared workspace Jacobians and scratch: one per thread.
struct PassCriterionData;

class DesignCriterion {
 public:
  DesignCriterion(const Plan& plan, Criterion criterion, double smooth_power = 0.0);

  /// One placement's information term over g = (p, c), r_j fitted at the nominal parameters.
  Eigen::MatrixXd contribution(const Placement& placement);
  /// The criterion (mm) of the design whose information terms sum to `information_g`;
  /// +infinity when V_p does not exist.
  double value(const Eigen::MatrixXd& information_g);
  /// The same with the worst-tip max replaced by the smooth p-norm when smooth_power > 0.
  double smoothValue(const Eigen::MatrixXd& information_g);
  int globalSize() const { return layout_.size(); }
  /// Criterion::Pass: P(pass), its standard error and q95 (always computed) of the design;
  /// std::nullopt when V_p does not exist. std::logic_error for another criterion.
  std::optional<PassEstimate> passEstimate(const Eigen::MatrixXd& information_g);

  // Active set (worst-tip; docs/optimize.md, "How it searches"): the max of S over a few
  // configurations where designs were found worst is a lower bound of G that costs a fraction
  // of the full workspace. The search ranks designs by it and confirms each decision with the
  // full max (activate), which adds the configurations that were missing, so a design is only
  // ever accepted on its true G. Other criteria: activeValue() = value().

  /// Empties the active set (each start begins afresh: the plan must not depend on threads).
  void resetActive();
  /// The criterion over the active set (worst-tip), or value() when it is empty or unused.
  double activeValue(const Eigen::MatrixXd& information_g);
  /// value(), after adding to the active set the configurations where this design is worse
  /// than anywhere in it (the few worst of them).
  double activate(const Eigen::MatrixXd& information_g);
  int activeSize() const { return static_cast<int>(active_.size()); }
  /// S (mm) at each configuration of the active set (worst-tip); false, and `S` untouched,
  /// when V_p does not exist or the set is empty.
  bool activeTip(const Eigen::MatrixXd& information_g, Eigen::VectorXd& S);

 private:
  double evaluate(const Eigen::MatrixXd& information_g, double power);
  double worstOver(const Eigen::MatrixXd& V, const TipEvaluator& tip);
  const Plan* plan_;
  Criterion criterion_;
  double smooth_power_;
  GlobalLayout layout_;
  PlanEvaluator evaluator_;
  DesignMatrixBuilder builder_;
  NormalMatrixReducer reducer_;
  ObservationBlock block_;
  Eigen::VectorXd scale_, S_m2_;
  std::vector<int> active_;  ///< indices into the workspace configurations
  std::optional<TipEvaluator> active_tip_;
  std::shared_ptr<const PassCriterionData> pass_;  ///< Criterion::Pass
};

/// Refuses a design that cannot be identifiable by counting (docs/method.md section 5): InputError
/// at /design/placements.
void checkDesignCount(const Plan& plan);

/// Runs the search for `plan.design`; the plan's own placements stay fixed and count.
/// InputError when the region holds no feasible placement or the count cannot suffice.
OptimizerSummary optimizePlan(const Plan& plan, const OptimizerOptions& options);

}  // namespace artcal
