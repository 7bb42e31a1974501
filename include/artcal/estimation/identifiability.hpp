#pragma once
// Identifiability (docs/method.md section 5).
//
// The counting condition sum_j (N(b_j) - N(r_j)) >= N(p) is necessary, not sufficient. N(r_j)
// is the effective one: the rank of the placement's rigid block (normal_matrix.hpp), which can be
// lower than the table value of the artifact kind (a 2-D step gauge probed on its axis sees 1
// direction, not 2), so the count is never stricter than the rank test.
//
// Rank policy (docs/method.md section 5): the real test is the numerical rank of the information of
// p, N_red, scaled by the *unreduced* diagonal D = diag(sum_j A_pj^T A_pj):
// S = D^-1/2 N_red D^-1/2. An eigenvalue of S is the fraction of a direction's own information
// that survives the elimination of the rigid motions and of the other parameters; one at or below
// `tolerance` (absolute, 1e-10) marks a deficiency, also when it is the only parameter, and the
// eigenvectors are the combinations the plan cannot separate. The rigid motions are eliminated
// with each placement's *full* rigid block (design_matrix.hpp), so a parameter that moves the
// whole machine rigidly (j1.theta, j1.d of a serial arm, a base rotation of a URDF chain) keeps
// only rounding (~1e-13) whatever the readings' scatter; scaling by N_red's own diagonal would
// blow that residue up to 1. A parameter whose sqrt(D_i) is at most kUnobservedScale times the
// largest is not observed at all (scale 0). The null space is reported in reduced row-echelon
// form, so that a parameter unidentifiable on its own appears alone; coefficients are in the
// scaled parameters.
//
// Two thresholds, two questions (docs/method.md section 5): check, evaluate and optimize decide
// what planned readings can separate at all (kDefaultRankTolerance). Calibrating *measured*
// readings with "identifiable" further holds at nominal every parameter whose surviving fraction
// is below kWeakInformationTolerance (1e-6, the independent reference's |R_kk|/|R_00| > 1e-3 of a
// column-pivoted QR of the column-scaled reduced Jacobian): information of the order of the model
// mismatch, not of the data (weaklyDetermined, calibration/calibrate_plan.hpp).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "artcal/artifact/rigid_transform.hpp"
#include "artcal/estimation/identifiability_result.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// The information of p a set of placements gives (evaluator.hpp, planInformation).
struct PlanInformation {
  /// N_red of p (c eliminated with its prior), each placement's full rigid motion eliminated
  /// where its readings observe it: what the rank decisions use (a base rotation absorbed).
  Eigen::MatrixXd reduced;
  /// N_red with each placement eliminating only the rigid directions its calibrated features
  /// see (a ball bar's roll is a gauge: the Fisher information of ideal readings does not lose
  /// to it): what V_p is the inverse of. Equal to `reduced` on consistent readings; on real ones
  /// the roll the mismatch makes look observed would otherwise take a share of every
  /// parameter's information, however weakly it is observed.
  Eigen::MatrixXd estimable;
  Eigen::VectorXd unreduced_diagonal;  ///< diag(sum_j A_pj^T A_pj), the rank test's scale
  std::vector<int> rigid_ranks;        ///< per placement, observed rigid directions
  /// Per placement, r_j at p: its pose, or the rigid fit to its readings (fitPlacements).
  std::vector<RigidTransform> poses;
};

inline constexpr double kDefaultRankTolerance = 1e-10;
/// Surviving fraction below which calibrate holds a parameter of measured readings at nominal
/// ("weakly determined": of the order of the model mismatch, docs/method.md section 5).
inline constexpr double kWeakInformationTolerance = 1e-6;
/// A parameter the structural rule dropped is calibrated in place of weakly determined ones only
/// where its own surviving fraction after the kept ones is at least this (the held-out model
/// choice's bound of a parameter beyond question, model_choice.hpp's kCandidateFraction): a
/// direction the readings determine well, such as a tool length; a weaker one would carry the
/// model mismatch as the held one did.
inline constexpr double kBroughtBackFraction = 1e-2;
/// sqrt(D_i) at most this fraction of the largest: the parameter is not observed at all.
inline constexpr double kUnobservedScale = 1e-9;

/// The counting condition; with `effective_rigid` (one per placement, PlanInformation) N(r) is
/// the effective count, else the table values.
CountingCondition countingCondition(const Plan& plan, const std::vector<Placement>& placements,
                                    const std::vector<int>* effective_rigid = nullptr);

/// Counting condition with the effective N(r_j), rank of S (see above), the combinations.
Identifiability analyseIdentifiability(const Plan& plan, const std::vector<Placement>& placements,
                                       const PlanInformation& information,
                                       double tolerance = kDefaultRankTolerance);

/// The rank test's scaled matrix S = D^-1/2 N_red D^-1/2 (unreduced D; unobserved parameters get
/// a zero row and column).
Eigen::MatrixXd scaledInformation(const PlanInformation& information);

/// `"calibrate": "identifiable"` resolved (docs/models.md section 1): which of the listed
/// parameters (machine.calibrated, in preferred order) the plan's nominal readings identify.
struct CalibratedSetChoice {
  std::vector<int> kept;     ///< positions into the listed parameters, in order
  std::vector<int> dropped;  ///< positions into the listed parameters
  /// Per dropped parameter: the smallest eigenvalue of S over kept + {it}, the fraction of its
  /// information that survives (0 when it is not observed at all).
  std::vector<double> dropped_fraction;
  /// Per dropped parameter: the combination (positions, scaled coefficients, the dropped one
  /// +1) the plan cannot tell from zero.
  std::vector<std::vector<std::pair<int, double>>> ties;
};

/// The greedy rule of docs/models.md section 1: S over all listed parameters; a parameter with
/// sqrt(D_i) <= kUnobservedScale max sqrt(D) is never kept; parameter i is kept when the smallest
/// eigenvalue of S over kept + {i} exceeds `tolerance` (absolute: a surviving fraction).
CalibratedSetChoice chooseIdentifiableSet(const PlanInformation& information,
                                          double tolerance = kDefaultRankTolerance);

/// The greedy rule in the order of QR with column pivoting of the scaled reduced Jacobian
/// (Cholesky of S with diagonal pivoting: next, the parameter whose information surviving the ones
/// before it is the largest) instead of the listed order; the same size as chooseIdentifiableSet's
/// in general, and the same set whatever order the parameters are listed in (ties aside). Kept and
/// dropped are reported in the listed order. With `max_kept` (>= 0), at most that many are kept,
/// the first in the pivoted order. `first` (positions): pivoted before every other one (among
/// themselves in the pivoted order); `last`: after every other one. With `later_fraction` > 0,
/// one not in `first` is kept only where its own surviving fraction after the kept ones is at
/// least that.
CalibratedSetChoice choosePivotedSet(const PlanInformation& information, double tolerance,
                                     int max_kept = -1, const std::vector<int>& first = {},
                                     const std::vector<int>& last = {},
                                     double later_fraction = 0.0);

/// The weak rule over every listed parameter (docs/method.md section 5, "Real readings"), what
/// calibrate applies to measured readings at the nominal parameters and again at the estimate:
/// QR with column pivoting of the scaled reduced Jacobian of every parameter "identifiable"
/// listed (choosePivotedSet), from the readings made consistent with the machine at p
/// (consistent_readings.hpp: the layout's information, not the misfit's), keeping a parameter
/// while its surviving fraction exceeds kWeakInformationTolerance. The kept set spans the same
/// directions whatever order the parameters are listed in (of an exact tie, the first listed),
/// and a parameter the structural rule dropped as tied to one the weak rule holds carries that
/// direction again (a tool length tied to a wrist's twist by a tool 0.09 mm off the last axis).
/// The weak rule for a plan with a resolved "identifiable" set (calibrate_resolution), at p (the
/// calibration's estimate), keeping at most as many as the plan's calibrated set: at the estimate
/// it holds, never adds. `structural` the set the structural rule kept (what held and in_place
/// are counted against). At the nominal parameters the rule's choice is computed once, with the
/// structural verdict (CalibratedSetResolution::at_nominal).
WeakRuleChoice weakRuleChoice(const Plan& plan, const std::vector<int>& structural,
                              const Eigen::VectorXd& p);

/// Which of the plan's listed parameters (machine.calibrated, in preferred order) the nominal
/// readings of `placements` identify (chooseIdentifiableSet), as model parameter indices.
/// `last` (model parameter indices) are ranked last by the weak rule's pivoting
/// (CalibratedSetResolution::last).
CalibratedSetResolution resolveListedSet(const Plan& plan, const std::vector<Placement>& placements,
                                         const std::vector<int>& last = {});

/// Resolves the plan's `"calibrate": "identifiable"` once, at its nominal readings: sets
/// machine.calibrated to the kept parameters and records the dropped ones and their ties in
/// plan.calibrate_resolution. Does nothing unless machine.calibrate_identifiable; a plan without
/// placements keeps its listed parameters (nothing to decide from), and so does a plan whose
/// readings identify none of them (check then says NOT IDENTIFIABLE, as for a listed set; a spec's
/// design decides, resolveOnDesigns).
void resolveCalibratedSet(Plan& plan);

}  // namespace artcal
