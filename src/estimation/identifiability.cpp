#include "artcal/estimation/identifiability.hpp"

#include "artcal/core/linear_algebra.hpp"
#include "artcal/estimation/consistent_readings.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/estimation/normal_matrix.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include "artcal/core/dense_decompositions.hpp"

namespace artcal {

CountingCondition countingCondition(const Plan& plan, const std::vector<Placement>& placements,
                                    const std::vector<int>* effective_rigid) {
  CountingCondition count;
  count.N_p = plan.machine.calibratedCount();
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placements[j].artifact)];
    count.N_b += artifact.rowsPerReading() * static_cast<int>(placements[j].measurements.size());
    const int table = artifact.rigidDof();
    // What the readings see, but never more than the calibrated features can: real readings make
    // a ball bar's roll look observed by their mismatch, which creates no equation.
    const int effective = effective_rigid && j < effective_rigid->size()
                              ? std::min((*effective_rigid)[j],
                                         rigidRankOfFeatures(artifact, placements[j].measurements))
                              : table;
    count.rigid_table.push_back(table);
    count.rigid_effective.push_back(effective);
    count.N_r_table += table;
    count.N_r += effective;
  }
  count.satisfied = count.N_b - count.N_r >= count.N_p;
  if (!placements.empty()) {
    const Placement& first = placements.front();
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(first.artifact)];
    const int per = artifact.rowsPerReading() * static_cast<int>(first.measurements.size()) -
                    count.rigid_effective.front();
    if (per > 0) count.minimum_alike = (count.N_p + per - 1) / per;
  }
  return count;
}

namespace {

// Reduced row-echelon form of the rows of B (each row a null vector), pivots taken in parameter
// order: a canonical, sparse basis of the null space.
Eigen::MatrixXd reducedRowEchelon(Eigen::MatrixXd B, double tolerance) {
  int row = 0;
  for (int col = 0; col < B.cols() && row < B.rows(); ++col) {
    Eigen::Index pivot;
    const double magnitude = B.col(col).tail(B.rows() - row).cwiseAbs().maxCoeff(&pivot);
    if (magnitude <= tolerance) continue;
    B.row(row).swap(B.row(row + static_cast<int>(pivot)));
    B.row(row) /= B(row, col);
    for (int r = 0; r < B.rows(); ++r) {
      if (r != row) B.row(r) -= B(r, col) * B.row(row);
    }
    ++row;
  }
  return B;
}

// The surviving fraction (section 5) of the machine's change of scale s: each calibrated length
// parameter in proportion to its nominal value. A uniform scale of an all-revolute machine maps a
// plane to a parallel plane, which the placement's offset absorbs: a single plane sees no length.
bool scaleUnobserved(const Plan& plan, const PlanInformation& information, double tolerance) {
  const Machine& machine = plan.machine;
  Eigen::VectorXd s = Eigen::VectorXd::Zero(machine.calibratedCount());
  for (int k = 0; k < s.size(); ++k) {
    if (!machine.calibratedInfo(k).quantity.isAngle())
      s[k] = machine.nominal[machine.calibrated[static_cast<std::size_t>(k)]];
  }
  const double own = s.dot(information.unreduced_diagonal.cwiseMax(0.0).asDiagonal() * s);
  if (!(own > 0.0) || s.size() != information.reduced.rows()) return false;
  return s.dot(information.reduced * s) / own <= tolerance;
}

}  // namespace

Eigen::MatrixXd scaledInformation(const PlanInformation& information) {
  const Eigen::MatrixXd& N = information.reduced;
  const int n = static_cast<int>(N.rows());
  // sqrt(D): a parameter nothing observes (rounding: a column that vanishes identically, e.g. a
  // serial arm's last alpha with the probe on that joint's x axis) keeps a zero row and column.
  const Eigen::VectorXd root = information.unreduced_diagonal.cwiseMax(0.0).cwiseSqrt();
  const double largest = n > 0 ? root.maxCoeff() : 0.0;
  Eigen::VectorXd scale(n);
  for (int i = 0; i < n; ++i) {
    const bool observed = root[i] > kUnobservedScale * largest && std::isfinite(root[i]);
    scale[i] = observed ? 1.0 / root[i] : 0.0;
  }
  return scale.asDiagonal() * N * scale.asDiagonal();
}

Identifiability analyseIdentifiability(const Plan& plan, const std::vector<Placement>& placements,
                                       const PlanInformation& information, double tolerance) {
  Identifiability result;
  result.counting = countingCondition(plan, placements, &information.rigid_ranks);
  result.tolerance = tolerance;
  const int n = static_cast<int>(information.reduced.rows());
  const Eigen::MatrixXd scaled = scaledInformation(information);
  const SymmetricEigenSolver eig(scaled);
  const Eigen::VectorXd& lambda = eig.eigenvalues();  // ascending
  const double largest = n > 0 ? lambda[n - 1] : 0.0;
  // Absolute (docs/method.md section 5): an eigenvalue of S is the fraction of a direction's own
  // information that survives the elimination; a relative test is vacuous for one parameter.
  std::vector<int> null;
  for (int i = 0; i < n; ++i) {
    if (!(lambda[i] > tolerance)) null.push_back(i);
  }
  result.deficiency = static_cast<int>(null.size());
  result.rank = n - result.deficiency;
  result.condition_number = result.deficiency == 0 && lambda[0] > 0.0
                                ? largest / lambda[0]
                                : std::numeric_limits<double>::infinity();
  if (null.empty()) return result;
  result.no_length_scale = scaleUnobserved(plan, information, tolerance);
  Eigen::MatrixXd basis(static_cast<int>(null.size()), n);
  for (std::size_t k = 0; k < null.size(); ++k) {
    basis.row(static_cast<int>(k)) = eig.eigenvectors().col(null[k]).transpose();
  }
  const Eigen::MatrixXd rref = reducedRowEchelon(basis, 1e-6);
  const auto& params = plan.machine.mechanism->parameters();
  for (int k : chooseIdentifiableSet(information, tolerance).dropped) {
    result.to_fix.push_back(params[static_cast<std::size_t>(plan.machine.calibrated[k])].name);
  }
  for (int r = 0; r < rref.rows(); ++r) {
    const double largest_coefficient = rref.row(r).cwiseAbs().maxCoeff();
    if (largest_coefficient <= 0.0) continue;
    Combination combination;
    for (int i = 0; i < n; ++i) {
      const double c = rref(r, i) / largest_coefficient;
      if (std::abs(c) < 1e-6) continue;
      combination.names.push_back(
          params[static_cast<std::size_t>(plan.machine.calibrated[i])].name);
      combination.coefficients.push_back(c);
    }
    result.unidentifiable.push_back(std::move(combination));
  }
  return result;
}

namespace {

Eigen::MatrixXd principal(const Eigen::MatrixXd& S, const std::vector<int>& set) {
  const int n = static_cast<int>(set.size());
  Eigen::MatrixXd out(n, n);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) out(a, b) = S(set[a], set[b]);
  }
  return out;
}

double smallestEigenvalue(const Eigen::MatrixXd& M) {
  return SymmetricEigenSolver(M, Eigen::EigenvaluesOnly).eigenvalues()[0];
}

// The combination that ties a dropped parameter to the kept ones: the eigenvector of the
// smallest eigenvalue of S over kept + {dropped}, largest coefficient magnitude 1.
std::vector<std::pair<int, double>> tieOf(const Eigen::MatrixXd& S, std::vector<int> set) {
  const SymmetricEigenSolver eig(principal(S, set));
  Eigen::VectorXd v = eig.eigenvectors().col(0);
  const int last = static_cast<int>(set.size()) - 1;
  if (v[last] < 0.0) v = -v;  // the dropped parameter (last) with a positive sign
  v /= v.cwiseAbs().maxCoeff();
  std::vector<std::pair<int, double>> tie;
  // The dropped one first, then the kept ones it trades against.
  tie.emplace_back(set[last], v[last]);
  for (int i = 0; i < last; ++i) {
    if (std::abs(v[i]) >= 1e-6) tie.emplace_back(set[i], v[i]);
  }
  return tie;
}

// The fraction of parameter i's information that survives the elimination of the `kept` ones:
// S_ii - s^T S_KK^-1 s (the pivot of i after them in a Cholesky of S).
double survivingAfter(const Eigen::MatrixXd& S, const std::vector<int>& kept, int i) {
  if (kept.empty()) return S(i, i);
  Eigen::VectorXd s(static_cast<Eigen::Index>(kept.size()));
  for (std::size_t a = 0; a < kept.size(); ++a) s[static_cast<Eigen::Index>(a)] = S(kept[a], i);
  return S(i, i) - s.dot(principal(S, kept).ldlt().solve(s));
}

// What the greedy rule may keep beyond its cutoff: at most `max_kept` (-1: any number), and of
// the parameters not in `first` only those whose own surviving fraction after the kept ones is
// at least `later_fraction`.
struct GreedyLimits {
  int max_kept = -1;
  std::vector<int> first;
  double later_fraction = 0.0;
};

// The greedy rule along `order` (positions into S): a parameter is kept when the smallest
// eigenvalue of S over the kept ones and it exceeds `cutoff` (and `limits` allow it).
CalibratedSetChoice greedyAlong(const Eigen::MatrixXd& S, const std::vector<int>& order,
                                double cutoff, const GreedyLimits& limits = {}) {
  CalibratedSetChoice choice;
  const auto n = static_cast<int>(S.rows());
  // The smallest eigenvalue of S over kept + {i} exceeds the cutoff exactly when S - cutoff I over
  // kept + {i} is positive definite: its Cholesky factor L grows by one row per kept parameter, a
  // trial costs one forward substitution. Only a dropped parameter needs its eigenvalue (the
  // fraction it keeps) and its tie.
  Eigen::MatrixXd L(n, n);
  for (const int i : order) {
    const int k = static_cast<int>(choice.kept.size());
    Eigen::VectorXd column(k);
    for (int a = 0; a < k; ++a) column[a] = S(choice.kept[static_cast<std::size_t>(a)], i);
    const Eigen::VectorXd row = L.topLeftCorner(k, k).triangularView<Eigen::Lower>().solve(column);
    const double pivot = S(i, i) - cutoff - row.squaredNorm();
    // An unobserved parameter has a zero row and column in S (scaledInformation).
    const bool observed = S(i, i) > 0.0;
    const bool room = limits.max_kept < 0 || k < limits.max_kept;
    const bool later = limits.later_fraction > 0.0 &&
                       std::find(limits.first.begin(), limits.first.end(), i) == limits.first.end();
    const bool enough = !later || survivingAfter(S, choice.kept, i) >= limits.later_fraction;
    if (observed && pivot > 0.0 && room && enough) {
      L.row(k).head(k) = row.transpose();
      L(k, k) = std::sqrt(pivot);
      choice.kept.push_back(i);
      continue;
    }
    std::vector<int> trial = choice.kept;
    trial.push_back(i);
    const double surviving = observed ? smallestEigenvalue(principal(S, trial)) : 0.0;
    choice.dropped.push_back(i);
    choice.dropped_fraction.push_back(std::max(surviving, 0.0));
    choice.ties.push_back(tieOf(S, trial));
  }
  return choice;
}

// The order of Cholesky with diagonal pivoting of S, which is QR with column pivoting of the
// scaled reduced Jacobian (S = J^T J): next, the parameter whose information surviving the ones
// before it, |R_kk|^2, is the largest. Parameters nothing observes come last.
// `first` and `last` (positions) make three tiers: every one of `first` is pivoted before the
// others, every one of `last` after them.
std::vector<int> pivotedOrder(const Eigen::MatrixXd& S, const std::vector<int>& first,
                              const std::vector<int>& last) {
  const auto n = static_cast<int>(S.rows());
  Eigen::VectorXd remaining = S.diagonal();
  Eigen::MatrixXd L = Eigen::MatrixXd::Zero(n, n);
  std::vector<bool> taken(static_cast<std::size_t>(n), false);
  std::vector<int> tier(static_cast<std::size_t>(n), 1);
  for (const int i : first) tier[static_cast<std::size_t>(i)] = 0;
  for (const int i : last) tier[static_cast<std::size_t>(i)] = 2;
  // Whether i goes before `best`: a lower tier, else the larger remaining information.
  const auto before = [&](int i, int best) {
    const int a = tier[static_cast<std::size_t>(i)], b = tier[static_cast<std::size_t>(best)];
    if (a != b) return a < b;
    return remaining[i] > remaining[best];
  };
  std::vector<int> order;
  for (int k = 0; k < n; ++k) {
    int best = -1;
    for (int i = 0; i < n; ++i) {
      if (taken[static_cast<std::size_t>(i)]) continue;
      if (best < 0 || before(i, best)) best = i;
    }
    taken[static_cast<std::size_t>(best)] = true;
    order.push_back(best);
    if (!(remaining[best] > 0.0)) continue;  // the rest: rounding, in the listed order
    const double root = std::sqrt(remaining[best]);
    for (int i = 0; i < n; ++i) {
      if (taken[static_cast<std::size_t>(i)]) continue;
      const double l = (S(i, best) - L.row(i).head(k).dot(L.row(best).head(k))) / root;
      L(i, k) = l;
      remaining[i] -= l * l;
    }
  }
  return order;
}

}  // namespace

CalibratedSetChoice chooseIdentifiableSet(const PlanInformation& information, double tolerance) {
  const Eigen::MatrixXd S = scaledInformation(information);
  std::vector<int> listed(static_cast<std::size_t>(S.rows()));
  std::iota(listed.begin(), listed.end(), 0);
  // Absolute cutoff on the surviving fraction (docs/method.md section 5): a lone absorbed
  // parameter (j1.theta alone) is dropped too.
  return greedyAlong(S, listed, tolerance);
}

CalibratedSetChoice choosePivotedSet(const PlanInformation& information, double tolerance,
                                     int max_kept, const std::vector<int>& first,
                                     const std::vector<int>& last, double later_fraction) {
  const Eigen::MatrixXd S = scaledInformation(information);
  CalibratedSetChoice choice =
      greedyAlong(S, pivotedOrder(S, first, last), tolerance, {max_kept, first, later_fraction});
  // Reported in the listed order, as chooseIdentifiableSet's.
  std::sort(choice.kept.begin(), choice.kept.end());
  std::vector<std::size_t> by_position(choice.dropped.size());
  std::iota(by_position.begin(), by_position.end(), std::size_t{0});
  std::sort(by_position.begin(), by_position.end(),
            [&](std::size_t x, std::size_t y) { return choice.dropped[x] < choice.dropped[y]; });
  CalibratedSetChoice sorted;
  sorted.kept = std::move(choice.kept);
  for (const std::size_t d : by_position) {
    sorted.dropped.push_back(choice.dropped[d]);
    sorted.dropped_fraction.push_back(choice.dropped_fraction[d]);
    sorted.ties.push_back(choice.ties[d]);
  }
  return sorted;
}

namespace {

// Whether the parameters at `positions` pass the rule together: the smallest eigenvalue of S
// over them exceeds `tolerance`, which is when the greedy rule along any order keeps every one.
bool passesTogether(const Eigen::MatrixXd& S, const std::vector<int>& positions, double tolerance) {
  if (positions.empty()) return true;
  return smallestEigenvalue(principal(S, positions)) > tolerance;
}

bool contains(const std::vector<int>& set, int index) {
  return std::find(set.begin(), set.end(), index) != set.end();
}

}  // namespace

namespace {

// The weak rule's choice from the information over every listed parameter (weakRuleChoice).
std::vector<int> positionsIn(const std::vector<int>& listed, const std::vector<int>& indices) {
  std::vector<int> out;
  for (const int index : indices) {
    const auto at = std::find(listed.begin(), listed.end(), index);
    if (at != listed.end()) out.push_back(static_cast<int>(at - listed.begin()));
  }
  return out;
}

WeakRuleChoice weakChoiceFrom(const PlanInformation& information, const std::vector<int>& listed,
                              const std::vector<int>& structural, const std::vector<int>& current,
                              int max_kept, const std::vector<int>& last) {
  // The current set first (the structural rule's, or the last stage's), its weak directions held
  // in the pivoted order among it; then the others, in the pivoted order, where they carry a
  // direction the kept ones do not: a tie the structural rule broke in the listed order changes
  // only where its kept member is weak.
  const CalibratedSetChoice choice = choosePivotedSet(
      information, kWeakInformationTolerance, max_kept, positionsIn(listed, current),
      positionsIn(listed, last), kBroughtBackFraction);
  WeakRuleChoice out;
  for (const int k : choice.kept) out.kept.push_back(listed[static_cast<std::size_t>(k)]);
  for (std::size_t d = 0; d < choice.dropped.size(); ++d) {
    const int index = listed[static_cast<std::size_t>(choice.dropped[d])];
    if (!contains(structural, index)) continue;
    out.held.push_back(index);
    out.held_fraction.push_back(choice.dropped_fraction[d]);
  }
  for (const int index : out.kept)
    if (!contains(structural, index)) out.in_place.push_back(index);
  out.current_passes = passesTogether(scaledInformation(information), positionsIn(listed, current),
                                      kWeakInformationTolerance);
  return out;
}

}  // namespace

WeakRuleChoice weakRuleChoice(const Plan& plan, const std::vector<int>& structural,
                              const Eigen::VectorXd& p) {
  const std::vector<int>& listed = plan.calibrate_resolution->listed;
  Plan all = plan;
  all.machine.calibrated = listed;
  const auto consistent = consistentPlacements(all, all.placements, p);
  const PlanInformation information =
      planInformation(all, consistent ? *consistent : all.placements, p, false);
  // At the estimate the rule holds, never adds: ties the estimate's own values break (a few
  // micrometres of a location error) are no information the nominal layout had.
  return weakChoiceFrom(information, listed, structural, plan.machine.calibrated,
                        static_cast<int>(plan.machine.calibrated.size()),
                        plan.calibrate_resolution->last);
}

CalibratedSetResolution resolveListedSet(const Plan& plan, const std::vector<Placement>& placements,
                                         const std::vector<int>& last) {
  const PlanInformation information =
      verdictInformation(plan, placements, /*with_estimable=*/false);
  const CalibratedSetChoice choice = chooseIdentifiableSet(information);
  const std::vector<int>& listed = plan.machine.calibrated;
  CalibratedSetResolution resolution;
  resolution.listed = listed;
  for (int k : choice.kept) resolution.kept.push_back(listed[static_cast<std::size_t>(k)]);
  resolution.last = last;
  // In place of the held, never more than the structural rule kept.
  resolution.at_nominal = weakChoiceFrom(information, listed, resolution.kept, resolution.kept,
                                         static_cast<int>(resolution.kept.size()), last);
  const Eigen::VectorXd root = information.unreduced_diagonal.cwiseMax(0.0).cwiseSqrt();
  const double largest = root.size() > 0 ? root.maxCoeff() : 0.0;
  for (int k : choice.dropped) {
    resolution.dropped.push_back(listed[static_cast<std::size_t>(k)]);
    if (!(root[k] >= kUnobservedInformation * largest))
      resolution.unobserved.push_back(listed[static_cast<std::size_t>(k)]);
  }
  for (const auto& tie : choice.ties) {
    std::vector<std::pair<int, double>> named;
    for (const auto& [k, coefficient] : tie) {
      named.emplace_back(listed[static_cast<std::size_t>(k)], coefficient);
    }
    resolution.ties.push_back(std::move(named));
  }
  return resolution;
}

void resolveCalibratedSet(Plan& plan) {
  if (!plan.machine.calibrate_identifiable || plan.placements.empty()) return;
  CalibratedSetResolution resolution = resolveListedSet(plan, plan.placements);
  // Readings that identify none of them decide nothing: the listed set stays, and check,
  // evaluate and calibrate answer as for a listed set the readings cannot identify (a plan
  // without placements likewise; a spec's design decides later, resolveOnDesigns).
  if (resolution.kept.empty()) return;
  plan.machine.calibrated = resolution.kept;
  plan.calibrate_resolution = std::move(resolution);
}

}  // namespace artcal
