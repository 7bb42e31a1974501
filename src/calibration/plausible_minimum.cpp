#include "artcal/calibration/plausible_minimum.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "artcal/calibration/calibrate_readings.hpp"
#include "artcal/calibration/calibrator.hpp"
#include "artcal/estimation/identifiability.hpp"

namespace artcal {

namespace {

MinimumFit minimumFit(const Plan& plan, const Calibration& calibration) {
  MinimumFit fit;
  fit.calibrated = plan.machine.calibrated;
  fit.parameters = calibration.parameters;
  fit.chi2 = calibration.chi2;
  fit.dof = calibration.dof;
  fit.chi2_per_dof = calibration.chi2_per_dof;
  fit.probe = plan.noise.probe;
  fit.flagged = implausibleCorrections(plan.machine, plan.machine.nominal, calibration.parameters);
  return fit;
}

// `listed` with the `demoted` parameters moved to its end, in the order they were demoted.
std::vector<int> withDemotedLast(const std::vector<int>& listed, const std::vector<int>& demoted) {
  std::vector<int> order;
  for (const int i : listed) {
    if (std::find(demoted.begin(), demoted.end(), i) == demoted.end()) order.push_back(i);
  }
  for (const int i : demoted) {
    if (std::find(listed.begin(), listed.end(), i) != listed.end()) order.push_back(i);
  }
  return order;
}

std::string names(const Machine& machine, const std::vector<int>& indices) {
  std::string out;
  for (const int i : indices) {
    if (!out.empty()) out += ", ";
    out += machine.mechanism->parameters()[static_cast<std::size_t>(i)].name;
  }
  return out;
}

std::string number(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

}  // namespace

std::vector<int> parametersOf(const std::vector<ImplausibleCorrection>& corrections) {
  std::vector<int> out;
  for (const ImplausibleCorrection& c : corrections) out.push_back(c.parameter);
  return out;
}

CalibrationRun choosePlausibleMinimum(const Plan& before, CalibrationRun run,
                                      const CalibrateAsListed& calibrate) {
  const Plan& plan = run.decided;
  Calibration& fit = run.calibration;
  if (!fit.summary.converged() || !before.machine.calibrate_identifiable ||
      !before.calibrate_resolution) {
    return run;
  }
  MinimumChoice choice;
  choice.flagged = minimumFit(plan, fit);
  if (choice.flagged.flagged.empty()) return run;
  const std::vector<int>& listed = before.calibrate_resolution->listed;
  // The flagged fit's scatter over the stated noise: what a chi2 difference is measured in.
  const double birge = std::max(1.0, choice.flagged.chi2_per_dof);
  std::vector<int> previous_kept = before.machine.calibrated;  // the plain path's set
  std::vector<ImplausibleCorrection> to_demote = choice.flagged.flagged;
  // The chosen alternative: no flagged correction, the same cost.
  std::optional<CalibrationRun> best;
  std::string stop;
  for (int round = 0; round < kMaxDemotionRounds; ++round) {
    bool demoted_more = false;
    for (const int i : parametersOf(to_demote)) {
      if (std::find(choice.demoted.begin(), choice.demoted.end(), i) != choice.demoted.end())
        continue;
      choice.demoted.push_back(i);
      demoted_more = true;
    }
    if (!demoted_more) break;
    Plan trial = before;
    trial.machine.calibrated = withDemotedLast(listed, choice.demoted);
    CalibratedSetResolution resolution = resolveListedSet(trial, trial.placements, choice.demoted);
    // The set calibrate starts from: the structural rule's, or the weak rule's choice.
    const std::vector<int> first = resolution.at_nominal.setFor(resolution.kept);
    if (first == previous_kept) {
      // Nothing else takes the demoted parameters' directions: the set, and so the fit, stays.
      stop = "no other parameter takes the directions of " + names(plan.machine, choice.demoted);
      break;
    }
    previous_kept = first;
    trial.machine.calibrated = resolution.kept;
    trial.calibrate_resolution = std::move(resolution);
    CalibrationRun alternative = calibrate(trial);
    ++choice.fits;
    if (!alternative.calibration.summary.converged()) {
      stop = "the fit with " + names(plan.machine, choice.demoted) + " last did not converge";
      break;
    }
    MinimumFit tried = minimumFit(alternative.decided, alternative.calibration);
    // Its chi2 at the flagged fit's probe noise (the same when the noise is stated).
    const double scale = tried.probe / choice.flagged.probe;
    const int held_more = std::max(0, tried.dof - choice.flagged.dof);
    tried.chi2_increase = (tried.chi2 * scale * scale - choice.flagged.chi2) / birge;
    tried.chi2_allowance = held_more + 3.0 * std::sqrt(2.0 * std::max(1, held_more));
    const bool same_cost = tried.chi2_increase <= tried.chi2_allowance;
    to_demote = tried.flagged;
    const bool better = same_cost && tried.flagged.empty();
    if (!best || better) choice.alternative = tried;
    if (better) best.emplace(std::move(alternative));
    if (!same_cost) {
      stop = "with " + names(plan.machine, choice.demoted) + " last the readings fit worse (chi2 " +
             number("%+.4g", tried.chi2_increase) + " in units of max(1, chi2/dof), beyond " +
             number("%.3g", tried.chi2_allowance) + "): they need those corrections";
      break;
    }
    if (tried.flagged.empty()) break;
  }
  if (best) {
    const MinimumFit& chosen = *choice.alternative;
    choice.alternative_chosen = true;
    choice.reason = "the plain fit corrects " +
                    names(plan.machine, parametersOf(choice.flagged.flagged)) +
                    " implausibly; with " + names(plan.machine, choice.demoted) +
                    " last in the rank rule's order the readings fit as well (chi2 " +
                    number("%+.3g", chosen.chi2_increase) + " in units of max(1, chi2/dof), " +
                    "within " + number("%.3g", chosen.chi2_allowance) +
                    ") with no implausible correction: that minimum is taken";
    best->calibration.minimum = std::move(choice);
    return std::move(*best);
  }
  if (stop.empty()) stop = "every fit tried corrects a parameter implausibly";
  choice.reason = "the plain fit's minimum is kept: " + stop;
  fit.minimum = std::move(choice);
  return run;
}

}  // namespace artcal
