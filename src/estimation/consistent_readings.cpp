#include "artcal/estimation/consistent_readings.hpp"

#include "artcal/core/dense_decompositions.hpp"
#include <exception>
#include <set>

#include "artcal/estimation/design_matrix.hpp"

namespace artcal {

namespace {

constexpr int kMaxSteps = 6;           // Gauss-Newton steps per reading (quadratic: 2-3 suffice)
constexpr double kConsistent = 1e-12;  // mm (rad): a residual this small is rounding
constexpr double kDamping = 1e-12;     // of trace(J_q J_q^T), where that matrix is singular

// Whether the placement's pose is fitted to its readings' points (fitPlacements): not a plane's
// (its touches lie anywhere on its faces; its pose is the plan's or the touches' start) nor a
// lone feature's whose pose the plan states.
bool poseFittedToReadings(const Artifact& artifact, const Placement& placement) {
  if (artifact.kind().touches_faces) return false;
  if (artifact.translatesOnly()) return true;
  std::set<int> distinct;
  for (const Measurement& m : placement.measurements) distinct.insert(m.feature);
  return !(distinct.size() < 2 && placement.pose);
}

// One reading moved to consistency at (p, pose): the minimum-norm Gauss-Newton steps in q;
// whether it moved (its misfit above kAlreadyConsistent). A reading whose steps do not lower its
// misfit (far from consistency, or whose forward kinematics fails on the way: a hexapod's
// numerical one) stays as it is: the verdict is then that of the reading as measured.
bool makeConsistent(const DesignMatrixBuilder& builder, const Artifact& artifact,
                    const Eigen::VectorXd& p, const RigidTransform& pose, const Eigen::VectorXd& c,
                    Measurement& reading) {
  std::vector<Measurement> one{reading};
  std::vector<ReadingMisfit> misfit;
  std::vector<Eigen::MatrixXd> jacobian;
  double first = 0.0, last = 0.0;
  try {
    for (int step = 0; step < kMaxSteps; ++step) {
      misfit.clear();
      jacobian.clear();
      builder.misfits(artifact, one, p, pose, c, misfit, &jacobian);
      const Eigen::VectorXd e = misfit.front().residual;
      if (!e.allFinite()) return false;
      last = e.lpNorm<Eigen::Infinity>();
      if (step == 0) first = last;
      if (step == 0 && last <= kAlreadyConsistent) return false;
      if (last <= kConsistent) break;
      const Eigen::MatrixXd& J = jacobian.front();
      Eigen::MatrixXd JJt = J * J.transpose();
      JJt.diagonal().array() += kDamping * JJt.trace() + 1e-300;
      const Eigen::VectorXd dq = -J.transpose() * JJt.ldlt().solve(e);
      if (!dq.allFinite()) return false;
      one.front().joints += dq;
    }
  } catch (const std::exception&) {
    return false;
  }
  if (!(last < first)) return false;
  reading.joints = one.front().joints;
  return true;
}

}  // namespace

std::optional<std::vector<Placement>> consistentPlacements(const Plan& plan,
                                                           const std::vector<Placement>& placements,
                                                           const Eigen::VectorXd& p) {
  const std::vector<RigidTransform> poses = fitPlacements(plan, placements, p);
  const DesignMatrixBuilder builder(plan.machine, plan.noise);
  std::optional<std::vector<Placement>> out;
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placements[j].artifact)];
    if (!poseFittedToReadings(artifact, placements[j])) continue;
    const Eigen::VectorXd c = Eigen::VectorXd::Zero(artifact.systematicCount());
    for (std::size_t i = 0; i < placements[j].measurements.size(); ++i) {
      Measurement reading = placements[j].measurements[i];
      if (!makeConsistent(builder, artifact, p, poses[j], c, reading)) continue;
      if (!out) out = placements;  // the first that moves: the copy is made once
      (*out)[j].measurements[i].joints = reading.joints;
    }
  }
  return out;
}

}  // namespace artcal
