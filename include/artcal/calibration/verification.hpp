#pragma once
// Verification of a (calibrated) machine on readings it has not seen (docs/models.md section 6):
// the parameters are held fixed, every placement's rigid transform is fitted (Gauss-Newton on the
// same whitened observation blocks the calibrator uses, started from the same Umeyama fit), and
// the figures a metrologist reads are computed per placement:
//
// - spread of a feature: its postures' machine-frame positions x_i = f(p, q_i), their mean m,
//   spread_mean = mean |x_i - m| (MUKCa's MAE), spread_rms = sqrt(mean |x_i - m|^2);
// - length errors: for every pair (a, b) of measured features, |m_b - m_a| - |W*_b - W*_a|;
// - residuals of the rigid fit: |[R x_i + t - W*_i]_valued| per reading.
//
// Predicted figures, when the parameters' covariance V_p (of the calibration that produced them)
// is given. The deviation of posture i from the feature mean is
//   d_i = (J_i - Jbar) dp + (e_i - ebar),   J_i = df/dp at q_i over the covariance's parameters,
// with dp ~ (0, V_p) the calibration's parameter error and e_i ~ (0, Sigma_i) the reading's own
// error, Sigma_i = s_p^2 I + J_q,i Sigma_q J_q,i^T (docs/method.md section 2: probing and
// encoders), independent between readings. Hence
//   E|d_i|^2 = tr((J_i - Jbar) V_p (J_i - Jbar)^T) + tr(Sigma_i) (1 - 2/n) + tr(sum_k Sigma_k)/n^2
// and predicted_spread_rms = sqrt(mean_i E|d_i|^2). A length error's predicted u is the standard
// deviation of u^T (m_b - m_a), u the unit direction between the means, with Cov(m_b - m_a) =
// (Jbar_b - Jbar_a) V_p (...)^T + sum Sigma_i / n_a^2 + sum Sigma_k / n_b^2, plus the artifact's
// own calibration uncertainty of that distance (its systematic errors). What is not modelled
// (gear errors, elasticity, a socket that moved) is exactly what the observed figures show beyond
// the predicted ones.
//
// The posterior prediction: when the calibration's own readings scattered s = sqrt(chi2/dof)
// times the stated noise (its Birge ratio), the a-posteriori variance factor s^2 scales every
// Sigma_i and, with them, V_p; E|d_i|^2 is linear in both, so the prediction scales by s. It is
// the prediction for readings that scatter as the calibration's did (the same factor as the
// calibration's u_posterior); unmodelled errors that differ between placements it cannot know.
// A calibration that estimated its probe noise (`"probe": "estimate"`) has a Birge ratio of 1 by
// construction: its readings scattered as the estimate s_e says. When the plan verified states a
// probe noise of its own (import-readings' first guess), the posterior prediction is then the one
// with s_e in place of the stated noise (V_p is already in the units of s_e), times that ratio.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "artcal/artifact/rigid_transform.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// The covariance of some of the model's parameters (internal units).
struct ParameterUncertainty {
  std::vector<int> indices;  ///< into the model's full parameter vector
  Eigen::MatrixXd V;         ///< indices.size() squared
  /// sqrt(chi2/dof) of the calibration that produced V, 0 when not known. The readings of that
  /// fit scattered this many times as much as the stated noise says.
  double birge_ratio = 0.0;
  /// The probe noise the calibration estimated (`"probe": "estimate"`), mm; 0 when it was stated.
  /// V is in the units of that noise; a plan that also says "estimate" predicts with it.
  double probe_noise = 0.0;
  /// The error the model does not explain (unmodelled_error.hpp), mm per coordinate of a point;
  /// 0 when not estimated. It adds s_u^2 I to each held-out reading's point covariance in the
  /// predictions, apart from the noise (not scaled by the Birge ratio).
  double unmodelled = 0.0;
};

/// A predicted RMS of held-out deviations in its three parts (mm) and their sum in quadrature:
/// `base` from the parameters' covariance and the noise (the posterior one when the Birge ratio
/// is known, else the stated noise's), `unmodelled` from ParameterUncertainty::unmodelled.
/// total = sqrt(base^2 + unmodelled^2).
double predictedTotal(double base, double unmodelled);
/// The base of a total: the posterior prediction when the Birge ratio gave one, else the plain.
inline double basePrediction(double plain, double posterior) {
  return posterior > 0.0 ? posterior : plain;
}

/// The noise a plan's held-out readings are predicted with: a probe noise of `"estimate"` is the
/// one the calibration behind `uncertainty` estimated (verify's prediction of held-out readings
/// of the same machine); a stated noise stays. A new value: the plan is not changed.
Noise withEstimatedProbeNoise(const Noise& noise,
                              const std::optional<ParameterUncertainty>& uncertainty);

struct FeatureSpread {
  int feature = 0;
  int postures = 0;
  Eigen::VectorXd mean;               ///< machine-frame mean position, mm
  double spread_mean = 0.0;           ///< mm
  double spread_rms = 0.0;            ///< mm
  double predicted_spread_rms = 0.0;  ///< mm
  /// predicted_spread_rms times the calibration's Birge ratio, 0 when that is not known.
  double predicted_spread_rms_posterior = 0.0;
  /// The unmodelled error's share of the predicted spread (mm): sqrt(d s_u^2 (n - 1) / n) over
  /// n postures of a d-dimensional point (a posture's deviation from the mean of n keeps
  /// (n - 1) / n of an independent error's variance).
  double predicted_spread_rms_unmodelled = 0.0;
  /// predictedTotal of the posterior (or plain) prediction and the unmodelled share, mm.
  double predicted_spread_rms_total = 0.0;
};

struct LengthError {
  int from = 0;
  int to = 0;
  double error = 0.0;        ///< |m_to - m_from| - calibrated distance, mm
  double predicted_u = 0.0;  ///< mm
  /// predicted_u for readings that scatter as the calibration's did (as the spread's posterior);
  /// 0 when the calibration's Birge ratio is not known.
  double predicted_u_posterior = 0.0;
};

/// A frame the calibration estimated for one of its placements (machine -> artifact, or the
/// instrument's station), with which held-out readings are scored without re-registration when
/// the artifact or the instrument stayed where it was (docs/models.md section 6).
struct CalibrationFrame {
  std::string placement;  ///< the calibration plan's placement label
  RigidTransform pose;
};

/// A plane's flush touches (docs/planes.md, "verify"): RMS over them of the height (the tool
/// face's distance from the plane) and of the tool's tilts against the plane about its own x
/// (roll) and y (pitch): roll and pitch of R_face^T R_tool, the tool frame the tip frame turned
/// the least way so that its z is minus the tool axis.
struct FlushFigures {
  int touches = 0;
  double height_rms = 0.0;  ///< mm
  double roll_rms = 0.0;    ///< rad
  double pitch_rms = 0.0;   ///< rad
};

/// A placement's residuals in the calibration's frame (`pose` of the frame, not refitted).
struct InFrameResiduals {
  std::string frame_of;       ///< the calibration's placement whose frame scored them
  Eigen::VectorXd residuals;  ///< |[R x_i + t - W*_i]_valued| per reading, mm
  double residual_rms = 0.0;
  double residual_max = 0.0;
  std::optional<FlushFigures> flush;  ///< a plane's flush touches, in that frame
};

struct PlacementVerification {
  int index = 0;
  std::vector<FeatureSpread> features;
  std::vector<LengthError> length_errors;
  RigidTransform pose;         ///< fitted, machine -> artifact
  Eigen::VectorXd residuals;   ///< |residual| per reading, mm, in measurement order
  Eigen::VectorXd deviations;  ///< |x_i - m| per reading, mm, in measurement order
  double residual_rms = 0.0;
  double residual_max = 0.0;
  /// The same residuals in the calibration's frame, when one was given for this placement.
  std::optional<InFrameResiduals> in_frame;
  /// A plane's flush touches, the placement refitted.
  std::optional<FlushFigures> flush;
};

struct Verification {
  std::vector<PlacementVerification> placements;
  bool predicted = false;                       ///< a covariance was given
  double spread_rms = 0.0;                      ///< over every posture of every placement
  double spread_mean = 0.0;                     ///< mean |x_i - m| over every posture (MUKCa's MAE)
  double predicted_spread_rms = 0.0;            ///< sqrt of the mean predicted |d_i|^2
  double birge_ratio = 0.0;                     ///< the calibration's, 0 when not known
  double predicted_spread_rms_posterior = 0.0;  ///< predicted_spread_rms * birge_ratio
  double predicted_spread_rms_unmodelled = 0.0;  ///< the unmodelled error's share, mm
  double unmodelled = 0.0;  ///< ParameterUncertainty::unmodelled predicted with, mm
  /// predictedTotal of the posterior (or plain) prediction and the unmodelled share, mm.
  double predicted_spread_rms_total = 0.0;
  /// The calibration's estimated probe noise (mm) the posterior prediction was made with when
  /// the plan states another (see the header); 0 when the posterior is the Birge ratio's scaling.
  double posterior_probe_noise = 0.0;
  double length_error_rms = 0.0;  ///< over every pair of every placement
  double length_error_mean_abs = 0.0;
  double residual_rms = 0.0;
  /// Over the placements scored in the calibration's frame (in_frame_placements > 0): their
  /// residual RMS in that frame and, on the same readings, re-registered.
  int in_frame_placements = 0;
  double in_frame_residual_rms = 0.0;
  double reregistered_residual_rms = 0.0;
  /// Over every placement's flush touches (refitted; and in the calibration's frames, over the
  /// placements scored in one).
  std::optional<FlushFigures> flush, flush_in_frame;
};

struct VerifyOptions {
  int max_iterations = 30;        ///< Gauss-Newton steps of each rigid fit
  double step_tolerance = 1e-12;  ///< mm (and rad): a rigid step smaller than this stops
  /// Per placement of the plan (empty: none), the calibration's frame to score it in as well,
  /// beside the re-registered figures.
  std::vector<std::optional<CalibrationFrame>> calibration_frames = {};
};

/// Verifies the full parameter vector `p` on every placement of `plan`. `uncertainty`, when
/// given, supplies V_p for the predicted figures (without it they are those of the readings'
/// own noise alone). KinematicsError when a reading's forward kinematics fails.
Verification verifyMachine(const Plan& plan, const Eigen::VectorXd& p,
                           const std::optional<ParameterUncertainty>& uncertainty,
                           const VerifyOptions& options = {});

/// The plan's own nominal machine on the same readings, which `verify --machine` shows beside the
/// calibrated one: a calibration that does worse than nominal on readings it never saw does not
/// hold there (trained too far from them, or fooled by its own readings). nullopt when the
/// nominal machine's forward kinematics fails on a reading.
std::optional<Verification> verifyNominal(const Plan& plan, const VerifyOptions& options = {});

/// A figure `verify --machine` compares with the nominal machine's: its JSON name, the words a
/// sentence gives it, and where a Verification holds it.
struct ComparedFigure {
  const char* name;
  const char* words;
  double Verification::*value;
};
/// The MUKCa figures, in the order they are reported.
inline constexpr ComparedFigure kComparedFigures[] = {
    {"spread_mean", "spread mean", &Verification::spread_mean},
    {"spread_rms", "spread rms", &Verification::spread_rms},
    {"length_error_mean_abs", "length error mean |e|", &Verification::length_error_mean_abs}};

/// The figures are printed to the micrometre: two that print alike are not called worse ("0.009 mm
/// > 0.009 mm" was warned).
inline constexpr double kComparedFigureResolution = 1e-3;  // mm

/// The overall figures (kComparedFigures) in which `calibrated` does worse than `nominal` on the
/// same readings, by their JSON names, by more than kComparedFigureResolution shows.
/// A spread averages every posture's deviation, and the two machines see the same readings, so a
/// larger one is worse. A length error is one number per pair, the nominal one can be small by
/// chance: its mean |e| counts as worse only beyond twice the RMS of the calibrated machine's
/// predicted u of the pairs (posterior when known), what the calibration itself says it can do.
std::vector<std::string> worseThanNominal(const Verification& calibrated,
                                          const Verification& nominal);

}  // namespace artcal
