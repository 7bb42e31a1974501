#include "artcal/model/closed_chain.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>

#include "artcal/core/random.hpp"

namespace artcal {

namespace {

using PoseLU = Eigen::PartialPivLU<ConstraintPoseJacobian>;
using PoseStep = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;

// Scratch for the Jacobians in p and q: one per thread, so that a shared, immutable model
// allocates nothing per call once warm.
struct ForwardScratch {
  Eigen::MatrixXd H_s, H_p, G_p, G_q, M;
};

ForwardScratch& scratch() {
  thread_local ForwardScratch s;
  return s;
}

// G_s with its rotation columns turned into mm (times `rotation_scale`), factorised; false when
// its smallest pivot is below `singular_pivot` times its largest: no unique Newton step.
bool factorise(const ConstraintPoseJacobian& G_s, int pose_dimension, double rotation_scale,
               double singular_pivot, PoseLU& lu) {
  ConstraintPoseJacobian scaled = G_s;
  if (pose_dimension == 6) scaled.rightCols(3) /= rotation_scale;
  if (!scaled.allFinite()) return false;
  lu.compute(scaled);
  const auto pivots = lu.matrixLU().diagonal().cwiseAbs();
  return pivots.minCoeff() > singular_pivot * pivots.maxCoeff();
}

// The Newton step ds = -G_s^-1 g from the scaled factorisation.
PoseStep newtonStep(const PoseLU& lu, const ConstraintVector& g, int pose_dimension,
                    double rotation_scale) {
  PoseStep ds = -lu.solve(g);
  if (pose_dimension == 6) ds.tail(3) /= rotation_scale;
  return ds;
}

}  // namespace

Eigen::Matrix3d rotationFromRpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Matrix3d randomTilt(const Eigen::Matrix3d& home, double tilt, std::mt19937_64& rng) {
  Eigen::Vector3d direction;
  do {  // uniform in the unit ball by rejection, then projected on the sphere
    for (int i = 0; i < 3; ++i) direction[i] = 2.0 * unitUniform(rng) - 1.0;
  } while (direction.squaredNorm() > 1.0 || direction.squaredNorm() < 1e-6);
  const double angle = tilt * unitUniform(rng);
  return Eigen::AngleAxisd(angle, direction.normalized()).toRotationMatrix() * home;
}

void retractPose(ChainPose& pose, const Eigen::Ref<const Eigen::VectorXd>& ds) {
  const auto n = ds.size();
  pose.t.head(std::min<Eigen::Index>(n, 3)) += ds.head(std::min<Eigen::Index>(n, 3));
  if (n == 6) {
    const Eigen::Vector3d w = ds.tail<3>();
    const double angle = w.norm();
    if (angle > 0.0) pose.R = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix() * pose.R;
  }
}

ForwardStatus ClosedChainMechanism::solvePose(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                              ChainPose& pose) const {
  const int n = poseDimension();
  const double scale = rotationScale();
  pose = home(p);
  ConstraintVector g;
  ConstraintPoseJacobian G_s;
  PoseLU lu(n);
  for (int it = 0; it < options_.max_iterations; ++it) {
    constraints(pose, p, q, g, &G_s, nullptr, nullptr);
    const double residual = g.cwiseAbs().maxCoeff();
    if (!std::isfinite(residual)) return ForwardStatus::NotConverged;
    if (!factorise(G_s, n, scale, options_.singular_pivot, lu)) return ForwardStatus::Singular;
    retractPose(pose, newtonStep(lu, g, n, scale));
    // Converged: the step just taken is the polishing one (Newton's quadratic convergence takes
    // a residual of 1e-10 mm to rounding), so that finite differences of x see no solver noise.
    if (residual < options_.tolerance) return ForwardStatus::Ok;
  }
  return ForwardStatus::NotConverged;
}

ForwardStatus ClosedChainMechanism::forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                            Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p,
                                            Eigen::MatrixXd* J_x_q) const {
  ChainPose pose;
  const ForwardStatus status = solvePose(p, q, pose);
  if (status != ForwardStatus::Ok) return status;
  if (!J_x_p && !J_x_q) {
    tip(pose, p, x, nullptr, nullptr);
    return ForwardStatus::Ok;
  }
  ForwardScratch& s = scratch();
  tip(pose, p, x, &s.H_s, J_x_p ? &s.H_p : nullptr);
  ConstraintVector g;
  ConstraintPoseJacobian G_s;
  constraints(pose, p, q, g, &G_s, J_x_p ? &s.G_p : nullptr, J_x_q ? &s.G_q : nullptr);
  const int n = poseDimension();
  const double scale = rotationScale();
  PoseLU lu(n);
  if (!factorise(G_s, n, scale, options_.singular_pivot, lu)) return ForwardStatus::Singular;
  // Implicit function theorem: dx = H_s ds + H_p dp with G_s ds + G_p dp + G_q dq = 0, so
  // J_x_. = H_. - M G_.  with M = H_s G_s^-1 (G_s^-1 = D lu^-1, D the column scaling).
  ConstraintPoseJacobian inverse = lu.inverse();
  if (n == 6) inverse.bottomRows(3) /= scale;
  s.M.noalias() = s.H_s * inverse;
  if (J_x_p) {
    *J_x_p = s.H_p;
    J_x_p->noalias() -= s.M * s.G_p;
  }
  if (J_x_q) {
    J_x_q->resize(dimension(), jointCount());
    J_x_q->noalias() = -s.M * s.G_q;
  }
  return ForwardStatus::Ok;
}

}  // namespace artcal
