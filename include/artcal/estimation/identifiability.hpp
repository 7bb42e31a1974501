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
// S = D^-1/2 N_red D^-1/2, eigenvalues below `tolerance` times the largest mark a deficiency,
// and their eigenvectors are the parameter combinations the plan cannot separate. A parameter
// whose information the rigid motions absorb (j1.theta, j1.d of a serial arm: reduced/unreduced
// ~ 1e-13) is thus unidentifiable; scaling by N_red's own diagonal would blow its rounding
// residue up to 1. A parameter whose sqrt(D_i) is at most kUnobservedScale times the largest is
// not observed at all (scale 0). The null space is reported in reduced row-echelon form, so that
// a parameter unidentifiable on its own appears alone; coefficients are in the scaled parameters.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "artcal/plan/plan.hpp"

namespace artcal {

struct CountingCondition {
  int N_p = 0;                       ///< calibrated parameters
  int N_b = 0;                       ///< valued coordinates observed, sum of n o k
  int N_r = 0;                       ///< rigid-motion unknowns, sum of the effective N(r_j)
  int N_r_table = 0;                 ///< sum of the table values N(r_j) of the artifact kinds
  std::vector<int> rigid_table;      ///< per placement, the table value
  std::vector<int> rigid_effective;  ///< per placement, the rank of its rigid block
  bool satisfied = false;
  /// Placements needed when all are alike the first one: ceil(N_p / (n o k - N(r))), or -1
  /// when a placement gives no more equations than unknowns.
  int minimum_alike = -1;
};

/// The information of p a set of placements gives (evaluator.hpp, planInformation).
struct PlanInformation {
  Eigen::MatrixXd reduced;             ///< N_red of p (c eliminated with its prior)
  Eigen::VectorXd unreduced_diagonal;  ///< diag(sum_j A_pj^T A_pj), the rank test's scale
  std::vector<int> rigid_ranks;        ///< per placement, observed rigid directions
};

struct Combination {
  std::vector<std::string> names;
  std::vector<double> coefficients;  ///< scaled parameters, largest magnitude 1
};

struct Identifiability {
  CountingCondition counting;
  int rank = 0;
  int deficiency = 0;
  double condition_number = 0.0;  ///< of the scaled N_red (largest / smallest eigenvalue)
  double tolerance = 0.0;
  std::vector<Combination> unidentifiable;
  /// When deficient: the calibrated parameters to fix (keep at nominal) so that the rest is
  /// identifiable with these placements (chooseIdentifiableSet in the plan's order).
  std::vector<std::string> to_fix;
  bool identifiable() const { return counting.satisfied && deficiency == 0; }
};

inline constexpr double kDefaultRankTolerance = 1e-10;
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
  /// Per dropped parameter: the combination (positions, scaled coefficients, the dropped one
  /// +1) the plan cannot tell from zero.
  std::vector<std::vector<std::pair<int, double>>> ties;
};

/// The greedy rule of docs/models.md section 1: S over all listed parameters; a parameter with
/// sqrt(D_i) <= kUnobservedScale max sqrt(D) is never kept; parameter i is kept when the smallest
/// eigenvalue of S over kept + {i} exceeds `tolerance` times the largest eigenvalue of S over all
/// listed parameters.
CalibratedSetChoice chooseIdentifiableSet(const PlanInformation& information,
                                          double tolerance = kDefaultRankTolerance);

/// Which of the plan's listed parameters (machine.calibrated, in preferred order) the nominal
/// readings of `placements` identify (chooseIdentifiableSet), as model parameter indices.
CalibratedSetResolution resolveListedSet(const Plan& plan,
                                         const std::vector<Placement>& placements);

/// Resolves the plan's `"calibrate": "identifiable"` once, at its nominal readings: sets
/// machine.calibrated to the kept parameters and records the dropped ones and their ties in
/// plan.calibrate_resolution. Does nothing unless machine.calibrate_identifiable; a plan without
/// placements keeps its listed parameters (nothing to decide from).
void resolveCalibratedSet(Plan& plan);

}  // namespace artcal
