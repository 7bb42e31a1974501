#pragma once
// The held-out model choice of `"calibrate": "identifiable"` on measured readings (issue 29,
// docs/calibrate-your-robot.md, docs/method.md section 5). The rank rule keeps every parameter the
// readings determine beyond the model mismatch; a parameter they determine only weakly may still
// carry more of the mismatch than of the machine, and hold worse on readings the fit never saw.
//
// Candidates: the rank rule's kept set and nested subsets of it, the parameter with the smallest
// surviving fraction of information (1 / (S_K^-1)_ii, S the scaled reduced information at the
// estimate, K the current set) held at nominal first; only parameters whose surviving fraction is
// below kCandidateFraction are candidates for removal, at most kMaxRemoved of them. Each candidate
// is fitted to every reading from the rank rule's estimate (a warm start).
//
// Judged on held-out readings: with 2 placements (stations) or more, leave one placement out.
// Each fold is one Gauss-Newton step from the candidate's estimate with the placement's reduced
// normal terms removed (N - N_j, b - b_j: exact for a linear model, from the blocks the
// calibrator already built), and the left-out placement's misfit after its own rigid motion is
// re-fitted: q_j = c_j - 2 b_j^T dg + dg^T N_j dg, per its degrees of freedom (held-out chi2/dof).
// Predicted for readings that scatter as the fit's own: chi2/dof (1 + tr(N_j (N - N_j)^-1) /
// dof_j), pooled. With one placement the table shows Mallows' Cp with the rank rule's scatter,
// (chi2_k + 2 k s^2) / (dof_k + k).
//
// A smaller candidate replaces the rank rule's set only when it is clearly better: a lower
// pooled held-out error, and lower in so many folds that a candidate no better would be so in at
// most kSignificance of cases (one-sided sign test over the folds: all 5 of 5, all 7 of 7, 7 of 8,
// 8 of 9, ...; never with fewer than kMinFolds placements). The chosen one is the lowest pooled
// error among those.
//
// One more candidate where the weak-direction rule held parameters (surviving fraction below
// kWeakInformationTolerance: a numerical guard, not a test of the readings): the rank rule's set
// with them calibrated again. It is the set the information determines, so it is judged the
// other way round: taken when converged, plausible (no correction flagged, corrections.hpp) and
// lower held out, pooled and in more than half of the folds, or by Cp with one placement (AIC:
// the chi2 falls by more than 2 s^2 per parameter restored).

#include <optional>

#include "artcal/calibration/calibrator.hpp"
#include "artcal/calibration/model_choice_result.hpp"
#include "artcal/estimation/identifiability.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// A parameter is a candidate for removal when its surviving fraction is below this.
inline constexpr double kCandidateFraction = 1e-2;
/// At most this many parameters removed (candidates beyond the rank rule's set).
inline constexpr int kMaxRemoved = 6;
/// A smaller set is taken with at least this many placements (a sign test over fewer folds can
/// never reach kSignificance).
inline constexpr int kMinFolds = 5;
/// The sign test's level: how often chance may make a candidate look better in the folds.
inline constexpr double kSignificance = 0.05;

/// The one-sided sign test over the folds: the probability that a candidate no better than the
/// reference is lower in at least `lower` of `folds` folds (each fold a fair coin), the binomial
/// tail sum_{i >= lower} C(folds, i) / 2^folds.
double signTestLevel(int lower, int folds);

/// One placement's part of a linearisation at an estimate, its rigid motion eliminated:
/// cost_j(dg) ~ misfit - 2 b^T dg + dg^T N dg over g = (p, c), dof its coordinates less its
/// observed rigid directions.
struct PlacementTerms {
  Eigen::MatrixXd N;
  Eigen::VectorXd b;
  double misfit = 0.0;
  int dof = 0;
};

/// Each placement's terms from the blocks of `linearization` (the calibrator's own, at its state).
std::vector<PlacementTerms> placementTerms(const Plan& plan,
                                           const std::vector<Placement>& placements,
                                           const Linearization& linearization);

/// Leave one placement out from a linearisation at the estimate: per placement, its held-out
/// chi2 (one Gauss-Newton step of the others, its rigid motion re-fitted) and the trace
/// tr(N_j (N - N_j)^-1) the prediction adds to its dof.
struct LeaveOneOut {
  std::vector<double> chi2;
  std::vector<double> trace;
  std::vector<int> dof;
};
LeaveOneOut leaveOnePlacementOut(const Linearization& linearization,
                                 const std::vector<PlacementTerms>& terms);

/// The choice made, and the state the chosen candidate converged at (its warm start).
struct ModelChoiceOutcome {
  ModelChoice choice;
  CalibrationState chosen_state;
};

/// Runs the choice after the rank rule's calibration: `plan.machine.calibrated` is the rank rule's
/// set, `calibrator` the one that produced `calibration` (its linearisation at the estimate),
/// `information` the information at the estimate over that set. `plan` is not changed (each
/// candidate is fitted with its own copy, whose calibrated set is the candidate's); std::nullopt
/// when there is nothing to choose (not converged, no candidate).
std::optional<ModelChoiceOutcome> chooseKeptSet(const Plan& plan, const CalibrationOptions& options,
                                                const Calibrator& calibrator,
                                                const Calibration& calibration,
                                                const PlanInformation& information);

}  // namespace artcal
