#include "artcal/estimation/design_matrix.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <set>
#include <stdexcept>

#include "artcal/model/rotation_vector.hpp"

#include "artcal/estimation/plane_rows.hpp"
#include "artcal/estimation/reading_noise.hpp"
#include "artcal/estimation/reading_rows.hpp"

namespace artcal {

DesignMatrixBuilder::DesignMatrixBuilder(const Machine& machine, const Noise& noise)
    : machine_(&machine), noise_(noise) {}

Eigen::MatrixXd DesignMatrixBuilder::probePositions(const std::vector<Measurement>& measurements,
                                                    const Eigen::VectorXd& p) const {
  const int d = machine_->dimension();
  Eigen::MatrixXd points(d, static_cast<int>(measurements.size()));
  Eigen::VectorXd x(d);
  for (std::size_t i = 0; i < measurements.size(); ++i) {
    forwardReadingOrThrow(*machine_, p, measurements[i], x);
    points.col(static_cast<int>(i)) = x;
  }
  return points;
}

namespace {

// At most 6 rows per reading (3 valued coordinates, and a pose's 3 orientation coordinates): the
// small matrices live on the stack.
using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, 6>;

// Rows row..row + k of a column-major matrix <- L^-1 those rows, for a lower-triangular L of
// order k (1 to 6; K: k known at compile time, or Eigen::Dynamic): forward substitution, column by
// column, each column's k entries contiguous. The same operations in the same order as row by row.
template <int K>
void whitenRows(const Small& L, int k, double* first, Eigen::Index stride, Eigen::Index cols) {
  const int n = K == Eigen::Dynamic ? k : K;
  for (Eigen::Index c = 0; c < cols; ++c) {
    double* x = first + c * stride;
    for (int i = 0; i < n; ++i) {
      double v = x[i];
      for (int j = 0; j < i; ++j) v -= L(i, j) * x[j];
      x[i] = v / L(i, i);
    }
  }
}

// One reading's rows (`row`, L's order) of every part of the block whitened.
void whitenReading(const Small& L, int row, bool with_residuals, ObservationBlock& block) {
  const int k = static_cast<int>(L.rows());
  withReadingRows(k, [&]<int K>() {
    forEachPartAtRow(block, row, with_residuals,
                     [&](double* first, Eigen::Index stride, Eigen::Index cols) {
                       whitenRows<K>(L, k, first, stride, cols);
                     });
  });
}

}  // namespace

void DesignMatrixBuilder::build(const Artifact& artifact,
                                const std::vector<Measurement>& measurements,
                                const Eigen::VectorXd& p, const RigidTransform& r,
                                const Eigen::VectorXd& c, bool with_residuals,
                                ObservationBlock& block, const ReadingWeights* held,
                                ReadingWeights* record, ReadingWeights* own) {
  const Machine& machine = *machine_;
  const int k = artifact.valuedPerFeature();
  const int per = artifact.rowsPerReading();  // k, and a pose's 3 orientation rows
  const int rows = per * static_cast<int>(measurements.size());
  const int n_p = machine.calibratedCount();
  const int n_r = artifact.fullRigidDof();  // rank policy: the full rigid block
  const int n_c = artifact.systematicCount();
  block.A_p.resize(rows, n_p);
  block.A_r.resize(rows, n_r);
  block.rigid_primary = artifact.rigidDof();
  block.A_c.setZero(rows, n_c);
  if (with_residuals) block.e.resize(rows);
  // An instrument's own noise adds in quadrature to the probe's (instruments.md).
  const double sigma_p2 = readingPointVariance(noise_.probe, artifact.noise);
  const double sigma_angle2 = readingAngleVariance(noise_.probe, noise_.estimate_probe,
                                                   artifact.noise, artifact.noise_angle);
  J_r_.resize(k, n_r);
  for (std::size_t i = 0; i < measurements.size(); ++i) {
    const Measurement& m = measurements[i];
    const int row = per * static_cast<int>(i);
    if (artifact.kind().touches_faces) {
      const Small own_L = planeReading(artifact, m, p, r, c, row, with_residuals, block);
      const Small L = held ? Small(held->factors[i].topLeftCorner(per, per)) : own_L;
      if (held && own) storeFactor(*own, measurements.size(), i, own_L);
      if (record) storeFactor(*record, measurements.size(), i, L);
      whitenReading(L, row, with_residuals, block);
      continue;
    }
    if (artifact.measures_pose) {
      forwardReadingPoseOrThrow(machine, p, m, x_, R_tip_, &J_x_p_, &J_x_q_, &J_w_p_, &J_w_q_);
      orientationRows(artifact, m, r, row + k, with_residuals, block);
    } else {
      forwardReadingOrThrow(machine, p, m, x_, &J_x_p_, &J_x_q_);
    }
    W_.noalias() = r.R * x_;
    W_ += r.t;
    // dF/dp and dF/dq: the valued rows of R J (the rigid motion does not depend on p or q).
    const auto R_valued = r.R.topRows(k);
    auto A_p = block.A_p.middleRows(row, k);
    auto A_r = block.A_r.middleRows(row, k);
    if (k == 3 && r.R.cols() == 3) {  // a 3-D point: fixed-size products, no dispatch per column
      const Eigen::Matrix3d R3 = r.R;
      for (int j = 0; j < n_p; ++j) {
        block.A_p.block<3, 1>(row, j).noalias() =
            R3 * J_x_p_.block<3, 1>(0, machine.calibrated[static_cast<std::size_t>(j)]);
      }
    } else {
      for (int j = 0; j < n_p; ++j)
        A_p.col(j).noalias() = R_valued.lazyProduct(J_x_p_.col(machine.calibrated[j]));
    }
    artifact.fullRigidJacobian(W_, J_r_);
    A_r = J_r_;
    for (int s = 0; s < n_c; ++s) {
      const SystematicError& err = artifact.systematic[static_cast<std::size_t>(s)];
      if (err.feature == m.feature && err.coordinate < k) block.A_c(row + err.coordinate, s) = -1.0;
    }
    if (with_residuals) {
      block.e.segment(row, k) = W_.head(k) - readingTarget(artifact, m, c).head(k);
    }
    // Whitening (docs/method.md section 2): Sigma = s_p^2 I + J_q Sigma_q J_q^T = L L^T,
    // rows *= L^-1.
    Small L;
    if (held) {
      L = held->factors[i].topLeftCorner(per, per);
      // The factor at this block's own state, for the convergence test's reweighting.
      if (own)
        storeFactor(*own, measurements.size(), i,
                    readingFactor(R_valued, per, k, sigma_p2, sigma_angle2, artifact));
    } else {
      L = readingFactor(R_valued, per, k, sigma_p2, sigma_angle2, artifact);
    }
    if (record) storeFactor(*record, measurements.size(), i, L);
    whitenReading(L, row, with_residuals, block);
  }
}

// A plane reading's rows at `row` (unwhitened, plane_rows.hpp) and the factor of their covariance:
// Sigma = J_q Sigma_q J_q^T + diag(s_p^2 + flatness^2, tilt variance, tilt variance).
DesignMatrixBuilder::Small DesignMatrixBuilder::planeReading(
    const Artifact& artifact, const Measurement& m, const Eigen::VectorXd& p,
    const RigidTransform& r, const Eigen::VectorXd& c, int row, bool with_residuals,
    ObservationBlock& block) {
  planeRows(artifact, *machine_, p, m, r, c, true, plane_rows_, plane_scratch_);
  const int n = plane_rows_.rows;
  block.A_p.middleRows(row, n) = plane_rows_.J_p;
  block.A_r.middleRows(row, n) = plane_rows_.J_r;
  for (int s = 0; s < artifact.systematicCount(); ++s) {
    const SystematicError& err = artifact.systematic[static_cast<std::size_t>(s)];
    if (err.feature == m.feature) block.A_c(row, s) = -1.0;
  }
  if (with_residuals) block.e.segment(row, n) = plane_rows_.residual;
  Small sigma;
  readingCovariance(noise_.encoder, plane_rows_.J_q,
                    readingPointVariance(noise_.probe, artifact.noise), 1,
                    readingAngleVariance(noise_.probe, noise_.estimate_probe, artifact.noise,
                                         artifact.noise_angle),
                    sigma);
  return Eigen::LLT<Small>(sigma).matrixL();
}

// A pose reading's orientation rows at `row` (unwhitened): the residual of the predicted
// orientation in the station's frame, R_r R(p, q), against the measured one, and its exact
// derivatives (header); leaves J_l^-1(e) R_r in orientation_factor_ for the encoders' part.
void DesignMatrixBuilder::orientationRows(const Artifact& artifact, const Measurement& m,
                                          const RigidTransform& r, int row, bool with_residuals,
                                          ObservationBlock& block) {
  if (m.orientation.size() != 3)
    throw std::logic_error("a pose instrument's reading without its orientation");
  Eigen::Matrix3d J_e_w;
  const Eigen::Matrix3d R_station = r.R;
  const Eigen::Vector3d e = orientationResidual(R_station * R_tip_, m.orientation, &J_e_w);
  orientation_factor_.noalias() = J_e_w * R_station;
  const std::vector<int>& calibrated = machine_->calibrated;
  auto A_p = block.A_p.middleRows(row, 3);
  for (std::size_t j = 0; j < calibrated.size(); ++j)
    A_p.col(static_cast<int>(j)).noalias() = orientation_factor_ * J_w_p_.col(calibrated[j]);
  // A station step exp(delta) turns the prediction by delta's rotation and not by its translation.
  const std::vector<int>& order = artifact.fullRigidOrder();
  auto A_r = block.A_r.middleRows(row, 3);
  for (std::size_t c = 0; c < order.size(); ++c) {
    const int direction = order[c];
    if (direction < 3)
      A_r.col(static_cast<int>(c)).setZero();
    else
      A_r.col(static_cast<int>(c)) = J_e_w.col(direction - 3);
  }
  if (with_residuals) block.e.segment<3>(row) = e;
}

// The Cholesky factor L of one reading's covariance at the last forward call (docs/method.md
// section 2): Sigma = J_q Sigma_q J_q^T + s^2 I over the point's rows, plus s_angle^2 I over a
// pose's orientation rows (whose J_q is J_l^-1(e) R_r J_w_q, left by orientationRows).
DesignMatrixBuilder::Small DesignMatrixBuilder::readingFactor(
    const Eigen::Ref<const Eigen::MatrixXd>& R_valued, int per, int k, double sigma_p2,
    double sigma_angle2, const Artifact& artifact) {
  if (!artifact.measures_pose) return pointFactor(R_valued, k, sigma_p2);
  J_valued_q_.resize(per, J_x_q_.cols());
  J_valued_q_.topRows(k).noalias() = R_valued.lazyProduct(J_x_q_);
  J_valued_q_.bottomRows(3).noalias() = orientation_factor_ * J_w_q_;
  Small sigma;
  readingCovariance(noise_.encoder, J_valued_q_, sigma_p2, k, sigma_angle2, sigma);
  return Eigen::LLT<Small>(sigma).matrixL();
}

// A point's factor (k rows) by loops over at most 3 x 3: the numbers readingCovariance and
// Eigen's products give (each sum in the same order, the lower triangle that LLT reads).
DesignMatrixBuilder::Small DesignMatrixBuilder::pointFactor(
    const Eigen::Ref<const Eigen::MatrixXd>& R_valued, int k, double sigma_p2) {
  const int d = static_cast<int>(J_x_q_.rows());
  const int n_q = static_cast<int>(J_x_q_.cols());
  const Eigen::VectorXd& encoder = noise_.encoder;
  // J_valued_q = R_valued J_x_q, then (J_valued_q Sigma_q) J_valued_q^T.
  J_valued_q_.resize(k, n_q);
  for (int l = 0; l < n_q; ++l) {
    for (int a = 0; a < k; ++a) {
      double sum = R_valued(a, 0) * J_x_q_(0, l);
      for (int m = 1; m < d; ++m) sum += R_valued(a, m) * J_x_q_(m, l);
      J_valued_q_(a, l) = sum;
    }
  }
  Small sigma(k, k);
  for (int b = 0; b < k; ++b) {
    for (int a = b; a < k; ++a) {
      double sum = 0.0;
      for (int l = 0; l < n_q; ++l) {
        const double term = (J_valued_q_(a, l) * (encoder[l] * encoder[l])) * J_valued_q_(b, l);
        sum = l == 0 ? term : sum + term;
      }
      sigma(a, b) = sum;
      sigma(b, a) = sum;
    }
    sigma(b, b) += sigma_p2;
  }
  return Eigen::LLT<Small>(sigma).matrixL();
}

void DesignMatrixBuilder::storeFactor(ReadingWeights& weights, std::size_t readings, std::size_t i,
                                      const Small& L) {
  weights.factors.resize(readings);
  weights.factors[i].setZero();
  weights.factors[i].topLeftCorner(L.rows(), L.cols()) = L;
}

void DesignMatrixBuilder::misfits(const Artifact& artifact,
                                  const std::vector<Measurement>& measurements,
                                  const Eigen::VectorXd& p, const RigidTransform& r,
                                  const Eigen::VectorXd& c, std::vector<ReadingMisfit>& out,
                                  std::vector<Eigen::MatrixXd>* joint_jacobians) const {
  const int k = artifact.valuedPerFeature();
  // A pose's orientation rows enter when they carry a share of s_p^2 (reading_noise.hpp), scaled
  // by 1/sqrt(share) so that s_p^2 adds to every row alike (Calibrator::misfits).
  const double angle_share =
      angleVariancePerProbeVariance(noise_.estimate_probe, artifact.noise, artifact.noise_angle);
  const bool pose_rows = artifact.measures_pose && angle_share > 0.0;
  Eigen::VectorXd x;
  Eigen::Matrix3d R;
  Eigen::MatrixXd J_x_q, J_w_q;
  const bool tilt_rows = artifact.plane.flush && angle_share > 0.0;
  PlaneRows plane_rows;
  PlaneRowsScratch plane_scratch;
  for (const Measurement& m : measurements) {
    if (artifact.kind().touches_faces) {
      // As a pose's: the distance row, and a flush contact's tilt rows when they carry a share.
      planeRows(artifact, *machine_, p, m, r, c, true, plane_rows, plane_scratch);
      const int kept = tilt_rows ? plane_rows.rows : 1;
      ReadingMisfit misfit;
      readingCovariance(noise_.encoder, plane_rows.J_q.topRows(kept),
                        readingPointVariance(0.0, artifact.noise), 1,
                        artifact.noise_angle * artifact.noise_angle, misfit.encoder_covariance);
      misfit.residual = plane_rows.residual.head(kept);
      if (kept > 1) {
        const double unscale = 1.0 / std::sqrt(angle_share);
        misfit.residual.tail(kept - 1) *= unscale;
        misfit.encoder_covariance.bottomRows(kept - 1) *= unscale;
        misfit.encoder_covariance.rightCols(kept - 1) *= unscale;
      }
      if (joint_jacobians) {
        Eigen::MatrixXd J_q = plane_rows.J_q.topRows(kept);
        if (kept > 1) J_q.bottomRows(kept - 1) /= std::sqrt(angle_share);
        joint_jacobians->push_back(std::move(J_q));
      }
      out.push_back(std::move(misfit));
      continue;
    }
    if (pose_rows)
      forwardReadingPoseOrThrow(*machine_, p, m, x, R, nullptr, &J_x_q, nullptr, &J_w_q);
    else
      forwardReadingOrThrow(*machine_, p, m, x, nullptr, &J_x_q);
    const Eigen::MatrixXd J_valued_q = r.R.topRows(k) * J_x_q;
    ReadingMisfit misfit;
    const Eigen::VectorXd point_residual = (r.apply(x) - readingTarget(artifact, m, c)).head(k);
    // An instrument's stated noise is known: it joins the part the probe-noise estimate keeps.
    if (!pose_rows) {
      misfit.residual = point_residual;
      readingCovariance(noise_.encoder, J_valued_q, readingPointVariance(0.0, artifact.noise),
                        misfit.encoder_covariance);
      if (joint_jacobians) joint_jacobians->push_back(J_valued_q);
      out.push_back(std::move(misfit));
      continue;
    }
    Eigen::Matrix3d J_e_w;
    const Eigen::Vector3d e = orientationResidual(Eigen::Matrix3d(r.R * R), m.orientation, &J_e_w);
    Eigen::MatrixXd J_q(k + 3, J_x_q.cols());
    J_q.topRows(k) = J_valued_q;
    J_q.bottomRows(3) = J_e_w * r.R * J_w_q;
    readingCovariance(noise_.encoder, J_q, readingPointVariance(0.0, artifact.noise), k,
                      artifact.noise_angle * artifact.noise_angle, misfit.encoder_covariance);
    const double unscale = 1.0 / std::sqrt(angle_share);
    misfit.residual.resize(k + 3);
    misfit.residual << point_residual, unscale * e;
    misfit.encoder_covariance.bottomRows(3) *= unscale;
    misfit.encoder_covariance.rightCols(3) *= unscale;
    if (joint_jacobians) {
      J_q.bottomRows(3) *= unscale;
      joint_jacobians->push_back(std::move(J_q));
    }
    out.push_back(std::move(misfit));
  }
}

std::vector<RigidTransform> fitPlacements(const Plan& plan,
                                          const std::vector<Placement>& placements,
                                          const Eigen::VectorXd& p) {
  DesignMatrixBuilder builder(plan.machine, plan.noise);
  std::vector<RigidTransform> poses;
  poses.reserve(placements.size());
  for (const Placement& placement : placements) {
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    std::set<int> distinct;
    for (const Measurement& m : placement.measurements) distinct.insert(m.feature);
    if (artifact.translatesOnly() && !artifact.kind().touches_faces &&
        !placement.measurements.empty()) {
      // A sphere: the mean offset of the probed centres from its centre, no rotation.
      const Eigen::MatrixXd machine_points = builder.probePositions(placement.measurements, p);
      RigidTransform shift = RigidTransform::identity(artifact.dimension);
      shift.t = -machine_points.rowwise().mean();
      for (const Measurement& m : placement.measurements)
        shift.t += readingTarget(artifact, m, Eigen::VectorXd()) /
                   static_cast<double>(placement.measurements.size());
      poses.push_back(shift);
      continue;
    }
    // A plane's touches lie anywhere on its faces: its placement starts from the plan's pose.
    if ((distinct.size() < 2 || artifact.kind().touches_faces) && placement.pose) {
      poses.push_back(poseTransform(plan.machine.dimension(), *placement.pose));
      continue;
    }
    const Eigen::MatrixXd machine_points = builder.probePositions(placement.measurements, p);
    Eigen::MatrixXd artifact_points(artifact.dimension, machine_points.cols());
    for (std::size_t i = 0; i < placement.measurements.size(); ++i) {
      artifact_points.col(static_cast<int>(i)) =
          readingTarget(artifact, placement.measurements[i], Eigen::VectorXd());
    }
    poses.push_back(fitRigid(machine_points, artifact_points));
  }
  return poses;
}

}  // namespace artcal
