#pragma once
// Verification of a calibrated machine on an instrument's held-out station (instruments.md,
// "What verify and the report give"). With the parameters held, each station is fitted (a plain
// least-squares rigid fit, fitRigid) on its readings marked `"stationing": true` (on all of them
// when none is marked); the result is the deviations of the other readings: |W_i - (R f(p, q_i) +
// t)|, their mean, RMS and max per station and in all.
//
// Predicted RMS, to first order: with y_s = A_s dr + J_s dp + e_s the stationing readings' misfit
// (A the rigid columns at W, J = R df/dp, e the reading's error, Sigma_i = (s_p^2 + s_inst^2) I +
// R J_q Sigma_q J_q^T R^T), the fit takes dr = K (J_s dp + e_s), K = (A_s^T A_s)^-1 A_s^T, and a
// held-out reading's deviation is d_i = (J_i - A_i K J_s) dp + e_i - A_i K e_s, so
//   E|d_i|^2 = tr(G V_p G^T) + tr(Sigma_i) + tr(A_i K Sigma_s K^T A_i^T),  G = J_i - A_i K J_s,
// and predicted_rms = sqrt(mean_i E|d_i|^2) over the held-out readings (the posterior one scales
// V_p and the Sigma by the calibration's Birge ratio squared).
//
// A pose instrument (`"measures": "pose"`): the station is fitted on the stationing readings'
// points as above, and each held-out reading also has an angular deviation, |e_i| with e_i =
// log(R_r R(p, q_i) exp([m_i]x)^T) (deg). Its prediction is the same formula over the
// orientation rows: B_i = [0, J_l^-1(e_i)] the rigid columns, J_i = J_l^-1(e_i) R_r J_w_p, Sigma_i
// = s_angle^2 I + (J_l^-1 R_r J_w_q) Sigma_q (...)^T, with K from the points' fit.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "artcal/calibration/verification.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

struct DeviationSummary {
  int count = 0;
  double mean = 0.0;                     ///< mm
  double rms = 0.0;                      ///< mm
  double max = 0.0;                      ///< mm
  double predicted_rms = 0.0;            ///< mm, 0 without V_p
  double predicted_rms_posterior = 0.0;  ///< mm, 0 without a Birge ratio
  /// The unmodelled error's share (ParameterUncertainty::unmodelled): the same formula with
  /// Sigma_i = s_u^2 I on the point rows, no V_p (mm; angles: 0, s_u is a point's).
  double predicted_rms_unmodelled = 0.0;
  double predicted_rms_total = 0.0;  ///< predictedTotal(posterior or plain, unmodelled), mm
};

/// A station's held-out readings scored with the station the calibration estimated (no
/// re-registration): the instrument stood still between the sessions.
struct InFrameDeviations {
  std::string frame_of;        ///< the calibration's placement whose station scored them
  Eigen::VectorXd deviations;  ///< mm, per held-out reading, as StationVerification's
  /// Its prediction: E|d_i|^2 = tr(J_i V_p J_i^T) + tr Sigma_i (+ 3 s_u^2), no fit's share taken
  /// off; the calibration's own uncertainty of the station (of order the noise over the square
  /// root of its readings) is left out.
  DeviationSummary summary;
  Eigen::VectorXd angular_deviations;       ///< deg, a pose instrument only
  std::optional<DeviationSummary> angular;  ///< deg, a pose instrument only
};

struct StationVerification {
  int placement = 0;           ///< index into Plan::placements
  int stationing = 0;          ///< readings the station was fitted on
  RigidTransform station;      ///< fitted, machine -> instrument
  Eigen::VectorXd deviations;  ///< mm, per held-out reading, in measurement order
  std::vector<int> held_out;   ///< the held-out readings' indices in the placement
  DeviationSummary summary;
  /// A pose instrument only: the angular deviations (deg) and their summary (its figures in deg).
  Eigen::VectorXd angular_deviations;
  std::optional<DeviationSummary> angular;
  /// The same held-out readings in the calibration's frame, when one was given for this station.
  std::optional<InFrameDeviations> in_frame;
};

struct StationsVerification {
  std::vector<StationVerification> stations;
  DeviationSummary all;
  std::optional<DeviationSummary> angular_all;  ///< deg; when a station is a pose instrument's
  /// Over the stations scored in the calibration's frame: their held-out deviations in that
  /// frame, and (`reregistered_all`) the same readings' deviations with the station refitted.
  std::optional<DeviationSummary> in_frame_all, reregistered_all;
  std::optional<DeviationSummary> in_frame_angular_all, reregistered_angular_all;  ///< deg
};

/// The instrument placements of `plan` verified at full parameters `p`; `uncertainty` (optional)
/// gives the predicted RMS. A station with fewer than 3 stationing readings, or none held out,
/// raises InputError naming the placement. `frames` (per placement of `plan`, may be empty): the
/// station the calibration estimated, with which the held-out readings are also scored as they
/// are, without a fit (InFrameDeviations); with every reading held out the re-registered RMS is
/// the least-squares minimum over stations, so the in-frame RMS is never below it.
StationsVerification verifyStations(
    const Plan& plan, const Eigen::VectorXd& p,
    const std::optional<ParameterUncertainty>& uncertainty,
    const std::vector<std::optional<CalibrationFrame>>& frames = {});

}  // namespace artcal
