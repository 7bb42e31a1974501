#pragma once
// Calibrating measured readings (docs/method.md sections 5 and 6, "Real readings"): the
// calibrator (calibrator.hpp) with what readings of a real machine need and planned readings do
// not.
//
// - Weakly determined parameters. With `"calibrate": "identifiable"`, the plan's resolution
//   (identifiability.hpp) keeps what the readings can separate at all (surviving fraction of the
//   scaled reduced information above 1e-10). On measured readings a direction whose surviving
//   fraction is of the order of the model mismatch (below kWeakInformationTolerance = 1e-6, the
//   independent reference's |R_kk|/|R_00| > 1e-3 of a column-pivoted QR of the column-scaled
//   reduced Jacobian) would be set by that mismatch, not by the data: it is held at nominal. The
//   rule runs at the nominal parameters, then again at the estimate (the calibration is repeated
//   when the estimate drops more), greedily in the listed order.
// - Noise that the data state. `"noise": {"probe": "estimate"}`: the probing noise s_p is the
//   variance component that makes chi2 = dof at the estimate (encoder noise as stated), the fit
//   repeated with it until s_p settles (the weights depend on s_p when encoders add noise).
//   u(s_p) = sqrt(2 dof) / |d chi2/d s_p| (the chi-square's spread over its slope; s_p / sqrt(2
//   dof) without encoder or instrument noise). u, gross errors and the
//   machine file's covariance then use the estimated s_p.
// - Warnings a metrologist would want: corrections no one would believe (corrections.hpp) and
//   readings that fit to rounding (planned readings calibrated as if measured).

#include <Eigen/Core>
#include <optional>

#include "artcal/calibration/calibrator.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// chi2/dof below this is no real probe's: the readings are consistent to rounding.
inline constexpr double kRoundingChi2PerDof = 1e-8;

/// A calibration of measured readings and what it decided. `decided` is the plan as calibrated:
/// machine.calibrated without the parameters held at nominal (the weakly determined ones,
/// recorded in calibrate_resolution->weak, and those the held-out model choice left out),
/// calibrate_resolution->kept the same set, noise.probe the s_p the estimate was computed with
/// (the variance component when the plan says "estimate"; its estimate and u also in
/// calibration.noise_estimate). Every output of the calibration (the tables, the machine file,
/// verify, the report, Python) reads these, so that it names what was estimated and with which
/// noise.
struct CalibrationRun {
  Calibration calibration;
  Plan decided;

  /// The calibrated parameters' indices (into the machine's parameters), in calibration order.
  const std::vector<int>& kept() const { return decided.machine.calibrated; }
  /// The parameters the weak-direction rule held at nominal (none when the plan lists its set).
  std::vector<int> held() const {
    return decided.calibrate_resolution ? decided.calibrate_resolution->weak : std::vector<int>{};
  }
  /// The probe noise s_p (mm) the calibration whitened the readings with (its estimate and u in
  /// calibration.noise_estimate when the plan says "estimate").
  double probeNoise() const { return decided.noise.probe; }
};

/// Calibrates `plan`'s readings as calibratePlan does, with the weak-direction rule, the plausible
/// minimum, the held-out model choice and the noise estimate above. No plan is changed during the
/// run: each decision (parameters held, a noise estimated, a kept set chosen) makes a new plan,
/// the last of which is the result's `decided`; a calibrator's plan never changes under it.
CalibrationRun calibrateReadings(const Plan& plan, const CalibrationOptions& options = {});

/// The unmodelled error of a run by cross-validation (unmodelled_error.hpp): its folds
/// calibrated with the run's decided set and noise model; std::nullopt when fewer than two folds
/// could be calibrated and scored. calibrateReadings calls it (CalibrationOptions::
/// cross_validation) on measured readings that converged.
std::optional<UnmodelledError> estimateUnmodelledError(const CalibrationRun& run,
                                                       const CalibrationOptions& options);

/// The probe noise `evaluate` and `report` predict with (issue 43): a stated one as stated; for a
/// plan that says `"probe": "estimate"`, the estimate of the calibration of its own readings
/// (`run`, or calibrated here when null) where they are measured, else the starting value, with
/// the reason in `source` (planned readings fit to rounding; the fit did not converge; readings
/// without their measured points).
struct PredictionNoise {
  double probe = 0.0;      ///< mm
  bool estimated = false;  ///< the calibration's estimate
  std::string source;      ///< in words, for the table and the JSON
  /// The unmodelled error the same calibration estimated by cross-validation, when it did
  /// (measured readings that converged): the tip map's S_u (tipWithUnmodelled).
  std::optional<UnmodelledError> unmodelled;
};
PredictionNoise predictionNoise(const Plan& plan, const CalibrationRun* run = nullptr);

/// `evaluate` as the command line and Python run it: the plan with its prediction noise
/// (predictionNoise), evaluated.
struct NoisedEvaluation {
  Plan plan;  ///< the plan evaluated: the given one, its probe noise the prediction noise
  Evaluation evaluation;
  PredictionNoise noise;
  /// The tip map with the unmodelled error (tipWithUnmodelled), where noise.unmodelled is known.
  std::optional<TipWithUnmodelled> tip_with_unmodelled;
};
NoisedEvaluation evaluateWithPredictionNoise(const Plan& plan, const EvaluateOptions& options);

/// Readings repeated bit for bit counted once (`calibrate --repeats once`, docs/hardening.md): in
/// each placement every copy of an earlier reading (the same feature, tip, joints and measured
/// point or pose) is removed. Returns one line per placement that had copies, naming how many.
/// (Input preparation before a run, on the readings as loaded.)
std::vector<std::string> countRepeatsOnce(std::vector<Placement>& placements);

/// The probe noise s_p (mm) that makes chi2 = dof at the calibration's estimate, the encoder
/// noise as stated; 0 when the encoders alone explain more than the scatter (see NoiseEstimate).
/// A pose instrument's orientation rows join with their share of s_p^2 when the plan estimates
/// the probe noise (reading_noise.hpp), as in calibrateReadings' own estimate.
double probeNoiseForUnitBirgeRatio(const Plan& plan, const std::vector<Placement>& placements,
                                   const Calibration& calibration);

}  // namespace artcal
