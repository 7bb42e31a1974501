#pragma once
// The evaluator: plan -> observation blocks -> reduced normal matrix -> V_p -> tip uncertainty
// (docs/method.md sections 3-5). It computes before any measurement: it needs the nominal
// parameters and the planned readings only.
//
// Rank policy: when the information of p is singular (identifiability.hpp), V_p does not exist.
// The evaluation then says so (identifiable() false) and carries no uncertainties, rather than
// numbers from a pseudo-inverse that would look meaningful and are not.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "artcal/estimation/evaluation_result.hpp"
#include "artcal/estimation/identifiability.hpp"
#include "artcal/estimation/normal_matrix.hpp"
#include "artcal/estimation/tip.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// Inverse of a (positive definite) information matrix; std::nullopt when it is not.
std::optional<ParameterCovariance> covarianceFromInformation(const Eigen::MatrixXd& information);

/// The information of p for a set of placements at parameters p (full vector), each r_j fitted,
/// the machine's parameter prior included (its inverse is V_p).
Eigen::MatrixXd placementsInformation(const Plan& plan, const std::vector<Placement>& placements,
                                      const Eigen::VectorXd& p);
/// The same with what the rank policy needs (identifiability.hpp): the unreduced diagonal and
/// each placement's observed rigid directions. Without `with_estimable` (a rank decision alone)
/// PlanInformation::estimable is left empty and its second pass skipped.
PlanInformation planInformation(const Plan& plan, const std::vector<Placement>& placements,
                                const Eigen::VectorXd& p, bool with_estimable = true);

/// The information the structural verdict reads (the "identifiable" set and the rank of check,
/// evaluate, optimize and calibrate alike, identifiability.hpp): planInformation at the machine
/// block's own values over the readings made consistent with them (consistent_readings.hpp), so
/// that measured readings of a machine off nominal give the verdict of their planned readings.
PlanInformation verdictInformation(const Plan& plan, const std::vector<Placement>& placements,
                                   bool with_estimable = true);

struct EvaluateOptions {
  double rank_tolerance = kDefaultRankTolerance;
  int profile_steps = 21;
};

Evaluation evaluatePlan(const Plan& plan, const EvaluateOptions& options = {});

/// Prepared, repeated evaluation (Pinocchio's model/data split): the plan is the immutable model;
/// this object holds the workspace Jacobians, computed once, and the scratch space reused by
/// every call. The optimizer re-evaluates candidate placements thousands of times through it.
/// Not thread-safe: one per thread.
class PlanEvaluator {
 public:
  /// Prepares the plan's own workspace (plan.workspace).
  explicit PlanEvaluator(const Plan& plan);
  PlanEvaluator(const Plan& plan, std::vector<Eigen::VectorXd> workspace);

  const Plan& plan() const { return *plan_; }
  /// The workspace's tip evaluator; on a machine with named tips, each configuration once per tip
  /// (tip t's copies the t-th block of workspaceSize()).
  const TipEvaluator& workspace() const { return tip_; }
  /// The number of workspace configurations (per tip).
  int workspaceSize() const { return workspace_size_; }

  /// The information of p for `placements` at the nominal parameters. `poses` gives each r_j;
  /// when null every r_j is fitted to the probed points.
  const Eigen::MatrixXd& information(const std::vector<Placement>& placements,
                                     const std::vector<RigidTransform>* poses = nullptr);
  /// V_p and the tip summary for `placements`; std::nullopt when V_p does not exist.
  std::optional<TipSummary> tip(const std::vector<Placement>& placements,
                                const std::vector<RigidTransform>* poses = nullptr);

 private:
  const Plan* plan_;
  int workspace_size_ = 0;
  TipEvaluator tip_;
  DesignMatrixBuilder builder_;
  NormalMatrixReducer reducer_;
  ObservationBlock block_;
  Eigen::MatrixXd information_;
};

}  // namespace artcal
