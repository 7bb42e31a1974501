#include "artcal/model/inverse_kinematics.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <numbers>

namespace artcal {

std::vector<Eigen::VectorXd> planar2rInverse(const Eigen::VectorXd& p,
                                             const Eigen::Vector2d& target) {
  const double l1 = p[0], l2 = p[1], dt2 = p[2];
  const double r2 = target.squaredNorm();
  const double cosine = (r2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2);
  if (cosine < -1.0 - 1e-12 || cosine > 1.0 + 1e-12) return {};
  const double elbow = std::acos(std::clamp(cosine, -1.0, 1.0));
  std::vector<Eigen::VectorXd> solutions;
  for (double sign : {1.0, -1.0}) {
    const double phi = sign * elbow;  // t2 + dt2
    const double t1 = std::atan2(target.y(), target.x()) -
                      std::atan2(l2 * std::sin(phi), l1 + l2 * std::cos(phi));
    solutions.push_back(Eigen::Vector2d(std::remainder(t1, 2 * std::numbers::pi),
                                        std::remainder(phi - dt2, 2 * std::numbers::pi)));
    if (elbow == 0.0) break;
  }
  return solutions;
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

namespace {

// Each angle moved by whole turns to the representative nearest q0 inside the limits; false
// when some angle has none.
bool nearestRepresentativeWithinLimits(const Machine& machine, const Eigen::VectorXd& q0,
                                       Eigen::VectorXd& q) {
  constexpr double kTurn = 2 * std::numbers::pi;
  for (int i = 0; i < q.size(); ++i) {
    const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
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

std::optional<Eigen::VectorXd> planar2rNear(const Machine& machine, const Eigen::VectorXd& p,
                                            const Eigen::VectorXd& target,
                                            const Eigen::VectorXd& q0) {
  std::optional<Eigen::VectorXd> best;
  double best_distance = 0.0;
  for (Eigen::VectorXd q : planar2rInverse(p, target.head<2>())) {
    if (!nearestRepresentativeWithinLimits(machine, q0, q)) continue;
    Eigen::VectorXd x;
    forwardOrThrow(*machine.mechanism, p, q, x);
    if ((x - target).norm() > 1e-6) continue;
    const double distance = (q - q0).norm();
    if (!best || distance < best_distance) {
      best = q;
      best_distance = distance;
    }
  }
  return best;
}

}  // namespace

std::optional<Eigen::VectorXd> solveInverseKinematics(const Machine& machine,
                                                      const Eigen::VectorXd& p,
                                                      const Eigen::VectorXd& target,
                                                      const Eigen::VectorXd& q0,
                                                      const IkOptions& options) {
  const Mechanism& mech = *machine.mechanism;
  if (mech.modelName() == "planar2r") return planar2rNear(machine, p, target, q0);
  Eigen::VectorXd q = q0;
  applyJointLimits(machine, q);
  Eigen::VectorXd x;
  Eigen::MatrixXd J;
  forwardOrThrow(mech, p, q, x, nullptr, &J);
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
    forwardOrThrow(mech, p, trial, x_trial, nullptr, &J_trial);
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
  return q;
}

std::vector<Eigen::VectorXd> diversePostures(const Machine& machine, const Eigen::VectorXd& p,
                                             const Eigen::VectorXd& target, int count,
                                             std::mt19937_64& rng, int attempts,
                                             const IkOptions& options) {
  const int n = machine.jointCount();
  std::vector<Eigen::VectorXd> found;
  for (int a = 0; a < attempts; ++a) {
    Eigen::VectorXd q0(n);
    for (int i = 0; i < n; ++i) {
      const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
      q0[i] = lo + (hi - lo) * (static_cast<double>(rng() >> 11) * 0x1.0p-53);
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

}  // namespace artcal
