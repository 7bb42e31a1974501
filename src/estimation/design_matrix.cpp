#include "artcal/estimation/design_matrix.hpp"

#include <Eigen/Cholesky>
#include <set>

namespace artcal {

DesignMatrixBuilder::DesignMatrixBuilder(const Machine& machine, const Noise& noise)
    : machine_(&machine), noise_(&noise) {}

Eigen::MatrixXd DesignMatrixBuilder::probePositions(const std::vector<Measurement>& measurements,
                                                    const Eigen::VectorXd& p) const {
  const int d = machine_->dimension();
  Eigen::MatrixXd points(d, static_cast<int>(measurements.size()));
  Eigen::VectorXd x(d);
  for (std::size_t i = 0; i < measurements.size(); ++i) {
    forwardOrThrow(*machine_->mechanism, p, measurements[i].joints, x, nullptr, nullptr,
                   measurements[i].stylus);
    points.col(static_cast<int>(i)) = x;
  }
  return points;
}

namespace {

// At most 3 valued coordinates per point: the small matrices live on the stack.
using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 3, 3>;

// rows <- L^-1 rows for a lower-triangular L of order 1 to 3 (forward substitution).
template <typename Rows>
void whiten(const Small& L, Rows&& rows) {
  const int k = static_cast<int>(L.rows());
  if (rows.cols() == 0) return;  // no parameter (or no systematic error) to whiten
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < i; ++j) rows.row(i) -= L(i, j) * rows.row(j);
    rows.row(i) /= L(i, i);
  }
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
  const int rows = k * static_cast<int>(measurements.size());
  const int n_p = machine.calibratedCount();
  const int n_r = artifact.fullRigidDof();  // rank policy: the full rigid block
  const int n_c = artifact.systematicCount();
  block.A_p.resize(rows, n_p);
  block.A_r.resize(rows, n_r);
  block.rigid_primary = artifact.rigidDof();
  block.A_c.setZero(rows, n_c);
  if (with_residuals) block.e.resize(rows);
  // An instrument's own noise adds in quadrature to the probe's (instruments.md).
  const double sigma_p2 = noise_->probe * noise_->probe + artifact.noise * artifact.noise;
  const auto sigma_q2 = noise_->encoder.array().square().matrix().asDiagonal();
  J_r_.resize(k, n_r);
  for (std::size_t i = 0; i < measurements.size(); ++i) {
    const Measurement& m = measurements[i];
    const int row = k * static_cast<int>(i);
    forwardOrThrow(*machine.mechanism, p, m.joints, x_, &J_x_p_, &J_x_q_, m.stylus);
    W_.noalias() = r.R * x_;
    W_ += r.t;
    // dF/dp and dF/dq: the valued rows of R J (the rigid motion does not depend on p or q).
    const auto R_valued = r.R.topRows(k);
    auto A_p = block.A_p.middleRows(row, k);
    auto A_r = block.A_r.middleRows(row, k);
    for (int j = 0; j < n_p; ++j) {
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
      L = held->factors[i].topLeftCorner(k, k);
      if (own) ownFactor(r.R, k, sigma_p2, own, measurements.size(), i);
    } else {
      J_valued_q_.noalias() = R_valued.lazyProduct(J_x_q_);
      Small sigma = (J_valued_q_ * sigma_q2).lazyProduct(J_valued_q_.transpose());
      sigma.diagonal().array() += sigma_p2;
      L = Eigen::LLT<Small>(sigma).matrixL();
    }
    if (record) {
      record->factors.resize(measurements.size());
      record->factors[i].setZero();
      record->factors[i].topLeftCorner(k, k) = L;
    }
    whiten(L, A_p);
    whiten(L, A_r);
    if (n_c > 0) whiten(L, block.A_c.middleRows(row, k));
    if (with_residuals) whiten(L, block.e.segment(row, k));
  }
}

void DesignMatrixBuilder::ownFactor(const Eigen::MatrixXd& R, int k, double sigma_p2,
                                    ReadingWeights* own, std::size_t readings,
                                    std::size_t i) const {
  // Sigma at p (as build() whitens a fresh block), from J_x_q_ of the last forward call:
  // C = J_q diag(sigma_q^2) J_q^T in the machine frame (zero-padded to 3 x 3), then its valued
  // rows in the artifact's.
  const int d = static_cast<int>(J_x_q_.rows());
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (int q = 0; q < J_x_q_.cols(); ++q) {
    const double s2 = noise_->encoder[q] * noise_->encoder[q];
    Eigen::Vector3d column = Eigen::Vector3d::Zero();
    for (int a = 0; a < d; ++a) column[a] = J_x_q_(a, q);
    C.noalias() += s2 * column * column.transpose();
  }
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Zero();
  rotation.topLeftCorner(d, d) = R;
  Eigen::Matrix3d sigma = rotation * C * rotation.transpose();
  sigma.diagonal().array() += sigma_p2;
  own->factors.resize(readings);
  own->factors[i].setZero();
  if (k == 3) {
    own->factors[i] = Eigen::LLT<Eigen::Matrix3d>(sigma).matrixL();
  } else {
    own->factors[i].topLeftCorner(k, k) =
        Eigen::LLT<Small>(Small(sigma.topLeftCorner(k, k))).matrixL();
  }
}

void DesignMatrixBuilder::misfits(const Artifact& artifact,
                                  const std::vector<Measurement>& measurements,
                                  const Eigen::VectorXd& p, const RigidTransform& r,
                                  const Eigen::VectorXd& c, std::vector<ReadingMisfit>& out) const {
  const int k = artifact.valuedPerFeature();
  const auto sigma_q2 = noise_->encoder.array().square().matrix().asDiagonal();
  Eigen::VectorXd x;
  Eigen::MatrixXd J_x_q;
  for (const Measurement& m : measurements) {
    forwardOrThrow(*machine_->mechanism, p, m.joints, x, nullptr, &J_x_q, m.stylus);
    const Eigen::MatrixXd J_valued_q = r.R.topRows(k) * J_x_q;
    ReadingMisfit misfit;
    misfit.residual = (r.apply(x) - readingTarget(artifact, m, c)).head(k);
    misfit.encoder_covariance = J_valued_q * sigma_q2 * J_valued_q.transpose();
    // An instrument's stated noise is known: it joins the part the probe-noise estimate keeps.
    misfit.encoder_covariance.diagonal().array() += artifact.noise * artifact.noise;
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
    if (distinct.size() < 2 && placement.pose) {
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
