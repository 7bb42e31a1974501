#include "artcal/calibration/verification.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numbers>
#include "artcal/core/dense_decompositions.hpp"

#include "artcal/estimation/design_matrix.hpp"
#include "artcal/estimation/normal_matrix.hpp"
#include "artcal/estimation/plane_rows.hpp"
#include "artcal/estimation/reading_noise.hpp"

namespace artcal {

namespace {

/// Machine-frame position, its Jacobian over the covariance's parameters and the covariance of
/// the reading's own error (probing and encoders, docs/method.md section 2) of one reading.
struct ReadingModel {
  Eigen::VectorXd x;
  Eigen::MatrixXd J;
  Eigen::MatrixXd Sigma;
};

ReadingModel modelReading(const Plan& plan, const Eigen::VectorXd& p, const Measurement& m,
                          const std::vector<int>& indices) {
  ReadingModel out;
  Eigen::MatrixXd J_x_p, J_x_q;
  forwardReadingOrThrow(plan.machine, p, m, out.x, &J_x_p, &J_x_q);
  const int d = static_cast<int>(out.x.size());
  out.J.resize(d, static_cast<int>(indices.size()));
  for (std::size_t k = 0; k < indices.size(); ++k)
    out.J.col(static_cast<int>(k)) = J_x_p.col(indices[k]);
  readingCovariance(plan.noise.encoder, J_x_q, readingPointVariance(plan.noise.probe, 0.0),
                    out.Sigma);
  return out;
}

/// The placement's rigid transform with p held fixed: Gauss-Newton on the whitened observation
/// block from the Umeyama start (the calibrator's r_j update with dg = 0).
RigidTransform fitRigidOnly(DesignMatrixBuilder& builder, const Artifact& artifact,
                            const Placement& placement, const Eigen::VectorXd& p,
                            RigidTransform pose, const VerifyOptions& options) {
  ObservationBlock block;
  const Eigen::VectorXd no_errors;
  for (int it = 0; it < options.max_iterations; ++it) {
    builder.build(artifact, placement.measurements, p, pose, no_errors, true, block);
    const Eigen::MatrixXd M = block.A_r.transpose() * block.A_r;
    const Eigen::VectorXd step = -symmetricPseudoInverse(M) * (block.A_r.transpose() * block.e);
    pose = pose.perturbed(artifact.expandFullRigidStep(step));
    if (!(step.lpNorm<Eigen::Infinity>() > options.step_tolerance)) break;
  }
  return pose;
}

struct FeatureAccumulator {
  std::vector<int> readings;  ///< indices into the placement's measurements
};

/// Sum over readings of the predicted E|d_i|^2 (see the header).
double predictedSquaredDeviations(const std::vector<ReadingModel>& models,
                                  const std::vector<int>& readings,
                                  const std::optional<ParameterUncertainty>& uncertainty) {
  const auto n = static_cast<double>(readings.size());
  const int d = static_cast<int>(models[readings.front()].x.size());
  Eigen::MatrixXd J_mean = Eigen::MatrixXd::Zero(d, models[readings.front()].J.cols());
  double trace_sum = 0.0;
  for (int i : readings) {
    J_mean += models[i].J / n;
    trace_sum += models[i].Sigma.trace();
  }
  double total = 0.0;
  for (int i : readings) {
    double parameter_part = 0.0;
    if (uncertainty) {
      const Eigen::MatrixXd dJ = models[i].J - J_mean;
      parameter_part = (dJ * uncertainty->V * dJ.transpose()).trace();
    }
    total += parameter_part + models[i].Sigma.trace() * (1.0 - 2.0 / n) + trace_sum / (n * n);
  }
  return total;
}

/// Predicted standard uncertainty of a length error between two features (see the header).
double predictedLengthU(const std::vector<ReadingModel>& models, const std::vector<int>& a,
                        const std::vector<int>& b, const Eigen::VectorXd& direction,
                        const std::optional<ParameterUncertainty>& uncertainty,
                        double artifact_variance) {
  auto meanNoise = [&](const std::vector<int>& readings, Eigen::MatrixXd& J_mean) {
    const auto n = static_cast<double>(readings.size());
    Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(direction.size(), direction.size());
    J_mean.setZero(direction.size(), models[readings.front()].J.cols());
    for (int i : readings) {
      cov += models[i].Sigma / (n * n);
      J_mean += models[i].J / n;
    }
    return cov;
  };
  Eigen::MatrixXd J_a, J_b;
  Eigen::MatrixXd cov = meanNoise(a, J_a) + meanNoise(b, J_b);
  if (uncertainty) {
    const Eigen::MatrixXd dJ = J_b - J_a;
    cov += dJ * uncertainty->V * dJ.transpose();
  }
  return std::sqrt(direction.dot(cov * direction) + artifact_variance);
}

/// Variance of the calibrated distance between features a and b from the artifact's systematic
/// errors (each moves one coordinate of one feature; first order along the distance).
double artifactDistanceVariance(const Artifact& artifact, int a, int b) {
  const Eigen::VectorXd zero;
  const Eigen::VectorXd delta = artifact.feature(b, zero) - artifact.feature(a, zero);
  const Eigen::VectorXd unit = delta / delta.norm();
  double variance = 0.0;
  for (const SystematicError& e : artifact.systematic) {
    if (e.feature != a && e.feature != b) continue;
    const double sign = e.feature == b ? 1.0 : -1.0;
    const double along = sign * unit[e.coordinate];
    variance += along * along * e.sigma * e.sigma;
  }
  return variance;
}

// A feature's spread from its readings' deviations (`readings`: indices into `deviations`, mm)
// and the sum of their predicted squared deviations (mm^2).
void setSpread(FeatureSpread& spread, const Eigen::VectorXd& deviations,
               const std::vector<int>& readings, double predicted,
               const std::optional<ParameterUncertainty>& uncertainty) {
  spread.postures = static_cast<int>(readings.size());
  double sum = 0.0, sum2 = 0.0;
  for (const int i : readings) {
    sum += deviations[i];
    sum2 += deviations[i] * deviations[i];
  }
  spread.spread_mean = sum / spread.postures;
  spread.spread_rms = std::sqrt(sum2 / spread.postures);
  spread.predicted_spread_rms = std::sqrt(predicted / spread.postures);
  if (uncertainty)
    spread.predicted_spread_rms_posterior = spread.predicted_spread_rms * uncertainty->birge_ratio;
}

// The unmodelled error's share of a feature's predicted spread (see the header): each posture's
// deviation from the mean of n keeps (n - 1) / n of an independent error's variance d s_u^2.
double unmodelledSpreadShare(int dimension, int postures,
                             const std::optional<ParameterUncertainty>& uncertainty) {
  if (!uncertainty || postures < 1) return 0.0;
  const double n = postures;
  return uncertainty->unmodelled * std::sqrt(dimension * (n - 1.0) / n);
}

/// Sums of squares of flush touches' height and tilts, and their count.
struct FlushSums {
  int touches = 0;
  double height2 = 0.0, roll2 = 0.0, pitch2 = 0.0;

  void add(const FlushSums& other) {
    touches += other.touches;
    height2 += other.height2;
    roll2 += other.roll2;
    pitch2 += other.pitch2;
  }
  std::optional<FlushFigures> figures() const {
    if (touches == 0) return std::nullopt;
    const double n = touches;
    return FlushFigures{touches, std::sqrt(height2 / n), std::sqrt(roll2 / n),
                        std::sqrt(pitch2 / n)};
  }
};

FlushSums sumsOf(const FlushFigures& f) {
  const double n = f.touches;
  return {f.touches, n * f.height_rms * f.height_rms, n * f.roll_rms * f.roll_rms,
          n * f.pitch_rms * f.pitch_rms};
}

// The tool frame of a flush contact in the tip frame: the tip frame turned the least way so that
// its z is minus the tool axis (the tool axis points into the face; z points out of it, along
// the outward normal when flush). A tool axis of +z: the half turn about x.
Eigen::Matrix3d toolFrame(const Eigen::Vector3d& tool_axis) {
  const Eigen::Vector3d z = -tool_axis.normalized();
  if (z.z() < -1.0 + 1e-12)
    return Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), z).toRotationMatrix();
}

// A flush touch's tilts (rad), as roll and pitch of R_face^T R_tool (x-y-z fixed axes): the
// face's outward normal n seen in the tool frame R_tool (machine frame), roll = atan2(n_y, n_z),
// pitch = atan2(-n_x, |(n_y, n_z)|): the tool's tilt about its own x and y axes. A plane's
// normal and the tool axis are lines, as calibrate reads them (its tilt rows are the tool axis's
// components across the normal): written with the other sign, the normal seen along -z is the
// same flush contact, not one tilted by half a turn (issue 44: verify said 180 deg of roll).
void addFlushTouch(double height, const Eigen::Matrix3d& R_tool, const Eigen::Vector3d& n,
                   FlushSums& sums) {
  Eigen::Vector3d in_tool = R_tool.transpose() * n;
  if (in_tool.z() < 0.0) in_tool = -in_tool;
  const double roll = std::atan2(in_tool.y(), in_tool.z());
  const double pitch = std::atan2(-in_tool.x(), std::hypot(in_tool.y(), in_tool.z()));
  ++sums.touches;
  sums.height2 += height * height;
  sums.roll2 += roll * roll;
  sums.pitch2 += pitch * pitch;
}

// A flush touch's rows at placement r (planeRows, its scratch holding the tip frame) added to
// `sums`; nothing for a point contact. `tool`: toolFrame of the artifact's tool axis.
void addFlushRows(const Artifact& artifact, const Measurement& m, const RigidTransform& r,
                  const PlaneRows& rows, const PlaneRowsScratch& scratch,
                  const Eigen::Matrix3d& tool, FlushSums& sums) {
  if (!artifact.plane.flush) return;
  const PlaneFace& face = artifact.plane.faces[static_cast<std::size_t>(m.feature)];
  const Eigen::Vector3d normal = face.sign * r.R.row(face.axis).transpose();  // machine frame
  addFlushTouch(rows.residual[0], scratch.R_tip * tool, normal, sums);
}

// The touches of a plane placement scored at placement r (the calibration's): each touch's
// |distance| from its face, mm, and a flush contact's height and tilts.
Eigen::VectorXd touchDistances(const Plan& plan, const Placement& placement,
                               const Eigen::VectorXd& p, const RigidTransform& r,
                               FlushSums& flush) {
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  const auto count = static_cast<int>(placement.measurements.size());
  Eigen::VectorXd out(count);
  PlaneRows rows;
  PlaneRowsScratch scratch;
  const Eigen::Matrix3d tool = toolFrame(artifact.plane.tool_axis);
  for (int i = 0; i < count; ++i) {
    const Measurement& m = placement.measurements[static_cast<std::size_t>(i)];
    planeRows(artifact, plan.machine, p, m, r, Eigen::VectorXd(), false, rows, scratch);
    out[i] = std::abs(rows.residual[0]);
    addFlushRows(artifact, m, r, rows, scratch, tool, flush);
  }
  return out;
}

// A plane's touches (docs/planes.md): the placement fitted with p held, each touch's distance
// from its face is both its residual and its deviation. Predicted, for each touch's distance row
// d_i: E d_i^2 = [M C M^T]_ii over all of the touches' rows (a flush contact's two tilt rows too:
// the refit weighs them as calibrate does), C = blockdiag(Sigma_i) + J_p V J_p^T, Sigma_i each
// touch's own covariance (encoders, probe, flatness; the tilts' angle noise), and
// M = L (I - A_r A_r^+) L^-1, A_r = L^-1 J_r: the residual of the weighted refit of the
// placement (Sigma = L L^T), which leaves each row less than its variance where it fixes the
// placement (issue 44: an unweighted projection over the distance rows alone was 7 to 17 % low for
// flush contacts, whose tilts fix the plane's tilt).
struct TouchRows {
  Eigen::MatrixXd J_p, J_r;       ///< every row of every touch
  Eigen::MatrixXd L;              ///< blockdiag of each touch's Sigma_i = L_i L_i^T
  std::vector<int> distance_row;  ///< per touch, its distance row
};

Eigen::MatrixXd predictedTouchCovariance(const TouchRows& t,
                                         const std::optional<ParameterUncertainty>& uncertainty) {
  const auto L = t.L.triangularView<Eigen::Lower>();
  const Eigen::MatrixXd A_r = L.solve(t.J_r);
  const auto n = A_r.rows();
  Eigen::MatrixXd M =
      Eigen::MatrixXd::Identity(n, n) -
      A_r * Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(A_r).pseudoInverse();
  // M = L P L^-1: right-multiplying by L^-1 is solving from the right with L.
  M = L.transpose().solve(M.transpose()).transpose();
  M = t.L * M;
  Eigen::MatrixXd C = t.L * t.L.transpose();
  if (uncertainty && t.J_p.cols() > 0) C += t.J_p * uncertainty->V * t.J_p.transpose();
  return M * C * M.transpose();
}

PlacementVerification verifyTouches(const Plan& plan, int index, const Eigen::VectorXd& p,
                                    const RigidTransform& start, DesignMatrixBuilder& builder,
                                    const std::optional<ParameterUncertainty>& uncertainty,
                                    const VerifyOptions& options, double& predicted_sum) {
  const Placement& placement = plan.placements[static_cast<std::size_t>(index)];
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  PlacementVerification out;
  out.index = index;
  out.pose = fitRigidOnly(builder, artifact, placement, p, start, options);
  Machine machine = plan.machine;
  machine.calibrated = uncertainty ? uncertainty->indices : std::vector<int>{};
  const auto count = static_cast<int>(placement.measurements.size());
  out.residuals.resize(count);
  PlaneRows rows;
  PlaneRowsScratch scratch;
  const double point_variance = readingPointVariance(plan.noise.probe, artifact.noise);
  const double angle_variance = readingAngleVariance(plan.noise.probe, plan.noise.estimate_probe,
                                                     artifact.noise, artifact.noise_angle);
  Eigen::MatrixXd points(plan.machine.dimension(), count);
  const Eigen::Matrix3d tool = toolFrame(artifact.plane.tool_axis);
  FlushSums fitted;
  std::vector<PlaneRows> each(static_cast<std::size_t>(count));
  std::vector<Eigen::MatrixXd> sigmas(static_cast<std::size_t>(count));
  int total_rows = 0;
  for (int i = 0; i < count; ++i) {
    const Measurement& m = placement.measurements[static_cast<std::size_t>(i)];
    planeRows(artifact, machine, p, m, out.pose, Eigen::VectorXd(), true, rows, scratch);
    addFlushRows(artifact, m, out.pose, rows, scratch, tool, fitted);
    points.col(i) = scratch.x;
    out.residuals[i] = std::abs(rows.residual[0]);
    readingCovariance(plan.noise.encoder, rows.J_q, point_variance, 1, angle_variance,
                      sigmas[static_cast<std::size_t>(i)]);
    total_rows += rows.rows;
    each[static_cast<std::size_t>(i)] = rows;
  }
  out.deviations = out.residuals;
  TouchRows stacked{Eigen::MatrixXd::Zero(total_rows, machine.calibratedCount()),
                    Eigen::MatrixXd(total_rows, artifact.fullRigidDof()),
                    Eigen::MatrixXd::Zero(total_rows, total_rows),
                    {}};
  for (int i = 0, row = 0; i < count; ++i) {
    const PlaneRows& r = each[static_cast<std::size_t>(i)];
    if (stacked.J_p.cols() > 0) stacked.J_p.middleRows(row, r.rows) = r.J_p;  // none: nominal
    stacked.J_r.middleRows(row, r.rows) = r.J_r;
    stacked.L.block(row, row, r.rows, r.rows) =
        Eigen::LLT<Eigen::MatrixXd>(sigmas[static_cast<std::size_t>(i)]).matrixL();
    stacked.distance_row.push_back(row);
    row += r.rows;
  }
  const Eigen::MatrixXd all = predictedTouchCovariance(stacked, uncertainty);
  Eigen::VectorXd predicted(count);
  for (int i = 0; i < count; ++i) {
    const int row = stacked.distance_row[static_cast<std::size_t>(i)];
    predicted[i] = all(row, row);
  }
  predicted_sum += predicted.sum();
  // Per face: its touches' distances (the deviation of a touch is its distance from the face).
  std::map<int, std::vector<int>> faces;
  for (int i = 0; i < count; ++i)
    faces[placement.measurements[static_cast<std::size_t>(i)].feature].push_back(i);
  for (const auto& [feature, touches] : faces) {
    FeatureSpread spread;
    spread.feature = feature;
    spread.mean = Eigen::VectorXd::Zero(plan.machine.dimension());
    double expected = 0.0;
    for (const int i : touches) {
      spread.mean += points.col(i) / static_cast<double>(touches.size());
      expected += predicted[i];
    }
    setSpread(spread, out.residuals, touches, std::max(0.0, expected), uncertainty);
    out.features.push_back(std::move(spread));
  }
  out.residual_rms = count > 0 ? std::sqrt(out.residuals.squaredNorm() / count) : 0.0;
  out.residual_max = count > 0 ? out.residuals.maxCoeff() : 0.0;
  out.flush = fitted.figures();
  const auto j = static_cast<std::size_t>(index);
  if (j < options.calibration_frames.size() && options.calibration_frames[j]) {
    const CalibrationFrame& frame = *options.calibration_frames[j];
    InFrameResiduals in_frame;
    in_frame.frame_of = frame.placement;
    FlushSums sums;
    in_frame.residuals = touchDistances(plan, placement, p, frame.pose, sums);
    in_frame.flush = sums.figures();
    in_frame.residual_rms = count > 0 ? std::sqrt(in_frame.residuals.squaredNorm() / count) : 0.0;
    in_frame.residual_max = count > 0 ? in_frame.residuals.maxCoeff() : 0.0;
    out.in_frame = std::move(in_frame);
  }
  return out;
}

PlacementVerification verifyPlacement(const Plan& plan, int index, const Eigen::VectorXd& p,
                                      const RigidTransform& start, DesignMatrixBuilder& builder,
                                      const std::optional<ParameterUncertainty>& uncertainty,
                                      const VerifyOptions& options, double& predicted_sum) {
  const Placement& placement = plan.placements[static_cast<std::size_t>(index)];
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  if (artifact.kind().touches_faces)
    return verifyTouches(plan, index, p, start, builder, uncertainty, options, predicted_sum);
  const std::vector<int> no_indices;
  const std::vector<int>& indices = uncertainty ? uncertainty->indices : no_indices;
  PlacementVerification out;
  out.index = index;
  const auto count = static_cast<int>(placement.measurements.size());
  std::vector<ReadingModel> models;
  models.reserve(placement.measurements.size());
  std::map<int, FeatureAccumulator> features;
  for (int i = 0; i < count; ++i) {
    const Measurement& m = placement.measurements[static_cast<std::size_t>(i)];
    models.push_back(modelReading(plan, p, m, indices));
    features[m.feature].readings.push_back(i);
  }
  out.deviations.resize(count);
  for (const auto& [feature, acc] : features) {
    FeatureSpread spread;
    spread.feature = feature;
    spread.mean = Eigen::VectorXd::Zero(plan.machine.dimension());
    const auto postures = static_cast<double>(acc.readings.size());
    for (int i : acc.readings) spread.mean += models[i].x / postures;
    for (int i : acc.readings) out.deviations[i] = (models[i].x - spread.mean).norm();
    const double predicted = predictedSquaredDeviations(models, acc.readings, uncertainty);
    predicted_sum += predicted;
    setSpread(spread, out.deviations, acc.readings, predicted, uncertainty);
    spread.predicted_spread_rms_unmodelled =
        unmodelledSpreadShare(plan.machine.dimension(), spread.postures, uncertainty);
    out.features.push_back(std::move(spread));
  }
  for (std::size_t a = 0; a < out.features.size(); ++a) {
    for (std::size_t b = a + 1; b < out.features.size(); ++b) {
      const FeatureSpread& fa = out.features[a];
      const FeatureSpread& fb = out.features[b];
      const Eigen::VectorXd zero;
      const double calibrated =
          (artifact.feature(fb.feature, zero) - artifact.feature(fa.feature, zero)).norm();
      const Eigen::VectorXd between = fb.mean - fa.mean;
      LengthError length;
      length.from = fa.feature;
      length.to = fb.feature;
      length.error = between.norm() - calibrated;
      length.predicted_u =
          predictedLengthU(models, features[fa.feature].readings, features[fb.feature].readings,
                           between / between.norm(), uncertainty,
                           artifactDistanceVariance(artifact, fa.feature, fb.feature));
      length.predicted_u_posterior =
          length.predicted_u * (uncertainty ? uncertainty->birge_ratio : 0.0);
      out.length_errors.push_back(length);
    }
  }
  out.pose = fitRigidOnly(builder, artifact, placement, p, start, options);
  const int k = artifact.valuedPerFeature();
  out.residuals.resize(count);
  const Eigen::VectorXd zero;
  for (int i = 0; i < count; ++i) {
    const int feature = placement.measurements[static_cast<std::size_t>(i)].feature;
    out.residuals[i] =
        (out.pose.apply(models[i].x) - artifact.feature(feature, zero)).head(k).norm();
  }
  out.residual_rms = count > 0 ? std::sqrt(out.residuals.squaredNorm() / count) : 0.0;
  out.residual_max = count > 0 ? out.residuals.maxCoeff() : 0.0;
  const auto j = static_cast<std::size_t>(index);
  if (j < options.calibration_frames.size() && options.calibration_frames[j]) {
    const CalibrationFrame& frame = *options.calibration_frames[j];
    InFrameResiduals in_frame;
    in_frame.frame_of = frame.placement;
    in_frame.residuals.resize(count);
    for (int i = 0; i < count; ++i) {
      const int feature = placement.measurements[static_cast<std::size_t>(i)].feature;
      in_frame.residuals[i] =
          (frame.pose.apply(models[i].x) - artifact.feature(feature, zero)).head(k).norm();
    }
    in_frame.residual_rms = count > 0 ? std::sqrt(in_frame.residuals.squaredNorm() / count) : 0.0;
    in_frame.residual_max = count > 0 ? in_frame.residuals.maxCoeff() : 0.0;
    out.in_frame = std::move(in_frame);
  }
  return out;
}

}  // namespace

double predictedTotal(double base, double unmodelled) {
  return std::hypot(base, unmodelled);
}

namespace {

// The unmodelled shares and the totals (see the header), once the posterior predictions are
// final: per feature, and over every posture of every placement.
void addUnmodelledShares(Verification& out, int readings) {
  double unmodelled_sum = 0.0;
  for (PlacementVerification& placement : out.placements) {
    for (FeatureSpread& f : placement.features) {
      const double share = f.predicted_spread_rms_unmodelled;
      unmodelled_sum += share * share * f.postures;
      f.predicted_spread_rms_total = predictedTotal(
          basePrediction(f.predicted_spread_rms, f.predicted_spread_rms_posterior), share);
    }
  }
  if (readings == 0) return;
  out.predicted_spread_rms_unmodelled = std::sqrt(unmodelled_sum / readings);
  out.predicted_spread_rms_total =
      predictedTotal(basePrediction(out.predicted_spread_rms, out.predicted_spread_rms_posterior),
                     out.predicted_spread_rms_unmodelled);
}

}  // namespace

Noise withEstimatedProbeNoise(const Noise& noise,
                              const std::optional<ParameterUncertainty>& uncertainty) {
  Noise out = noise;
  if (noise.estimate_probe && uncertainty && uncertainty->probe_noise > 0.0)
    out.probe = uncertainty->probe_noise;
  return out;
}

Verification verifyMachine(const Plan& plan, const Eigen::VectorXd& p,
                           const std::optional<ParameterUncertainty>& uncertainty,
                           const VerifyOptions& options) {
  Verification out;
  out.predicted = uncertainty.has_value();
  out.unmodelled = uncertainty ? uncertainty->unmodelled : 0.0;
  DesignMatrixBuilder builder(plan.machine, plan.noise);
  const std::vector<RigidTransform> starts = fitPlacements(plan, plan.placements, p);
  double predicted_sum = 0.0, deviation_sum = 0.0, deviation_sum2 = 0.0, residual_sum2 = 0.0;
  double length_sum2 = 0.0, length_sum_abs = 0.0;
  double in_frame_sum2 = 0.0, reregistered_sum2 = 0.0;
  int readings = 0, lengths = 0, in_frame_readings = 0;
  FlushSums flush, flush_in_frame;
  for (int j = 0; j < static_cast<int>(plan.placements.size()); ++j) {
    out.placements.push_back(verifyPlacement(plan, j, p, starts[static_cast<std::size_t>(j)],
                                             builder, uncertainty, options, predicted_sum));
    const PlacementVerification& v = out.placements.back();
    readings += static_cast<int>(v.deviations.size());
    deviation_sum += v.deviations.sum();
    deviation_sum2 += v.deviations.squaredNorm();
    residual_sum2 += v.residuals.squaredNorm();
    if (v.flush) flush.add(sumsOf(*v.flush));
    if (v.in_frame && v.in_frame->flush) flush_in_frame.add(sumsOf(*v.in_frame->flush));
    if (v.in_frame) {
      ++out.in_frame_placements;
      in_frame_readings += static_cast<int>(v.residuals.size());
      in_frame_sum2 += v.in_frame->residuals.squaredNorm();
      reregistered_sum2 += v.residuals.squaredNorm();
    }
    for (const LengthError& e : v.length_errors) {
      length_sum2 += e.error * e.error;
      length_sum_abs += std::abs(e.error);
      ++lengths;
    }
  }
  if (readings > 0) {
    out.spread_rms = std::sqrt(deviation_sum2 / readings);
    out.spread_mean = deviation_sum / readings;
    out.predicted_spread_rms = std::sqrt(predicted_sum / readings);
    out.birge_ratio = uncertainty ? uncertainty->birge_ratio : 0.0;
    out.predicted_spread_rms_posterior = out.predicted_spread_rms * out.birge_ratio;
    out.residual_rms = std::sqrt(residual_sum2 / readings);
  }
  if (in_frame_readings > 0) {
    out.in_frame_residual_rms = std::sqrt(in_frame_sum2 / in_frame_readings);
    out.reregistered_residual_rms = std::sqrt(reregistered_sum2 / in_frame_readings);
  }
  out.flush = flush.figures();
  out.flush_in_frame = flush_in_frame.figures();
  if (lengths > 0) {
    out.length_error_rms = std::sqrt(length_sum2 / lengths);
    out.length_error_mean_abs = length_sum_abs / lengths;
  }
  // The calibration estimated its probe noise and this plan states another (see the header):
  // the posterior is the prediction at that estimate, for readings that scatter as it says.
  if (uncertainty && uncertainty->probe_noise > 0.0 && !plan.noise.estimate_probe &&
      uncertainty->birge_ratio > 0.0 && uncertainty->probe_noise != plan.noise.probe) {
    Plan scattered = plan;
    scattered.noise.probe = uncertainty->probe_noise;
    const Verification at_estimate = verifyMachine(scattered, p, uncertainty, options);
    const double s = uncertainty->birge_ratio;
    out.posterior_probe_noise = uncertainty->probe_noise;
    out.predicted_spread_rms_posterior = at_estimate.predicted_spread_rms * s;
    for (std::size_t j = 0; j < out.placements.size(); ++j) {
      std::vector<FeatureSpread>& features = out.placements[j].features;
      for (std::size_t f = 0; f < features.size(); ++f) {
        features[f].predicted_spread_rms_posterior =
            at_estimate.placements[j].features[f].predicted_spread_rms * s;
      }
      std::vector<LengthError>& lengths = out.placements[j].length_errors;
      for (std::size_t e = 0; e < lengths.size(); ++e)
        lengths[e].predicted_u_posterior =
            at_estimate.placements[j].length_errors[e].predicted_u * s;
    }
  }
  if (out.predicted) addUnmodelledShares(out, readings);
  return out;
}

std::optional<Verification> verifyNominal(const Plan& plan, const VerifyOptions& options) {
  try {
    return verifyMachine(plan, plan.machine.nominal, std::nullopt, options);
  } catch (const KinematicsError&) {
    return std::nullopt;  // no nominal figures to compare with; the calibrated ones stand alone
  }
}

double lengthErrorUncertainty(const Verification& v) {
  double sum2 = 0.0;
  int pairs = 0;
  for (const PlacementVerification& placement : v.placements) {
    for (const LengthError& e : placement.length_errors) {
      const double u = e.predicted_u_posterior > 0.0 ? e.predicted_u_posterior : e.predicted_u;
      sum2 += u * u;
      ++pairs;
    }
  }
  return pairs > 0 ? std::sqrt(sum2 / pairs) : 0.0;
}

std::vector<std::string> worseThanNominal(const Verification& calibrated,
                                          const Verification& nominal) {
  std::vector<std::string> worse;
  const auto printed = [](double mm) { return std::round(mm / kComparedFigureResolution); };
  for (const ComparedFigure& figure : kComparedFigures) {
    const double tolerance = figure.value == &Verification::length_error_mean_abs
                                 ? 2.0 * lengthErrorUncertainty(calibrated)
                                 : 0.0;
    const double c = calibrated.*figure.value, n = nominal.*figure.value;
    if (c - n > tolerance && printed(c) > printed(n)) worse.emplace_back(figure.name);
  }
  return worse;
}

}  // namespace artcal
