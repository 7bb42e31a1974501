#include "artcal/calibration/model_choice.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include "artcal/core/dense_decompositions.hpp"

#include "artcal/calibration/corrections.hpp"
#include "artcal/estimation/normal_matrix.hpp"
#include "artcal/model/joint_compliance.hpp"

namespace artcal {

namespace {

// Solves N x = rhs for a symmetric positive semi-definite N: Cholesky, or the pseudo-inverse
// where N is singular (a direction only the left-out placement observed stays where it was).
Eigen::MatrixXd solveSymmetric(const Eigen::MatrixXd& N, const Eigen::MatrixXd& rhs) {
  const Eigen::LLT<Eigen::MatrixXd> llt(N);
  if (llt.info() == Eigen::Success) {
    Eigen::MatrixXd x = llt.solve(rhs);
    if (x.allFinite()) return x;
  }
  return symmetricPseudoInverse(N) * rhs;
}

// The order in which the rank rule's kept set loses its parameters: repeatedly the one whose
// surviving fraction 1 / (S_K^-1)_ii in the current set K is the smallest. Returns (position in
// the set, fraction) for the first `count` removals whose fraction is below kCandidateFraction.
std::vector<std::pair<int, double>> removalOrder(const PlanInformation& information, int count) {
  const Eigen::MatrixXd S = scaledInformation(information);
  std::vector<int> set(static_cast<std::size_t>(S.rows()));
  std::iota(set.begin(), set.end(), 0);
  std::vector<std::pair<int, double>> out;
  while (static_cast<int>(out.size()) < count && set.size() > 1) {
    const auto n = static_cast<Eigen::Index>(set.size());
    Eigen::MatrixXd sub(n, n);
    for (Eigen::Index a = 0; a < n; ++a)
      for (Eigen::Index b = 0; b < n; ++b)
        sub(a, b) = S(set[static_cast<std::size_t>(a)], set[static_cast<std::size_t>(b)]);
    const Eigen::MatrixXd inverse = solveSymmetric(sub, Eigen::MatrixXd::Identity(n, n));
    Eigen::Index weakest = 0;
    double fraction = 0.0;
    for (Eigen::Index a = 0; a < n; ++a) {
      const double f = inverse(a, a) > 0.0 ? 1.0 / inverse(a, a) : 0.0;
      if (a == 0 || f < fraction) {
        fraction = f;
        weakest = a;
      }
    }
    if (!(fraction < kCandidateFraction)) break;
    out.emplace_back(set[static_cast<std::size_t>(weakest)], fraction);
    set.erase(set.begin() + weakest);
  }
  return out;
}

// The held-out figures of one fitted candidate.
void crossValidate(const Linearization& linearization, const std::vector<PlacementTerms>& terms,
                   ModelChoiceCandidate& candidate) {
  const LeaveOneOut folds = leaveOnePlacementOut(linearization, terms);
  double chi2 = 0.0, trace = 0.0, dof = 0.0;
  candidate.fold_observed.clear();
  for (std::size_t j = 0; j < terms.size(); ++j) {
    chi2 += folds.chi2[j];
    trace += folds.trace[j];
    dof += folds.dof[j];
    candidate.fold_observed.push_back(folds.dof[j] > 0 ? folds.chi2[j] / folds.dof[j] : 0.0);
  }
  candidate.observed = dof > 0.0 ? chi2 / dof : 0.0;
  candidate.predicted = dof > 0.0 ? candidate.chi2_per_dof * (1.0 + trace / dof) : 0.0;
}

// In how many of the folds `candidate`'s held-out error is below `reference`'s.
int foldsLower(const ModelChoiceCandidate& candidate, const ModelChoiceCandidate& reference) {
  int lower = 0;
  for (std::size_t j = 0; j < candidate.fold_observed.size(); ++j)
    if (candidate.fold_observed[j] < reference.fold_observed[j]) ++lower;
  return lower;
}

// Whether `candidate` is clearly better held out than `reference` (see the header): a lower
// pooled error, lower in so many folds that chance gives it at most kSignificance.
bool clearlyBetter(const ModelChoiceCandidate& candidate, const ModelChoiceCandidate& reference,
                   ModelChoiceRule rule) {
  if (!candidate.converged || rule != ModelChoiceRule::CrossValidation) return false;
  if (!(candidate.observed < reference.observed)) return false;
  const auto folds = static_cast<int>(candidate.fold_observed.size());
  return signTestLevel(foldsLower(candidate, reference), folds) <= kSignificance;
}

// Whether the candidate with the weak directions restored holds better than the rank rule's set
// (see the header): converged, plausible, a lower held-out error (the left-out placements'
// pooled, or Cp's with one placement) and, with placements left out, lower in most of them.
bool restoresBetter(const ModelChoiceCandidate& candidate, const ModelChoiceCandidate& reference) {
  if (!candidate.converged || candidate.implausible) return false;
  if (!(candidate.observed < reference.observed)) return false;
  const auto folds = static_cast<int>(candidate.fold_observed.size());
  return folds == 0 || 2 * foldsLower(candidate, reference) > folds;
}

std::string numberText(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", value);
  return text;
}

std::string percent(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f %%", 100.0 * value);
  return text;
}

}  // namespace

double signTestLevel(int lower, int folds) {
  double tail = 0.0, choose = 1.0;  // C(folds, i)
  for (int i = 0; i <= folds; ++i) {
    if (i >= lower) tail += choose;
    choose = choose * (folds - i) / (i + 1);
  }
  return tail / std::pow(2.0, folds);
}

std::vector<PlacementTerms> placementTerms(const Plan& plan,
                                           const std::vector<Placement>& placements,
                                           const Linearization& linearization) {
  const GlobalLayout layout = GlobalLayout::of(plan);
  NormalMatrixReducer reducer(layout);
  PlacementElimination elimination;
  std::vector<PlacementTerms> out(placements.size());
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Placement& placement = placements[j];
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    const ObservationBlock& block = linearization.blocks[j];
    reducer.reset();
    // The rigid directions the calibrator steps (its caps): the left-out placement's own fit.
    reducer.add(block, placement.artifact, &elimination,
                rigidRankOfFeatures(artifact, placement.measurements));
    PlacementTerms& t = out[j];
    t.N = reducer.normal();
    t.b = reducer.rhs();
    t.misfit = reducer.chi2() - elimination.g_r.dot(elimination.M_rr_pinv * elimination.g_r);
    t.dof = block.rows() - reducer.rigidRanks().front();
  }
  return out;
}

LeaveOneOut leaveOnePlacementOut(const Linearization& linearization,
                                 const std::vector<PlacementTerms>& terms) {
  LeaveOneOut out;
  for (const PlacementTerms& t : terms) {
    const Eigen::MatrixXd others = linearization.N - t.N;
    // The others' estimate: one Gauss-Newton step from the estimate of all (exact when linear).
    Eigen::MatrixXd rhs(others.rows(), 1 + others.cols());
    rhs.col(0) = linearization.b - t.b;
    rhs.rightCols(others.cols()) = t.N;
    const Eigen::MatrixXd solved = solveSymmetric(others, rhs);
    const Eigen::VectorXd dg = solved.col(0);
    out.chi2.push_back(std::max(0.0, t.misfit - 2.0 * t.b.dot(dg) + dg.dot(t.N * dg)));
    out.trace.push_back(std::max(0.0, solved.rightCols(others.cols()).trace()));
    out.dof.push_back(t.dof);
  }
  return out;
}

std::optional<ModelChoiceOutcome> chooseKeptSet(const Plan& plan, const CalibrationOptions& options,
                                                const Calibrator& calibrator,
                                                const Calibration& calibration,
                                                const PlanInformation& information) {
  if (!calibration.summary.converged() || calibration.dof <= 0 || plan.placements.empty())
    return std::nullopt;
  const std::vector<int> rank_set = plan.machine.calibrated;
  const auto order = removalOrder(information, kMaxRemoved);
  ModelChoiceOutcome outcome;
  ModelChoice& choice = outcome.choice;
  choice.rule = plan.placements.size() >= 2 ? ModelChoiceRule::CrossValidation
                                            : ModelChoiceRule::InformationCriterion;
  choice.folds = choice.rule == ModelChoiceRule::CrossValidation
                     ? static_cast<int>(plan.placements.size())
                     : 0;
  choice.rank_size = static_cast<int>(rank_set.size());
  const bool probe_only = plan.noise.encoder.size() == 0 || plan.noise.encoder.isZero();
  bool artifact_noise = false;
  for (const Artifact& a : plan.artifacts) artifact_noise |= a.noise > 0.0 || a.noise_angle > 0.0;
  choice.mm_per_unit = probe_only && !artifact_noise ? plan.noise.probe : 0.0;

  const double reference_variance = calibration.chi2_per_dof;
  // `fitted`: the plan the candidate was fitted with (its calibrated set).
  auto judge = [&](const Plan& fitted, const Linearization& linearization, const Calibration& fit,
                   ModelChoiceCandidate& candidate) {
    candidate.converged = fit.summary.converged();
    candidate.chi2_per_dof = fit.chi2_per_dof;
    if (choice.rule == ModelChoiceRule::CrossValidation) {
      crossValidate(linearization, placementTerms(fitted, plan.placements, linearization),
                    candidate);
    } else {
      const double k = static_cast<double>(candidate.size);
      const double n = fit.dof + k;
      candidate.observed = (fit.chi2 + 2.0 * k * reference_variance) / n;
      candidate.predicted = fit.chi2_per_dof * (1.0 + k / n);
    }
  };

  ModelChoiceCandidate first;
  first.size = choice.rank_size;
  first.kept = rank_set;
  judge(plan, calibrator.linearization(), calibration, first);
  choice.candidates.push_back(std::move(first));

  std::vector<CalibrationState> states(1);
  CalibrationOptions quick = options;
  quick.details = false;
  // Fits a candidate's kept set to every reading from `start`, judges it (a fit that does not
  // converge is judged no further: never chosen) and records it with the state it ended at.
  auto fitCandidate = [&](ModelChoiceCandidate candidate, const CalibrationState& start) {
    Plan fitted = plan;  // the plan a candidate's calibrator is bound to: its own set
    fitted.machine.calibrated = candidate.kept;
    Calibrator fitter(fitted, quick);
    const Calibration fit = fitter.run(plan.placements, start);
    if (!candidate.restored.empty())
      candidate.implausible =
          !implausibleCorrections(fitted.machine, plan.machine.nominal, fit.parameters).empty();
    if (fit.summary.converged()) {
      judge(fitted, fitter.linearization(), fit, candidate);
    } else {
      candidate.chi2_per_dof = fit.chi2_per_dof;
    }
    states.push_back({fit.parameters, fit.systematic, fit.poses});
    choice.candidates.push_back(std::move(candidate));
  };

  std::vector<bool> removed(rank_set.size(), false);
  for (const auto& [position, fraction] : order) {
    removed[static_cast<std::size_t>(position)] = true;
    ModelChoiceCandidate candidate;
    candidate.removed = rank_set[static_cast<std::size_t>(position)];
    candidate.removed_fraction = fraction;
    for (std::size_t i = 0; i < rank_set.size(); ++i)
      if (!removed[i]) candidate.kept.push_back(rank_set[i]);
    candidate.size = static_cast<int>(candidate.kept.size());
    // From the rank rule's estimate, the removed parameters back at nominal.
    CalibrationState start;
    start.p = calibration.parameters;
    for (std::size_t i = 0; i < rank_set.size(); ++i) {
      if (removed[i]) start.p[rank_set[i]] = plan.machine.nominal[rank_set[i]];
    }
    start.c = calibration.systematic;
    start.poses = calibration.poses;
    fitCandidate(std::move(candidate), start);
  }

  // The rank rule's set with the directions the weak-direction rule held calibrated again, from
  // the rank rule's estimate (where they are at nominal).
  const std::vector<int> weak =
      plan.calibrate_resolution ? plan.calibrate_resolution->weak : std::vector<int>{};
  if (!weak.empty()) {
    ModelChoiceCandidate candidate;
    candidate.restored = weak;
    candidate.kept = rank_set;
    candidate.kept.insert(candidate.kept.end(), weak.begin(), weak.end());
    std::sort(candidate.kept.begin(), candidate.kept.end());
    candidate.size = static_cast<int>(candidate.kept.size());
    fitCandidate(std::move(candidate),
                 {calibration.parameters, calibration.systematic, calibration.poses});
  }
  // Geometric only (docs/compliance.md section 5): the rank rule's set without its compliances,
  // from its estimate with them at nominal. Compliance must earn its place held out.
  int geometric = -1;
  const Mechanism& mech = *plan.machine.mechanism;
  if (std::any_of(rank_set.begin(), rank_set.end(),
                  [&mech](int k) { return isComplianceParameter(mech, k); })) {
    ModelChoiceCandidate candidate;
    candidate.geometric_only = true;
    CalibrationState start{calibration.parameters, calibration.systematic, calibration.poses};
    for (const int k : rank_set) {
      if (isComplianceParameter(mech, k))
        start.p[k] = plan.machine.nominal[k];
      else
        candidate.kept.push_back(k);
    }
    candidate.size = static_cast<int>(candidate.kept.size());
    geometric = static_cast<int>(choice.candidates.size());
    fitCandidate(std::move(candidate), start);
  }
  if (choice.candidates.size() == 1) return std::nullopt;

  // The smallest held-out error among the candidates clearly better than the rank rule's set.
  const ModelChoiceCandidate& reference = choice.candidates.front();
  choice.chosen = 0;
  // Compliance kept only where geometric + compliance holds better than geometric only (the
  // rule that restores weak directions: lower pooled and in most folds, or by Cp).
  if (geometric >= 0) {
    const ModelChoiceCandidate& g = choice.candidates[static_cast<std::size_t>(geometric)];
    if (g.converged && !restoresBetter(reference, g)) {
      choice.chosen = geometric;
      choice.candidates[static_cast<std::size_t>(geometric)].chosen = true;
      choice.decided_by = nameOf(kModelChoiceRuleNames, choice.rule);
      choice.reason = "geometric + compliance is not better held out than geometric only (" +
                      numberText(reference.observed) + " against " + numberText(g.observed) +
                      "): the compliances are held at nominal";
      outcome.chosen_state = states[static_cast<std::size_t>(geometric)];
      return outcome;
    }
  }
  for (std::size_t i = 1; i < choice.candidates.size(); ++i) {
    const ModelChoiceCandidate& c = choice.candidates[i];
    if (c.geometric_only) continue;
    const bool better = c.restored.empty() ? clearlyBetter(c, reference, choice.rule)
                                           : restoresBetter(c, reference);
    if (!better) continue;
    if (choice.chosen == 0 || c.observed < choice.candidates[choice.chosen].observed)
      choice.chosen = static_cast<int>(i);
  }
  choice.candidates[static_cast<std::size_t>(choice.chosen)].chosen = true;
  const std::string rule = nameOf(kModelChoiceRuleNames, choice.rule);
  if (choice.chosen == 0) {
    choice.decided_by = "rank rule";
    const std::string restored =
        weak.empty()
            ? std::string()
            : "; the weak directions restored are not better held out" +
                  std::string(
                      choice.rule == ModelChoiceRule::CrossValidation ? "" : " by Cp's estimate");
    choice.reason =
        (choice.folds >= kMinFolds
             ? "no smaller candidate is clearly better held out (lower pooled error and lower in "
               "so many of the " +
                   std::to_string(choice.folds) + " folds that chance gives it at most " +
                   percent(kSignificance) + ")"
             : "fewer than " + std::to_string(kMinFolds) +
                   " placements: no held-out test can show a smaller set clearly better") +
        restored;
    if (geometric >= 0) {
      choice.reason += "; geometric + compliance holds better than geometric only (" +
                       numberText(reference.observed) + " against " +
                       numberText(choice.candidates[static_cast<std::size_t>(geometric)].observed) +
                       ")";
    }
  } else {
    const ModelChoiceCandidate& c = choice.candidates[static_cast<std::size_t>(choice.chosen)];
    choice.decided_by = rule;
    choice.reason =
        "held-out error " + percent(1.0 - c.observed / reference.observed) + " lower " +
        (c.restored.empty() ? std::string("than the rank rule's set")
                            : "with the weak directions calibrated again than with the rank "
                              "rule's set, which holds them at nominal");
    outcome.chosen_state = states[static_cast<std::size_t>(choice.chosen)];
  }
  return outcome;
}

}  // namespace artcal
