#include "artcal/calibration/station_verification.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "artcal/core/error.hpp"
#include "artcal/estimation/reading_noise.hpp"

namespace artcal {

namespace {

struct ReadingLinearization {
  Eigen::VectorXd W;  ///< R f(p, q) + t
  Eigen::MatrixXd A;  ///< rigid columns at W (3 x 6)
  Eigen::MatrixXd J;  ///< R df/dp over the covariance's parameters
  Eigen::MatrixXd Sigma;
};

ReadingLinearization linearize(const Plan& plan, const Artifact& instrument, const Measurement& m,
                               const Eigen::VectorXd& p, const RigidTransform& station,
                               const std::vector<int>& indices) {
  const Machine& machine = plan.machine;
  Eigen::VectorXd x;
  Eigen::MatrixXd J_x_p, J_x_q;
  forwardOrThrow(*machine.mechanism, p, m.joints, x, &J_x_p, &J_x_q, m.stylus);
  ReadingLinearization out;
  out.W = station.apply(x);
  out.A.resize(instrument.dimension, instrument.fullRigidDof());
  instrument.fullRigidJacobian(out.W, out.A);
  out.J.resize(instrument.dimension, static_cast<int>(indices.size()));
  for (std::size_t k = 0; k < indices.size(); ++k)
    out.J.col(static_cast<int>(k)) = station.R * J_x_p.col(indices[k]);
  const Eigen::MatrixXd Jq = station.R * J_x_q;
  readingCovariance(plan.noise.encoder, Jq,
                    readingPointVariance(plan.noise.probe, instrument.noise), out.Sigma);
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

// Expected squared deviations of the held-out readings (header), summed: (with V_p, without).
double expectedSquares(const std::vector<ReadingLinearization>& fit,
                       const std::vector<ReadingLinearization>& held, const Eigen::MatrixXd* V) {
  const int n_r = static_cast<int>(fit.front().A.cols());
  const int d = static_cast<int>(fit.front().A.rows());
  const int n_s = static_cast<int>(fit.size());
  Eigen::MatrixXd A_s(d * n_s, n_r), J_s(d * n_s, fit.front().J.cols());
  Eigen::MatrixXd Sigma_s = Eigen::MatrixXd::Zero(d * n_s, d * n_s);
  for (int i = 0; i < n_s; ++i) {
    A_s.middleRows(d * i, d) = fit[static_cast<std::size_t>(i)].A;
    // No calibrated parameter (the nominal machine): J_s has no columns and no data to offset.
    if (J_s.cols() > 0) J_s.middleRows(d * i, d) = fit[static_cast<std::size_t>(i)].J;
    Sigma_s.block(d * i, d * i, d, d) = fit[static_cast<std::size_t>(i)].Sigma;
  }
  const Eigen::MatrixXd K = (A_s.transpose() * A_s).ldlt().solve(A_s.transpose());
  const Eigen::MatrixXd KJ = K * J_s, KSK = K * Sigma_s * K.transpose();
  double total = 0.0;
  for (const ReadingLinearization& r : held) {
    total += r.Sigma.trace() + (r.A * KSK * r.A.transpose()).trace();
    if (V) {
      const Eigen::MatrixXd G = r.J - r.A * KJ;
      total += (G * (*V) * G.transpose()).trace();
    }
  }
  return total;
}

}  // namespace

StationsVerification verifyStations(const Plan& plan, const Eigen::VectorXd& p,
                                    const std::optional<ParameterUncertainty>& uncertainty) {
  StationsVerification out;
  const std::vector<int> no_indices;
  const std::vector<int>& indices = uncertainty ? uncertainty->indices : no_indices;
  std::vector<double> all;
  double all_expected = 0.0;
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const Placement& placement = plan.placements[j];
    const Artifact& instrument = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    if (instrument.kind != ArtifactKind::Instrument) continue;
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
    Eigen::MatrixXd machine_points(instrument.dimension, static_cast<int>(fit_on.size()));
    Eigen::MatrixXd measured(instrument.dimension, static_cast<int>(fit_on.size()));
    Eigen::VectorXd x;
    for (std::size_t i = 0; i < fit_on.size(); ++i) {
      forwardOrThrow(*plan.machine.mechanism, p, fit_on[i]->joints, x, nullptr, nullptr,
                     fit_on[i]->stylus);
      machine_points.col(static_cast<int>(i)) = x;
      measured.col(static_cast<int>(i)) = fit_on[i]->point;
    }
    station.stationing = static_cast<int>(fit_on.size());
    station.station = fitRigid(machine_points, measured);
    std::vector<double> deviations;
    std::vector<ReadingLinearization> fit_lin, held_lin;
    for (const Measurement* m : fit_on)
      fit_lin.push_back(linearize(plan, instrument, *m, p, station.station, indices));
    for (int i : station.held_out) {
      const Measurement& m = placement.measurements[static_cast<std::size_t>(i)];
      held_lin.push_back(linearize(plan, instrument, m, p, station.station, indices));
      deviations.push_back((m.point - held_lin.back().W).norm());
    }
    station.deviations = Eigen::Map<Eigen::VectorXd>(deviations.data(),
                                                     static_cast<Eigen::Index>(deviations.size()));
    summarize(deviations, station.summary);
    all.insert(all.end(), deviations.begin(), deviations.end());
    if (!held_lin.empty()) {
      const double expected =
          expectedSquares(fit_lin, held_lin, uncertainty ? &uncertainty->V : nullptr);
      all_expected += expected;
      station.summary.predicted_rms = std::sqrt(expected / static_cast<double>(held_lin.size()));
    }
    out.stations.push_back(std::move(station));
  }
  summarize(all, out.all);
  if (!all.empty())
    out.all.predicted_rms = std::sqrt(all_expected / static_cast<double>(all.size()));
  const double birge = uncertainty ? uncertainty->birge_ratio : 0.0;
  if (birge > 0.0) {
    for (StationVerification& s : out.stations)
      s.summary.predicted_rms_posterior = birge * s.summary.predicted_rms;
    out.all.predicted_rms_posterior = birge * out.all.predicted_rms;
  }
  return out;
}

}  // namespace artcal
