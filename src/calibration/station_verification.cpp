#include "artcal/calibration/station_verification.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "artcal/core/error.hpp"
#include "artcal/core/units.hpp"
#include "artcal/estimation/reading_noise.hpp"
#include "artcal/model/rotation_vector.hpp"

namespace artcal {

namespace {

struct ReadingLinearization {
  Eigen::VectorXd W;                            ///< R f(p, q) + t
  Eigen::Vector3d e = Eigen::Vector3d::Zero();  ///< a pose's orientation residual (rad)
  /// Rigid columns (rows x 6): the point's rows at W, then a pose's orientation rows.
  Eigen::MatrixXd A;
  Eigen::MatrixXd J;  ///< the same rows' derivatives over the covariance's parameters
  Eigen::MatrixXd Sigma;
};

ReadingLinearization linearize(const Plan& plan, const Artifact& instrument, const Measurement& m,
                               const Eigen::VectorXd& p, const RigidTransform& station,
                               const std::vector<int>& indices) {
  const int d = instrument.dimension;
  const int rows = instrument.rowsPerReading();
  Eigen::VectorXd x;
  Eigen::Matrix3d R;
  Eigen::MatrixXd J_x_p, J_x_q, J_w_p, J_w_q;
  if (instrument.measures_pose)
    forwardReadingPoseOrThrow(plan.machine, p, m, x, R, &J_x_p, &J_x_q, &J_w_p, &J_w_q);
  else
    forwardReadingOrThrow(plan.machine, p, m, x, &J_x_p, &J_x_q);
  ReadingLinearization out;
  out.W = station.apply(x);
  out.A = Eigen::MatrixXd::Zero(rows, instrument.fullRigidDof());
  instrument.fullRigidJacobian(out.W, out.A.topRows(d));
  Eigen::MatrixXd rows_p(rows, J_x_p.cols()), rows_q(rows, J_x_q.cols());
  rows_p.topRows(d) = station.R * J_x_p;
  rows_q.topRows(d) = station.R * J_x_q;
  if (instrument.measures_pose) {  // the orientation rows (design_matrix.hpp)
    Eigen::Matrix3d J_e_w;
    out.e = orientationResidual(Eigen::Matrix3d(station.R * R), m.orientation, &J_e_w);
    const Eigen::Matrix3d factor = J_e_w * station.R;
    rows_p.bottomRows(3) = factor * J_w_p;
    rows_q.bottomRows(3) = factor * J_w_q;
    const std::vector<int>& order = instrument.fullRigidOrder();
    for (std::size_t c = 0; c < order.size(); ++c) {
      if (order[c] >= 3) out.A.block(d, static_cast<int>(c), 3, 1) = J_e_w.col(order[c] - 3);
    }
  }
  out.J.resize(rows, static_cast<int>(indices.size()));
  for (std::size_t k = 0; k < indices.size(); ++k)
    out.J.col(static_cast<int>(k)) = rows_p.col(indices[k]);
  readingCovariance(plan.noise.encoder, rows_q,
                    readingPointVariance(plan.noise.probe, instrument.noise), d,
                    readingAngleVariance(plan.noise.probe, plan.noise.estimate_probe,
                                         instrument.noise, instrument.noise_angle),
                    out.Sigma);
  return out;
}

void summarize(const std::vector<double>& d, DeviationSummary& s) {
  s.count = static_cast<int>(d.size());
  if (d.empty()) return;
  double sum = 0.0, sum2 = 0.0;
  for (double v : d) {
    sum += v;
    sum2 += v * v;
    s.max = std::max(s.max, v);
  }
  s.mean = sum / static_cast<double>(d.size());
  s.rms = std::sqrt(sum2 / static_cast<double>(d.size()));
}

/// The rows of the held-out deviations a sum is over: the point's or a pose's orientation's.
struct RowRange {
  int first = 0;
  int count = 0;
};

// Expected squared deviations of the held-out readings (header), summed over their rows `held_rows`
// (with V_p, without); the station fitted on the fit readings' points (their first d rows). With
// `held_are_fit` the held-out readings are the fit's own, in its order (a station re-registered on
// the readings it scores): a reading's deviation d_i = e_i - A_i K e_s then shares its own error
// with the fit, E|d_i|^2 = tr Sigma_i - 2 tr(A_i K Cov(e_s, e_i)) + tr(A_i K Sigma_s K^T A_i^T),
// the fit's share taken off (about (n - 6) / n of the noise over n readings of a 3-D point, where
// the formula for independent readings would add 6 / n).
double expectedSquares(const std::vector<ReadingLinearization>& fit,
                       const std::vector<ReadingLinearization>& held, const Eigen::MatrixXd* V,
                       int d, RowRange held_rows, bool held_are_fit) {
  const int n_r = static_cast<int>(fit.front().A.cols());
  const int n_s = static_cast<int>(fit.size());
  Eigen::MatrixXd A_s(d * n_s, n_r), J_s(d * n_s, fit.front().J.cols());
  Eigen::MatrixXd Sigma_s = Eigen::MatrixXd::Zero(d * n_s, d * n_s);
  for (int i = 0; i < n_s; ++i) {
    const ReadingLinearization& r = fit[static_cast<std::size_t>(i)];
    A_s.middleRows(d * i, d) = r.A.topRows(d);
    // No calibrated parameter (the nominal machine): J_s has no columns and no data to offset.
    if (J_s.cols() > 0) J_s.middleRows(d * i, d) = r.J.topRows(d);
    Sigma_s.block(d * i, d * i, d, d) = r.Sigma.topLeftCorner(d, d);
  }
  const Eigen::MatrixXd K = (A_s.transpose() * A_s).ldlt().solve(A_s.transpose());
  const Eigen::MatrixXd KJ = K * J_s, KSK = K * Sigma_s * K.transpose();
  double total = 0.0;
  const int first = held_rows.first, count = held_rows.count;
  for (std::size_t k = 0; k < held.size(); ++k) {
    const ReadingLinearization& r = held[k];
    const Eigen::MatrixXd A = r.A.middleRows(first, count);
    total += r.Sigma.block(first, first, count, count).trace() + (A * KSK * A.transpose()).trace();
    if (held_are_fit) {  // Cov(e_s, e_i): reading k's point rows against its rows held_rows
      const Eigen::MatrixXd shared = r.Sigma.block(0, first, d, count);
      total -= 2.0 * (A * K.middleCols(d * static_cast<Eigen::Index>(k), d) * shared).trace();
    }
    if (V) {
      const Eigen::MatrixXd G = r.J.middleRows(first, count) - A * KJ;
      total += (G * (*V) * G.transpose()).trace();
    }
  }
  return total;
}

/// The readings' linearisations with Sigma = I on their point rows and 0 elsewhere: expectedSquares
/// of them without V_p is the unmodelled error's E|d|^2 per unit s_u^2 (verification.hpp).
std::vector<ReadingLinearization> withUnitPointVariance(std::vector<ReadingLinearization> rows,
                                                        int d) {
  for (ReadingLinearization& r : rows) {
    r.Sigma.setZero();
    r.Sigma.topLeftCorner(d, d).setIdentity();
  }
  return rows;
}

/// A deviation kind's figures of one station, and the sums `all` is made of.
struct DeviationTally {
  std::vector<double> deviations;
  double expected = 0.0;    ///< summed expected squares (V_p and the noise)
  double unmodelled = 0.0;  ///< summed expected squares of the unmodelled error
};

void addPrediction(DeviationSummary& summary, double expected, std::size_t count, double scale) {
  if (count > 0) summary.predicted_rms = scale * std::sqrt(expected / static_cast<double>(count));
}

void addUnmodelled(DeviationSummary& summary, double unmodelled, std::size_t count) {
  if (count > 0)
    summary.predicted_rms_unmodelled = std::sqrt(unmodelled / static_cast<double>(count));
}

// The posterior prediction (the Birge ratio's scaling of V_p and the noise, not of the unmodelled
// error) and the total.
void scalePosterior(DeviationSummary& s, double birge) {
  if (birge > 0.0) s.predicted_rms_posterior = birge * s.predicted_rms;
  const double base = basePrediction(s.predicted_rms, s.predicted_rms_posterior);
  if (base > 0.0 || s.predicted_rms_unmodelled > 0.0)
    s.predicted_rms_total = predictedTotal(base, s.predicted_rms_unmodelled);
}

// In the calibration's frame (header): E|d_i|^2 = tr(J_i V_p J_i^T) + tr Sigma_i, no fit.
double inFrameSquares(const ReadingLinearization& r, const Eigen::MatrixXd* V, RowRange rows) {
  double total = r.Sigma.block(rows.first, rows.first, rows.count, rows.count).trace();
  if (V && r.J.cols() > 0) {
    const Eigen::MatrixXd J = r.J.middleRows(rows.first, rows.count);
    total += (J * (*V) * J.transpose()).trace();
  }
  return total;
}

/// The sums of an in-frame scoring: its predictions, summed over readings, to pool stations.
struct InFrameTally {
  double expected = 0.0, unmodelled = 0.0, expected_angles = 0.0;
};

/// One instrument placement: the station fitted, its held-out deviations (points, and a pose's
/// angles in `angular`) and their predictions.
/// The held-out readings of `station` scored with the calibration's `frame` as it is.
InFrameDeviations inFrame(const Plan& plan, const Placement& placement,
                          const StationVerification& station, const CalibrationFrame& frame,
                          const Eigen::VectorXd& p,
                          const std::optional<ParameterUncertainty>& uncertainty,
                          InFrameTally& tally) {
  const Artifact& instrument = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  const int d = instrument.dimension;
  const std::vector<int> no_indices;
  const std::vector<int>& indices = uncertainty ? uncertainty->indices : no_indices;
  const Eigen::MatrixXd* V = uncertainty ? &uncertainty->V : nullptr;
  const double unmodelled = uncertainty ? uncertainty->unmodelled : 0.0;
  InFrameDeviations out;
  out.frame_of = frame.placement;
  std::vector<double> deviations, angular;
  double expected = 0.0, expected_angles = 0.0;
  for (int i : station.held_out) {
    const Measurement& m = placement.measurements[static_cast<std::size_t>(i)];
    const ReadingLinearization r = linearize(plan, instrument, m, p, frame.pose, indices);
    deviations.push_back((m.point - r.W).norm());
    angular.push_back(radToDeg(r.e.norm()));
    expected += inFrameSquares(r, V, {0, d});
    if (instrument.measures_pose) expected_angles += inFrameSquares(r, V, {d, 3});
  }
  out.deviations =
      Eigen::Map<Eigen::VectorXd>(deviations.data(), static_cast<Eigen::Index>(deviations.size()));
  summarize(deviations, out.summary);
  const double unmodelled_sum =
      d * unmodelled * unmodelled * static_cast<double>(deviations.size());
  if (uncertainty) {
    addPrediction(out.summary, expected, deviations.size(), 1.0);
    addUnmodelled(out.summary, unmodelled_sum, deviations.size());
    tally.expected += expected;
    tally.unmodelled += unmodelled_sum;
  }
  if (instrument.measures_pose) {
    out.angular_deviations =
        Eigen::Map<Eigen::VectorXd>(angular.data(), static_cast<Eigen::Index>(angular.size()));
    out.angular.emplace();
    summarize(angular, *out.angular);
    if (uncertainty) {
      addPrediction(*out.angular, expected_angles, angular.size(), radToDeg(1.0));
      tally.expected_angles += expected_angles;
    }
  }
  return out;
}

StationVerification verifyStation(const Plan& plan, std::size_t j, const Eigen::VectorXd& p,
                                  const std::vector<int>& indices, const Eigen::MatrixXd* V,
                                  double unmodelled, DeviationTally& points,
                                  DeviationTally& angles) {
  const Placement& placement = plan.placements[j];
  const Artifact& instrument = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  const bool marked = std::any_of(placement.measurements.begin(), placement.measurements.end(),
                                  [](const Measurement& m) { return m.stationing; });
  StationVerification station;
  station.placement = static_cast<int>(j);
  std::vector<const Measurement*> fit_on;
  for (std::size_t i = 0; i < placement.measurements.size(); ++i) {
    const Measurement& m = placement.measurements[i];
    if (!marked || m.stationing) fit_on.push_back(&m);
    if (!marked || !m.stationing) station.held_out.push_back(static_cast<int>(i));
  }
  const std::string label = placementLabel(plan.placements, j);
  if (fit_on.size() < 3)
    throw InputError(plan.source, "/placements/" + std::to_string(j),
                     "station \"" + label + "\": fewer than 3 stationing readings");
  const int d = instrument.dimension;
  Eigen::MatrixXd machine_points(d, static_cast<int>(fit_on.size()));
  Eigen::MatrixXd measured(d, static_cast<int>(fit_on.size()));
  Eigen::VectorXd x;
  for (std::size_t i = 0; i < fit_on.size(); ++i) {
    forwardReadingOrThrow(plan.machine, p, *fit_on[i], x);
    machine_points.col(static_cast<int>(i)) = x;
    measured.col(static_cast<int>(i)) = fit_on[i]->point;
  }
  station.stationing = static_cast<int>(fit_on.size());
  station.station = fitRigid(machine_points, measured);
  std::vector<double> deviations, angular;
  std::vector<ReadingLinearization> fit_lin, held_lin;
  for (const Measurement* m : fit_on)
    fit_lin.push_back(linearize(plan, instrument, *m, p, station.station, indices));
  for (int i : station.held_out) {
    const Measurement& m = placement.measurements[static_cast<std::size_t>(i)];
    held_lin.push_back(linearize(plan, instrument, m, p, station.station, indices));
    deviations.push_back((m.point - held_lin.back().W).norm());
    angular.push_back(radToDeg(held_lin.back().e.norm()));
  }
  station.deviations =
      Eigen::Map<Eigen::VectorXd>(deviations.data(), static_cast<Eigen::Index>(deviations.size()));
  summarize(deviations, station.summary);
  points.deviations.insert(points.deviations.end(), deviations.begin(), deviations.end());
  if (held_lin.empty()) return station;
  const double expected = expectedSquares(fit_lin, held_lin, V, d, {0, d}, !marked);
  points.expected += expected;
  addPrediction(station.summary, expected, held_lin.size(), 1.0);
  if (unmodelled > 0.0) {
    const double per_unit =
        expectedSquares(withUnitPointVariance(fit_lin, d), withUnitPointVariance(held_lin, d),
                        nullptr, d, {0, d}, !marked);
    const double share = unmodelled * unmodelled * std::max(0.0, per_unit);
    points.unmodelled += share;
    addUnmodelled(station.summary, share, held_lin.size());
  }
  if (instrument.measures_pose) {
    station.angular_deviations =
        Eigen::Map<Eigen::VectorXd>(angular.data(), static_cast<Eigen::Index>(angular.size()));
    station.angular.emplace();
    summarize(angular, *station.angular);
    angles.deviations.insert(angles.deviations.end(), angular.begin(), angular.end());
    const double expected_angles = expectedSquares(fit_lin, held_lin, V, d, {d, 3}, !marked);
    angles.expected += expected_angles;
    addPrediction(*station.angular, expected_angles, held_lin.size(), radToDeg(1.0));
  }
  return station;
}

}  // namespace

StationsVerification verifyStations(const Plan& plan, const Eigen::VectorXd& p,
                                    const std::optional<ParameterUncertainty>& uncertainty,
                                    const std::vector<std::optional<CalibrationFrame>>& frames) {
  StationsVerification out;
  const std::vector<int> no_indices;
  const std::vector<int>& indices = uncertainty ? uncertainty->indices : no_indices;
  const Eigen::MatrixXd* V = uncertainty ? &uncertainty->V : nullptr;
  const double unmodelled = uncertainty ? uncertainty->unmodelled : 0.0;
  DeviationTally points, angles;
  InFrameTally in_frame_tally;
  double reregistered_expected = 0.0, reregistered_unmodelled = 0.0,
         reregistered_expected_angles = 0.0;
  std::vector<double> in_frame, reregistered, in_frame_angular, reregistered_angular;
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const Artifact& instrument =
        plan.artifacts[static_cast<std::size_t>(plan.placements[j].artifact)];
    if (!instrument.kind().readings_are_features) continue;
    out.stations.push_back(verifyStation(plan, j, p, indices, V, unmodelled, points, angles));
    StationVerification& station = out.stations.back();
    if (station.angular && !out.angular_all) out.angular_all.emplace();
    if (j < frames.size() && frames[j]) {
      station.in_frame =
          inFrame(plan, plan.placements[j], station, *frames[j], p, uncertainty, in_frame_tally);
      const auto held = static_cast<double>(station.held_out.size());
      const DeviationSummary& own = station.summary;
      reregistered_expected += own.predicted_rms * own.predicted_rms * held;
      reregistered_unmodelled += own.predicted_rms_unmodelled * own.predicted_rms_unmodelled * held;
      if (station.angular) {
        const double angle_rms = station.angular->predicted_rms / radToDeg(1.0);
        reregistered_expected_angles += angle_rms * angle_rms * held;
      }
      const InFrameDeviations& f = *station.in_frame;
      in_frame.insert(in_frame.end(), f.deviations.begin(), f.deviations.end());
      reregistered.insert(reregistered.end(), station.deviations.begin(), station.deviations.end());
      in_frame_angular.insert(in_frame_angular.end(), f.angular_deviations.begin(),
                              f.angular_deviations.end());
      reregistered_angular.insert(reregistered_angular.end(), station.angular_deviations.begin(),
                                  station.angular_deviations.end());
    }
  }
  const bool predicted = uncertainty.has_value();
  if (!in_frame.empty()) {
    summarize(in_frame, out.in_frame_all.emplace());
    summarize(reregistered, out.reregistered_all.emplace());
    if (predicted) {
      addPrediction(*out.in_frame_all, in_frame_tally.expected, in_frame.size(), 1.0);
      addUnmodelled(*out.in_frame_all, in_frame_tally.unmodelled, in_frame.size());
      addPrediction(*out.reregistered_all, reregistered_expected, reregistered.size(), 1.0);
      addUnmodelled(*out.reregistered_all, reregistered_unmodelled, reregistered.size());
    }
  }
  if (!in_frame_angular.empty() && out.angular_all) {
    summarize(in_frame_angular, out.in_frame_angular_all.emplace());
    summarize(reregistered_angular, out.reregistered_angular_all.emplace());
    if (predicted) {
      addPrediction(*out.in_frame_angular_all, in_frame_tally.expected_angles,
                    in_frame_angular.size(), radToDeg(1.0));
      addPrediction(*out.reregistered_angular_all, reregistered_expected_angles,
                    reregistered_angular.size(), radToDeg(1.0));
    }
  }
  summarize(points.deviations, out.all);
  addPrediction(out.all, points.expected, points.deviations.size(), 1.0);
  addUnmodelled(out.all, points.unmodelled, points.deviations.size());
  if (out.angular_all) {
    summarize(angles.deviations, *out.angular_all);
    addPrediction(*out.angular_all, angles.expected, angles.deviations.size(), radToDeg(1.0));
  }
  if (predicted) {
    const double birge = uncertainty->birge_ratio;
    auto finish = [birge](std::optional<DeviationSummary>& s) {
      if (s) scalePosterior(*s, birge);
    };
    for (StationVerification& s : out.stations) {
      scalePosterior(s.summary, birge);
      finish(s.angular);
      if (s.in_frame) {
        scalePosterior(s.in_frame->summary, birge);
        finish(s.in_frame->angular);
      }
    }
    scalePosterior(out.all, birge);
    finish(out.angular_all);
    finish(out.in_frame_all);
    finish(out.reregistered_all);
    finish(out.in_frame_angular_all);
    finish(out.reregistered_angular_all);
  }
  return out;
}

}  // namespace artcal
