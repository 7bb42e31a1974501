#pragma once
// The noise of one reading's point, formed in one place (docs/method.md section 2;
// instruments.md): the encoders' noise through the joint Jacobian plus the noise every coordinate
// carries on its own (the probe's, an instrument's own in quadrature):
//   Sigma = J_q Sigma_q J_q^T + s^2 I,   Sigma_q = diag(sigma_q^2),   s^2 = s_p^2 + s_i^2.
// The design matrix whitens by it, calibrate's probe-noise estimate keeps its known part (s_p
// left out), verify predicts the readings' deviations with it.

#include <Eigen/Core>

namespace artcal {

/// s^2 = s_p^2 + s_i^2 (mm^2): the probe's noise and an instrument's own noise in quadrature.
inline double readingPointVariance(double probe_sigma, double instrument_sigma) {
  return probe_sigma * probe_sigma + instrument_sigma * instrument_sigma;
}

/// A pose instrument's orientation rows per unit of the probe's variance s_p^2 (rad^2 / mm^2).
/// With the probe noise estimated (`"probe": "estimate"`), the robot's own scatter is one common
/// variance factor on the instrument's rows (docs/method.md section 6, instruments.md):
///   Sigma = (1 + s_p^2 / s_i^2) diag(s_i^2 I, s_a^2 I) + J_q Sigma_q J_q^T,
/// so that the point's rows carry s_i^2 + s_p^2 as for a point instrument and the orientation's
/// s_a^2 + s_p^2 s_a^2 / s_i^2. With the probe noise stated (or no noise of the instrument's own
/// to scale), the orientation rows carry s_a^2 alone: 0.
inline double angleVariancePerProbeVariance(bool probe_estimated, double instrument_sigma,
                                            double angle_sigma) {
  if (!probe_estimated || !(instrument_sigma > 0.0)) return 0.0;
  return angle_sigma * angle_sigma / (instrument_sigma * instrument_sigma);
}

/// A pose reading's orientation variance (rad^2 per rotation-vector coordinate): s_a^2, plus the
/// probe's share when it is estimated (angleVariancePerProbeVariance).
inline double readingAngleVariance(double probe_sigma, bool probe_estimated,
                                   double instrument_sigma, double angle_sigma) {
  return angle_sigma * angle_sigma +
         probe_sigma * probe_sigma *
             angleVariancePerProbeVariance(probe_estimated, instrument_sigma, angle_sigma);
}

/// Sigma = J_q diag(encoder_sigma^2) J_q^T + point_variance I into `sigma`. J_q: the point's
/// joint Jacobian as the reading sees it (rows rotated into the artifact frame, valued rows
/// only); `encoder_sigma` (internal units) one per joint.
template <typename JacobianQ, typename Covariance>
void readingCovariance(const Eigen::VectorXd& encoder_sigma,
                       const Eigen::MatrixBase<JacobianQ>& J_q, double point_variance,
                       Covariance& sigma) {
  const auto sigma_q2 = encoder_sigma.array().square().matrix().asDiagonal();
  sigma = (J_q * sigma_q2).lazyProduct(J_q.transpose());
  sigma.diagonal().array() += point_variance;
}

/// The same for a pose reading (instruments.md, "measures": "pose"): J_q has the position's
/// `position_rows` rows, then the orientation's; the orientation rows carry `angle_variance`
/// (rad^2: readingAngleVariance) instead of the point's.
template <typename JacobianQ, typename Covariance>
void readingCovariance(const Eigen::VectorXd& encoder_sigma,
                       const Eigen::MatrixBase<JacobianQ>& J_q, double point_variance,
                       int position_rows, double angle_variance, Covariance& sigma) {
  const auto sigma_q2 = encoder_sigma.array().square().matrix().asDiagonal();
  sigma = (J_q * sigma_q2).lazyProduct(J_q.transpose());
  sigma.diagonal().head(position_rows).array() += point_variance;
  sigma.diagonal().tail(sigma.rows() - position_rows).array() += angle_variance;
}

}  // namespace artcal
