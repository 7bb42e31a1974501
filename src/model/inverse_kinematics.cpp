#include "artcal/model/inverse_kinematics.hpp"

#include "artcal/core/dense_decompositions.hpp"
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "artcal/core/random.hpp"
#include "artcal/model/closed_chain.hpp"
#include "artcal/model/planar2r.hpp"

namespace artcal {

std::vector<Eigen::VectorXd> planar2rInverse(const Eigen::VectorXd& p,
                                             const Eigen::Vector2d& target) {
  return Planar2R::elbowBranches(p, target);
}

void applyJointLimits(const Machine& machine, Eigen::VectorXd& q) {
  constexpr double kTurn = 2 * std::numbers::pi;
  for (int i = 0; i < q.size(); ++i) {
    const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
    if (machine.mechanism->jointKind(i) == JointKind::Revolute && hi - lo >= kTurn - 1e-12) {
      q[i] = lo + std::fmod(std::fmod(q[i] - lo, kTurn) + kTurn, kTurn);
    } else {
      q[i] = std::clamp(q[i], lo, hi);
    }
  }
}

bool nearestEquivalentWithinLimits(const Machine& machine, const Eigen::VectorXd& q0,
                                   Eigen::VectorXd& q) {
  constexpr double kTurn = 2 * std::numbers::pi;
  for (int i = 0; i < q.size(); ++i) {
    const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
    if (machine.mechanism->jointKind(i) == JointKind::Prismatic) {
      if (q[i] < lo - 1e-12 || q[i] > hi + 1e-12) return false;
      q[i] = std::clamp(q[i], lo, hi);
      continue;
    }
    const double nearest = q0[i] + std::remainder(q[i] - q0[i], kTurn);
    double best = std::numeric_limits<double>::quiet_NaN();
    for (int turns = -2; turns <= 2; ++turns) {
      const double candidate = nearest + turns * kTurn;
      if (candidate < lo - 1e-12 || candidate > hi + 1e-12) continue;
      if (std::isnan(best) || std::abs(candidate - q0[i]) < std::abs(best - q0[i])) {
        best = candidate;
      }
    }
    if (std::isnan(best)) return false;
    q[i] = std::clamp(best, lo, hi);
  }
  return true;
}

namespace {

// The closed-form solution nearest q0 within the limits (Mechanism::closedFormInverse).
std::optional<Eigen::VectorXd> closedFormNear(const Machine& machine, const Eigen::VectorXd& p,
                                              const Eigen::VectorXd& target,
                                              const Eigen::VectorXd& q0, int stylus) {
  std::optional<Eigen::VectorXd> best;
  double best_distance = 0.0;
  for (Eigen::VectorXd q : machine.mechanism->closedFormInverse(p, target, stylus)) {
    if (!nearestEquivalentWithinLimits(machine, q0, q)) continue;
    Eigen::VectorXd x;
    if (machine.mechanism->forwardStylus(stylus, p, q, x) != ForwardStatus::Ok) continue;
    if ((x - target).norm() > 1e-6) continue;
    const double distance = (q - q0).norm();
    if (!best || distance < best_distance) {
      best = q;
      best_distance = distance;
    }
  }
  return best;
}

// A model whose posture is an orientation (the hexapod): the closed form in the orientation the
// body has at q0 (home when q0 does not assemble), so that a posture keeps its identity.
std::optional<Eigen::VectorXd> orientedNear(const Machine& machine, const OrientedPostures& model,
                                            const Eigen::VectorXd& p, const Eigen::VectorXd& target,
                                            const Eigen::VectorXd& q0) {
  const Eigen::Matrix3d R = model.orientationOf(p, q0).value_or(model.homeOrientation());
  Eigen::VectorXd q = model.readingsAt(p, target.head<3>(), R);
  if (!machine.withinLimits(q)) return std::nullopt;
  return q;
}

// Up to `attempts` random orientations within options.tilt of home, those within the limits.
std::vector<Eigen::VectorXd> orientedCandidates(const Machine& machine,
                                                const OrientedPostures& model,
                                                const Eigen::VectorXd& p,
                                                const Eigen::VectorXd& target, int attempts,
                                                std::mt19937_64& rng, const IkOptions& options) {
  std::vector<Eigen::VectorXd> found;
  for (int a = 0; a < attempts; ++a) {
    const Eigen::Matrix3d R = randomTilt(model.homeOrientation(), options.tilt, rng);
    Eigen::VectorXd q = model.readingsAt(p, target.head<3>(), R);
    if (machine.withinLimits(q)) found.push_back(std::move(q));
  }
  return found;
}

}  // namespace

std::optional<Eigen::VectorXd> solveInverseKinematics(const Machine& machine,
                                                      const Eigen::VectorXd& p,
                                                      const Eigen::VectorXd& target,
                                                      const Eigen::VectorXd& q0,
                                                      const IkOptions& options) {
  const Mechanism& mech = *machine.mechanism;
  if (mech.hasClosedFormInverse()) return closedFormNear(machine, p, target, q0, options.stylus);
  if (const OrientedPostures* oriented = mech.orientedPostures()) {
    return orientedNear(machine, *oriented, p, target, q0);
  }
  Eigen::VectorXd q = q0;
  applyJointLimits(machine, q);
  Eigen::VectorXd x;
  Eigen::MatrixXd J;
  forwardOrThrow(mech, p, q, x, nullptr, &J, options.stylus);
  Eigen::VectorXd error = target - x;
  double lambda = 1e-3 * (J * J.transpose()).trace() / J.rows();
  const int d = mech.dimension();
  for (int it = 0; it < options.max_iterations && error.norm() > options.tolerance; ++it) {
    // dq = J^T (J J^T + lambda I)^-1 e: the minimum-norm damped step (redundant arms).
    const Eigen::MatrixXd JJt = J * J.transpose() + lambda * Eigen::MatrixXd::Identity(d, d);
    Eigen::VectorXd trial = q + J.transpose() * JJt.ldlt().solve(error);
    applyJointLimits(machine, trial);
    Eigen::VectorXd x_trial;
    Eigen::MatrixXd J_trial;
    forwardOrThrow(mech, p, trial, x_trial, nullptr, &J_trial, options.stylus);
    const Eigen::VectorXd trial_error = target - x_trial;
    if (trial_error.norm() < error.norm()) {
      q = trial;
      J = J_trial;
      error = trial_error;
      lambda = std::max(lambda * 0.1, 1e-12);
    } else {
      lambda *= 10.0;
      if (lambda > 1e12) break;
    }
  }
  if (error.norm() > std::max(options.tolerance, 1e-9)) return std::nullopt;
  // applyJointLimits wrapped full-turn joints into [lo, lo + 360 deg): back to the equivalent
  // angle nearest the start (a UR's 54 deg, not -306 deg, for limits of +-360 deg). A start with
  // no equivalent within the limits keeps the wrapped angle.
  Eigen::VectorXd nearest = q;
  if (nearestEquivalentWithinLimits(machine, q0, nearest)) return nearest;
  return q;
}

std::optional<Eigen::VectorXd> solveHoldingJoints(const Machine& machine, const Eigen::VectorXd& p,
                                                  const Eigen::VectorXd& target,
                                                  const Eigen::VectorXd& q0,
                                                  const std::vector<int>& held,
                                                  const IkOptions& options) {
  const Mechanism& mech = *machine.mechanism;
  const int n = machine.jointCount();
  std::vector<int> free;
  for (int i = 0; i < n; ++i)
    if (std::find(held.begin(), held.end(), i) == held.end()) free.push_back(i);
  const int f = static_cast<int>(free.size());
  Eigen::VectorXd q = q0, x;
  Eigen::MatrixXd J, J_free(mech.dimension(), f);
  for (int it = 0; it <= options.max_iterations; ++it) {
    if (mech.forwardStylus(options.stylus, p, q, x, nullptr, &J) != ForwardStatus::Ok)
      return std::nullopt;
    const Eigen::VectorXd error = target - x;
    if (!error.allFinite()) return std::nullopt;
    if (error.norm() <= options.tolerance) break;
    if (it == options.max_iterations || f == 0) return std::nullopt;
    for (int k = 0; k < f; ++k) J_free.col(k) = J.col(free[static_cast<std::size_t>(k)]);
    // The least-squares (minimum-norm when the free joints are redundant) Gauss-Newton step.
    const Eigen::VectorXd step = J_free.completeOrthogonalDecomposition().solve(error);
    for (int k = 0; k < f; ++k) q[free[static_cast<std::size_t>(k)]] += step[k];
  }
  // The free joints within the limits (a revolute one wraps by whole turns when it can).
  constexpr double kTurn = 2 * std::numbers::pi;
  for (int i : free) {
    const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
    if (mech.jointKind(i) == JointKind::Revolute && (q[i] < lo || q[i] > hi)) {
      const double wrapped = lo + std::fmod(std::fmod(q[i] - lo, kTurn) + kTurn, kTurn);
      if (wrapped <= hi) q[i] = wrapped;
    }
    if (q[i] < lo || q[i] > hi) return std::nullopt;
  }
  return q;
}

std::vector<Eigen::VectorXd> diversePostures(const Machine& machine, const Eigen::VectorXd& p,
                                             const Eigen::VectorXd& target, int count,
                                             std::mt19937_64& rng, int attempts,
                                             const IkOptions& options) {
  const int n = machine.jointCount();
  std::vector<Eigen::VectorXd> found;
  const OrientedPostures* oriented = machine.mechanism->orientedPostures();
  if (oriented) found = orientedCandidates(machine, *oriented, p, target, attempts, rng, options);
  for (int a = 0; a < (oriented ? 0 : attempts); ++a) {
    Eigen::VectorXd q0(n);
    for (int i = 0; i < n; ++i) {
      const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
      q0[i] = lo + (hi - lo) * unitUniform(rng);
    }
    if (auto q = solveInverseKinematics(machine, p, target, q0, options)) found.push_back(*q);
  }
  // Farthest-point selection: start from the first, add the one farthest from all chosen.
  std::vector<Eigen::VectorXd> chosen;
  if (found.empty()) return chosen;
  chosen.push_back(found.front());
  while (static_cast<int>(chosen.size()) < count) {
    double best = 0.0;
    int best_index = -1;
    for (std::size_t i = 0; i < found.size(); ++i) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const auto& c : chosen) nearest = std::min(nearest, (found[i] - c).norm());
      if (nearest > best) {
        best = nearest;
        best_index = static_cast<int>(i);
      }
    }
    if (best_index < 0 || best < 1e-3) break;  // nothing genuinely different left
    chosen.push_back(found[static_cast<std::size_t>(best_index)]);
  }
  return chosen;
}

std::vector<Eigen::VectorXd> posturesFor(const Machine& machine, const Eigen::VectorXd& p,
                                         const Eigen::VectorXd& target, int count,
                                         std::mt19937_64& rng, const IkOptions& options) {
  const Mechanism& mech = *machine.mechanism;
  if (!mech.hasClosedFormInverse()) {
    return diversePostures(machine, p, target, count, rng, 24, options);
  }
  std::vector<Eigen::VectorXd> out;
  for (const Eigen::VectorXd& branch : mech.closedFormInverse(p, target, options.stylus)) {
    if (auto q = solveInverseKinematics(machine, p, target, branch, options)) out.push_back(*q);
  }
  // More solutions than asked for: drop seeded random ones (planar2r: one elbow branch of two).
  while (count >= 1 && static_cast<int>(out.size()) > count) {
    out.erase(out.begin() + static_cast<long>(rng() % out.size()));
  }
  return out;
}

}  // namespace artcal
