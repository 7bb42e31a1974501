#include "artcal/calibration/calibrate_readings.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "artcal/calibration/corrections.hpp"
#include "artcal/calibration/model_choice.hpp"
#include "artcal/core/error.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/estimation/identifiability.hpp"

namespace artcal {

namespace {

constexpr int kMaxWeakRounds = 4;       // calibrations repeated for directions weak at the estimate
constexpr int kMaxNoiseFits = 8;        // calibrations while the probe noise settles
constexpr double kNoiseSettled = 1e-3;  // relative change of s_p that counts as settled
constexpr double kProbeNoiseFloor = 1e-6;  // mm: no real probe is better than a nanometre

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

// The weak rule's choice over every listed parameter (weakRuleChoice, identifiability.hpp) as the
// run's next plan; std::nullopt when the current set stays: when it passes the rule itself and
// the rule's choice is no larger (the same directions under other names of an exact tie, or
// rounding, never move a fit from one stage to the next).
std::optional<Plan> weakRuleOverListed(const Plan& plan, WeakRuleChoice choice) {
  if (choice.setFor(plan.machine.calibrated) == plan.machine.calibrated) return std::nullopt;
  std::optional<Plan> next(plan);
  CalibratedSetResolution& decided = *next->calibrate_resolution;
  decided.weak = std::move(choice.held);
  decided.weak_fraction = std::move(choice.held_fraction);
  decided.in_place = std::move(choice.in_place);
  next->machine.calibrated = choice.kept;
  decided.kept = std::move(choice.kept);
  return next;
}

// The readings' misfits in the eigenbases of their encoder covariances Q diag(lambda) Q^T: with
// the probe noise s added, Sigma = Q diag(lambda + s^2) Q^T and the whitened chi2 is
// sum_i (Q^T e)_i^2 / (lambda_i + s^2), so that the bisection on s solves nothing per step. One
// entry per valued coordinate of every reading, flat, so that a bisection step is one loop.
struct SpectralMisfits {
  std::vector<double> lambda;     // eigenvalues of the encoder covariance (clamped at 0)
  std::vector<double> projected;  // (Q^T e)_i^2
};

SpectralMisfits spectralMisfits(const std::vector<ReadingMisfit>& misfits) {
  SpectralMisfits out;
  out.lambda.reserve(6 * misfits.size());
  out.projected.reserve(6 * misfits.size());
  // At most 6 x 6 (a pose whose orientation rows share s_p^2): on the stack. Not finite (Eigen's
  // iteration leaves its results unspecified there): NaN, which no bisection step accepts.
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, 6>;
  for (const ReadingMisfit& m : misfits) {
    const auto k = m.residual.size();
    if (!m.encoder_covariance.allFinite() || !m.residual.allFinite()) {
      out.lambda.insert(out.lambda.end(), static_cast<std::size_t>(k), std::nan(""));
      out.projected.insert(out.projected.end(), static_cast<std::size_t>(k), std::nan(""));
      continue;
    }
    if (k == 3) {  // points: the closed form of a 3 x 3 (Eigen's computeDirect)
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
      eig.computeDirect(Eigen::Matrix3d(m.encoder_covariance));
      const Eigen::Vector3d projected =
          (eig.eigenvectors().transpose() * Eigen::Vector3d(m.residual)).array().square();
      for (int i = 0; i < 3; ++i) {
        out.lambda.push_back(std::max(eig.eigenvalues()[i], 0.0));
        out.projected.push_back(projected[i]);
      }
      continue;
    }
    const Eigen::SelfAdjointEigenSolver<Small> eig{Small(m.encoder_covariance)};
    const Eigen::VectorXd projected =
        (eig.eigenvectors().transpose() * m.residual).array().square().matrix();
    for (Eigen::Index i = 0; i < k; ++i) {
      out.lambda.push_back(std::max(eig.eigenvalues()[i], 0.0));
      out.projected.push_back(projected[i]);
    }
  }
  return out;
}

// readings(s) at u = s^2, and its derivative in u, -sum_i (Q^T e)_i^2 / (lambda_i + u)^2: one pass
// for Newton's steps and for the estimate's u.
struct ReadingsChi2InVariance {
  double chi2 = 0.0;
  double slope = 0.0;  // d chi2 / du, negative
};

ReadingsChi2InVariance readingsChi2InVariance(const SpectralMisfits& misfits, double u) {
  ReadingsChi2InVariance out;
  for (std::size_t r = 0; r < misfits.lambda.size(); ++r) {
    const double q = 1.0 / (misfits.lambda[r] + u);
    const double term = misfits.projected[r] * q;
    out.chi2 += term;
    out.slope -= term * q;
  }
  return out;
}

// Whitened chi2 of the readings' misfits at probe noise s (encoders as stated).
double readingsChi2(const SpectralMisfits& misfits, double s) {
  return readingsChi2InVariance(misfits, s * s).chi2;
}

// Bisection on log s within [low, high] until they agree to 1e-12: readings(s) = target.
double bisectProbeNoise(const SpectralMisfits& misfits, double target, double low, double high) {
  for (int i = 0; i < 80 && high / low > 1.0 + 1e-12; ++i) {
    const double mid = std::sqrt(low * high);
    (readingsChi2(misfits, mid) > target ? low : high) = mid;
  }
  return std::sqrt(low * high);
}

// readings(s) = target within the bracket [low, high] it holds, from `start`.
double solveProbeNoise(const SpectralMisfits& misfits, double target, double low, double high,
                       double start) {
  // As a function of u = s^2 it is a sum of p / (lambda + u): convex, so that Newton's steps in u
  // from the stated s converge quadratically (from below the root, monotonically); a step that
  // leaves the bracket [low, high] the readings keep is replaced by the bracket's middle on log s.
  // Stops when a step moves s by less than 1e-13 of itself: the root the bisection on log s
  // (bisectProbeNoise, 1e-12) finds, in a few evaluations instead of about 45.
  double s = start;
  if (!(s > low && s < high)) s = std::sqrt(low * high);
  for (int i = 0; i < 100; ++i) {
    const double u = s * s;
    const auto [chi2, slope] = readingsChi2InVariance(misfits, u);
    // Not finite (a misfit's NaN): what the bisection makes of it.
    if (!std::isfinite(chi2) || !std::isfinite(slope)) break;
    if (chi2 == target) return s;
    (chi2 > target ? low : high) = s;
    const double next_u = u - (chi2 - target) / slope;
    double next = next_u > 0.0 ? std::sqrt(next_u) : 0.0;
    if (!(next > low && next < high)) next = std::sqrt(low * high);
    if (std::abs(next - s) <= 1e-13 * s || high / low <= 1.0 + 1e-12) return next;
    s = next;
  }
  return bisectProbeNoise(misfits, target, low, high);
}

// The s_p that makes chi2 = dof for these misfits, and its standard uncertainty.
struct ProbeNoiseSolution {
  double s = 0.0;  // mm
  double u = 0.0;  // mm
};

// The s_p that makes chi2 = dof for these misfits at the calibration's estimate (whitened with
// s_p = `probe`; u = 0 where it cannot be solved). u = sqrt(2 target) / |d chi2/ds|: chi2 at the
// true s_p spreads by sqrt(2 dof), and the solution moves by that over the slope. Without encoder
// or instrument noise this is s_p / sqrt(2 dof); with the instrument's own noise s_i it is (s_i^2 +
// s_p^2) / (s_p sqrt(2 dof)): an s_p small against s_i is poorly determined.
ProbeNoiseSolution probeNoiseOfMisfits(const std::vector<ReadingMisfit>& readings,
                                       const Calibration& calibration, double probe) {
  const SpectralMisfits misfits = spectralMisfits(readings);
  // The priors' part of the cost does not depend on s_p: chi2(s) = readings(s) + priors = dof.
  const double priors = std::max(0.0, calibration.chi2 - readingsChi2(misfits, probe));
  const double target = calibration.dof - priors;
  if (!(target > 0.0)) return {probe, 0.0};
  // readings(s) decreases with s (a closed form only without encoders).
  const double low = kProbeNoiseFloor * 1e-3, high = 1e6;
  if (readingsChi2(misfits, low) <= target) return {0.0, 0.0};  // the encoders explain it all
  if (readingsChi2(misfits, high) >= target) return {high, 0.0};
  ProbeNoiseSolution out;
  out.s = solveProbeNoise(misfits, target, low, high, probe);
  // |d chi2/ds| = 2 s |d chi2/du|.
  const double slope = 2.0 * out.s * -readingsChi2InVariance(misfits, out.s * out.s).slope;
  out.u = slope > 0.0 && std::isfinite(slope) ? std::sqrt(2.0 * target) / slope : 0.0;
  return out;
}

// `next`, the result of a fit that followed `earlier`, with the work of both counted.
Calibration followedBy(const Calibration& earlier, Calibration next) {
  next.summary.iterations += earlier.summary.iterations;
  next.summary.accepted_steps += earlier.summary.accepted_steps;
  next.summary.fits += earlier.summary.fits;
  return next;
}

// Calibrates at the calibrator's noise (its plan's when it was made); with `"probe": "estimate"`,
// sets the calibrator's probe noise to the variance component that gives chi2 = dof and
// calibrates again until it settles, over `placements` (plan's readings: the vector the calibrator
// was prepared with, if it was). The calibrator owns the noise it whitens with; the noise
// used is in the result's noise_estimate (Stages::noteNoise records it for what follows).
Calibration calibrateWithNoise(const Plan& plan, const std::vector<Placement>& placements,
                               Calibrator& calibrator, const CalibrationState& start) {
  Calibration calibration = calibrator.run(placements, start);
  if (!plan.noise.estimate_probe) return calibration;
  NoiseEstimate estimate;
  estimate.stated = calibrator.probeNoise();
  std::optional<ProbeNoiseSolution> solved;  // at the last calibration's estimate
  for (estimate.fits = 1; estimate.fits < kMaxNoiseFits; ++estimate.fits) {
    if (calibration.dof <= 0 || !std::isfinite(calibration.chi2)) break;
    // The misfits at the estimate from the calibrator's last linearisation, built there.
    solved =
        probeNoiseOfMisfits(calibrator.misfits(placements), calibration, calibrator.probeNoise());
    const double s = std::max(solved->s, kProbeNoiseFloor);
    if (std::abs(s - calibrator.probeNoise()) <= kNoiseSettled * calibrator.probeNoise()) break;
    calibrator.setProbeNoise(s);  // the new s from the next linearisation on
    // From where the last fit converged: the poses and c too, so that only the reweighting moves.
    CalibrationState state;
    state.p = calibration.parameters;
    state.c = calibration.systematic;
    state.poses = calibration.poses;
    calibration = followedBy(calibration, calibrator.run(placements, state));
    solved.reset();
  }
  estimate.probe = calibrator.probeNoise();
  // Its u from the solution at the final estimate (settled: within 1e-3 of the s_p used); where
  // the fits ran out first, the chi-square's relative spread alone.
  if (solved && solved->u > 0.0) {
    estimate.u = solved->u;
  } else {
    estimate.u = calibration.dof > 0 ? estimate.probe / std::sqrt(2.0 * calibration.dof) : 0.0;
  }
  calibration.noise_estimate = estimate;
  return calibration;
}

// The noise `calibration` whitened with: `noise` with the probe noise it estimated, if it did.
Noise noiseUsed(const Noise& noise, const Calibration& calibration) {
  Noise out = noise;
  if (calibration.noise_estimate) out.probe = calibration.noise_estimate->probe;
  return out;
}

// The plans of one run, oldest first (Pinocchio's Model/Data split: a plan is the model, never
// changed while a calibrator is bound to it). Each decision of the run (parameters held by the
// weak rule, a probe noise estimated, a kept set chosen held out) makes the next plan, a changed
// copy of the current one; the earlier ones stay where their calibrators read them (a deque
// does not move its elements on push_back). The last is the plan as decided.
class Stages {
 public:
  explicit Stages(const Plan& given) : current_(&given) {}

  const Plan& current() const { return *current_; }
  /// `next` becomes the current plan.
  const Plan& push(Plan next) {
    later_.push_back(std::move(next));
    current_ = &later_.back();
    return *current_;
  }
  /// The noise `calibration` whitened with becomes the current plan's (when it estimated
  /// another): what the calibrators made afterwards start from and the run reports.
  void noteNoise(const Calibration& calibration) {
    Noise used = noiseUsed(current_->noise, calibration);
    if (used.probe == current_->noise.probe) return;
    Plan next = *current_;
    next.noise = std::move(used);
    push(std::move(next));
  }
  /// The plan as decided (a copy of the given one when nothing was decided); call last.
  Plan decided() && {
    if (later_.empty()) return *current_;
    return std::move(later_.back());
  }

 private:
  const Plan* current_;
  std::deque<Plan> later_;
};

// The information the rank rule reads at the calibration's estimate: the calibrator's own
// linearisation there when every coordinate of the points is valued (the reduced information of
// p then does not depend on the placements' poses, Calibrator::information), otherwise built
// again at the rigid fits of the readings (planInformation).
PlanInformation informationAtEstimate(const Plan& plan, Calibrator& calibrator,
                                      const Calibration& calibration) {
  const bool all_valued =
      std::all_of(plan.placements.begin(), plan.placements.end(), [&](const Placement& placement) {
        const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
        return artifact.valuedPerFeature() == artifact.dimension;
      });
  if (all_valued) return calibrator.information(plan.placements);
  return planInformation(plan, plan.placements, calibration.parameters, /*with_estimable=*/false);
}

// An angle and the same angle plus a turn describe the same machine (rpy, DH theta and alpha,
// joint offsets): each estimated angle is reported as the one nearest its nominal value.
void nearestTurn(const Plan& plan, Calibration& calibration) {
  const Machine& machine = plan.machine;
  const auto& parameters = machine.mechanism->parameters();
  for (const int i : machine.calibrated) {
    if (!(parameters[static_cast<std::size_t>(i)].quantity == Quantity::Angle)) continue;
    const double nominal = machine.nominal[i];
    calibration.parameters[i] =
        nominal + std::remainder(calibration.parameters[i] - nominal, 2.0 * std::numbers::pi);
  }
}

/// A reading's identity bit for bit: its feature, tip, joints and measured point or pose. An
/// instrument's reading is a feature of its own (its measured point), so its feature index never
/// repeats: its identity is the station's (the placement's) tip, joints and measured values.
std::string readingBits(const Measurement& m) {
  const auto bytes = [](std::string& key, const Eigen::VectorXd& v) {
    key.append(reinterpret_cast<const char*>(v.data()),
               static_cast<std::size_t>(v.size()) * sizeof(double));
    key += '|';
  };
  const bool instrument_reading = m.point.size() > 0;
  std::string key = (instrument_reading ? std::string("instrument") : std::to_string(m.feature)) +
                    "/" + std::to_string(m.stylus) + "|";
  bytes(key, m.joints);
  bytes(key, m.point);
  bytes(key, m.orientation);
  return key;
}

/// Readings repeated bit for bit (docs/hardening.md, repeated readings): copies of one reading
/// are not independent measurements, yet each counts as one, and u shrinks as sqrt(copies). One
/// warning per placement naming the first repeat and what it repeats.
void addRepeatWarnings(const Plan& plan, std::vector<std::string>& warnings) {
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const std::vector<Measurement>& readings = plan.placements[j].measurements;
    std::map<std::string, std::size_t> first;  // the reading's bytes -> its first index
    std::size_t repeats = 0, example = 0, original = 0;
    for (std::size_t i = 0; i < readings.size(); ++i) {
      const auto [at, fresh] = first.emplace(readingBits(readings[i]), i);
      if (fresh) continue;
      if (repeats++ == 0) {
        example = i;
        original = at->second;
      }
    }
    if (repeats == 0) continue;
    const ReadingLocation copy = readingLocation(plan, j, example);
    const ReadingLocation of = readingLocation(plan, j, original);
    const double shrink = std::sqrt(static_cast<double>(readings.size()) /
                                    static_cast<double>(readings.size() - repeats));
    char factor[32];
    std::snprintf(factor, sizeof factor, "%.3g", shrink);
    warnings.push_back("placement " + placementLabel(plan.placements, j) + ": " +
                       std::to_string(repeats) + " of " + std::to_string(readings.size()) +
                       " readings repeat another bit for bit (the first: " + copy.file + " " +
                       copy.where + " = " + (of.file == copy.file ? "" : of.file + " ") + of.where +
                       "): each copy is counted as a measurement of its own, which makes every "
                       "u up to " +
                       factor +
                       "x too small if they are copies; remove the copies (repeated "
                       "measurements of a real probe rarely agree to the last bit) or count "
                       "them once (calibrate --repeats once)");
  }
}

void addWarnings(const Plan& plan, Calibration& calibration) {
  addRepeatWarnings(plan, calibration.warnings);
  for (const ImplausibleCorrection& c :
       implausibleCorrections(plan.machine, plan.machine.nominal, calibration.parameters)) {
    calibration.warnings.push_back(describeCorrection(plan.machine, c));
  }
  const bool at_floor =
      calibration.noise_estimate && calibration.noise_estimate->probe <= kProbeNoiseFloor;
  const bool consistent =
      calibration.dof > 0 && calibration.chi2_per_dof < kRoundingChi2PerDof && !at_floor;
  if (consistent || (at_floor && calibration.dof > 0)) {
    calibration.warnings.push_back(
        "the readings fit the model to rounding (chi2/dof = " + number(calibration.chi2_per_dof) +
        (at_floor ? ", probe noise estimated at the 1e-6 mm floor" : "") +
        "): no real probe is this consistent; these look like planned (nominal) readings, for "
        "which u_posterior means nothing. Calibrate measured readings, or simulated ones "
        "(artcal simulate --truth)");
  }
}

}  // namespace

double probeNoiseForUnitBirgeRatio(const Plan& plan, const std::vector<Placement>& placements,
                                   const Calibration& calibration) {
  const GlobalLayout layout = GlobalLayout::of(plan);
  const DesignMatrixBuilder builder(plan.machine, plan.noise);
  std::vector<ReadingMisfit> readings;
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placements[j].artifact)];
    const int offset = layout.artifact_offset[static_cast<std::size_t>(placements[j].artifact)] -
                       layout.parameters;
    const Eigen::VectorXd c = calibration.systematic.segment(offset, artifact.systematicCount());
    builder.misfits(artifact, placements[j].measurements, calibration.parameters,
                    calibration.poses[j], c, readings);
  }
  return probeNoiseOfMisfits(readings, calibration, plan.noise.probe).s;
}

// An instrument's reading without its measured point is for planning only (instruments.md):
// calibrating it would fit the nominal machine's own tip points.
void requireMeasuredPoints(const Plan& plan) {
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    for (const Measurement& m : plan.placements[j].measurements) {
      if (m.point_given) continue;
      throw InputError(
          plan.source,
          "/placements/" + std::to_string(j) + "/measurements/" + std::to_string(m.entry),
          "calibrate needs the point the instrument measured (\"point\"); a reading "
          "without it is for planning only (check, evaluate, optimize, simulate)");
    }
  }
}

namespace {

// The plain path: the rank rule, the weak directions and the noise, as the plan lists them.
CalibrationRun calibrateAsListed(const Plan& given, const CalibrationOptions& options) {
  const bool resolve =
      given.machine.calibrate_identifiable && given.calibrate_resolution.has_value();
  const Eigen::VectorXd& nominal = given.machine.nominal;
  // The readings, the same in every stage: one vector, so that a calibrator prepared on it is
  // recognised as prepared (Calibrator::prepareFrom).
  const std::vector<Placement>& placements = given.placements;
  Stages stages(given);
  std::optional<Calibrator> calibrator(std::in_place, given, options);
  CalibrationState start = calibrator->initialState(placements, nominal);
  // Rank policy on measured readings (docs/method.md section 5): at the nominal parameters, from
  // the linearisation the calibration then starts from ...
  if (resolve) {
    if (auto held = weakRuleOverListed(given, given.calibrate_resolution->at_nominal)) {
      calibrator.emplace(stages.push(std::move(*held)), options);
      start = calibrator->initialState(placements, nominal);
    }
  }
  Calibration calibration = calibrateWithNoise(stages.current(), placements, *calibrator, start);
  stages.noteNoise(calibration);
  // ... and again at the estimate, the newly held parameters back at nominal.
  for (int round = 0; resolve && round < kMaxWeakRounds && calibration.summary.converged();
       ++round) {
    const Plan& plan = stages.current();
    auto held = weakRuleOverListed(
        plan, weakRuleChoice(plan, given.machine.calibrated, calibration.parameters));
    if (!held) break;
    const Plan& narrower = stages.push(std::move(*held));
    calibrator.emplace(narrower, options);
    start = calibrator->initialState(
        placements, narrower.machine.withCalibrated(
                        nominal, narrower.machine.calibratedValues(calibration.parameters)));
    calibration =
        followedBy(calibration, calibrateWithNoise(narrower, placements, *calibrator, start));
    stages.noteNoise(calibration);
  }
  const Plan& plan = stages.current();
  if (plan.noise.estimate_probe && calibration.dof == 0) {
    // No redundancy: the "estimate" would be the starting value (docs/hardening.md).
    throw InputError(plan.source, "/noise/probe",
                     "\"estimate\" needs more equations than unknowns, and the calibration has 0 "
                     "degrees of freedom: state the probe noise (mm) or add readings");
  }
  nearestTurn(plan, calibration);
  addWarnings(plan, calibration);
  calibrator.reset();  // bound to the last stage, which decided() moves out
  return {std::move(calibration), std::move(stages).decided()};
}

// The held-out model choice's outcome on the run's minimum (model_choice.hpp), from the
// linearisation at its estimate; std::nullopt when there is nothing to choose.
std::optional<ModelChoiceOutcome> modelChoiceOutcome(const CalibrationRun& run,
                                                     const CalibrationOptions& options) {
  const Plan& plan = run.decided;
  const Calibration& calibration = run.calibration;
  Calibrator calibrator(plan, options);
  const CalibrationState state{calibration.parameters, calibration.systematic, calibration.poses};
  if (!calibrator.prepare(plan.placements, state)) return std::nullopt;
  const PlanInformation at_estimate = informationAtEstimate(plan, calibrator, calibration);
  return chooseKeptSet(plan, options, calibrator, calibration, at_estimate);
}

// The held-out model choice, once, on the minimum taken: a smaller set of the rank rule's order
// where the readings the fit leaves out say it holds clearly better (model_choice.hpp).
CalibrationRun withModelChoice(CalibrationRun run, const CalibrationOptions& options) {
  if (options.model_choice != ModelChoiceMode::HeldOut || !run.calibration.summary.converged())
    return run;
  auto outcome = modelChoiceOutcome(run, options);
  if (!outcome) return run;
  const ModelChoice& choice = outcome->choice;
  if (choice.chosen != 0) {
    const ModelChoiceCandidate& chosen_set =
        choice.candidates[static_cast<std::size_t>(choice.chosen)];
    Plan chosen_plan = run.decided;  // the run's next stage: the chosen set
    chosen_plan.machine.calibrated = chosen_set.kept;
    chosen_plan.calibrate_resolution->kept = chosen_set.kept;
    if (!chosen_set.restored.empty()) {  // no longer held: calibrated again
      chosen_plan.calibrate_resolution->weak.clear();
      chosen_plan.calibrate_resolution->weak_fraction.clear();
    }
    Calibration chosen = [&] {  // its calibrator gone before the plan records the noise used
      Calibrator narrowed(chosen_plan, options);
      return followedBy(run.calibration, calibrateWithNoise(chosen_plan, chosen_plan.placements,
                                                            narrowed, outcome->chosen_state));
    }();
    chosen_plan.noise = noiseUsed(chosen_plan.noise, chosen);
    chosen.minimum = std::move(run.calibration.minimum);
    nearestTurn(chosen_plan, chosen);
    addWarnings(chosen_plan, chosen);
    run = {std::move(chosen), std::move(chosen_plan)};
  }
  run.calibration.model_choice = std::move(outcome->choice);
  return run;
}

// The unmodelled error by cross-validation (unmodelled_error.hpp), on readings that are measured
// (not consistent to rounding) and a fit that converged with degrees of freedom to spare.
CalibrationRun withUnmodelledError(CalibrationRun run, const CalibrationOptions& options) {
  const Calibration& c = run.calibration;
  if (!options.cross_validation || !c.summary.converged() || c.dof <= 0 ||
      c.chi2_per_dof < kRoundingChi2PerDof || !c.covariance)
    return run;
  run.calibration.unmodelled = estimateUnmodelledError(run, options);
  return run;
}

}  // namespace

CalibrationRun calibrateReadings(const Plan& given, const CalibrationOptions& options) {
  requireMeasuredPoints(given);
  CalibrationRun run = calibrateAsListed(given, options);
  if (!given.machine.calibrate_identifiable || !given.calibrate_resolution)
    return withUnmodelledError(std::move(run), options);
  // A fit whose corrections are flagged is searched for a plausible minimum from the plan as
  // given (plausible_minimum.hpp); the kept set is then judged held out on the minimum taken.
  run = choosePlausibleMinimum(
      given, std::move(run), [&](const Plan& trial) { return calibrateAsListed(trial, options); });
  return withUnmodelledError(withModelChoice(std::move(run), options), options);
}

PredictionNoise predictionNoise(const Plan& plan, const CalibrationRun* run) {
  PredictionNoise out{plan.noise.probe, false, "stated", std::nullopt};
  if (!plan.noise.estimate_probe) return out;
  out.source = "the starting value";
  std::optional<CalibrationRun> own;
  if (!run) {
    try {
      own.emplace(calibrateReadings(plan));
    } catch (const InputError& e) {
      out.source += " (the readings cannot be calibrated: " + std::string(e.what()) + ")";
      return out;
    } catch (const std::exception& e) {
      out.source += " (the calibration failed: " + std::string(e.what()) + ")";
      return out;
    }
    run = &*own;
  }
  const Calibration& c = run->calibration;
  if (!c.summary.converged()) {
    out.source += " (the calibration of the readings did not converge)";
  } else if (!c.noise_estimate || c.noise_estimate->probe <= kProbeNoiseFloor) {
    out.source +=
        " (the readings fit the model to rounding: planned readings, nothing to estimate)";
  } else {
    out.probe = c.noise_estimate->probe;
    out.estimated = true;
    out.source = "estimated by calibrating the plan's readings";
    out.unmodelled = c.unmodelled;
  }
  return out;
}

NoisedEvaluation evaluateWithPredictionNoise(const Plan& plan, const EvaluateOptions& options) {
  NoisedEvaluation out{plan, {}, predictionNoise(plan), std::nullopt};
  out.plan.noise.probe = out.noise.probe;
  out.evaluation = evaluatePlan(out.plan, options);
  if (out.noise.unmodelled)
    out.tip_with_unmodelled = tipWithUnmodelled(out.evaluation, out.noise.unmodelled->sigma,
                                                out.plan.machine.dimension());
  return out;
}

std::vector<std::string> countRepeatsOnce(std::vector<Placement>& placements) {
  std::vector<std::string> out;
  for (std::size_t j = 0; j < placements.size(); ++j) {
    std::vector<Measurement>& readings = placements[j].measurements;
    std::set<std::string> seen;
    const std::size_t before = readings.size();
    std::erase_if(readings,
                  [&](const Measurement& m) { return !seen.insert(readingBits(m)).second; });
    if (readings.size() == before) continue;
    out.push_back("placement " + placementLabel(placements, j) + ": " +
                  std::to_string(before - readings.size()) + " of " + std::to_string(before) +
                  " readings repeat another bit for bit: counted once (--repeats once)");
  }
  return out;
}

}  // namespace artcal
