#pragma once
// Inverse kinematics: joint readings that put the probe centre on a target point.
//   planar2r: closed form, both elbow branches.
//   any model (serial-dh): damped least squares (Levenberg-Marquardt on |f(p, q) - x*|^2), joint
//   limits respected (revolute joints with a full turn of range wrap, others are clamped).
// `diversePostures` returns genuinely different postures for the same point (the seed's o > 1):
// many seeded starts, then a farthest-point choice in joint space.

#include <Eigen/Core>
#include <optional>
#include <random>
#include <vector>

#include "artcal/model/machine.hpp"

namespace artcal {

struct IkOptions {
  int max_iterations = 200;
  double tolerance = 1e-10;  ///< mm, on |f(p, q) - target|
};

/// Both elbow branches of the planar 2R arm for a target (parameters p = l1, l2, dt2), joint
/// limits not applied. Empty when the target is out of reach.
std::vector<Eigen::VectorXd> planar2rInverse(const Eigen::VectorXd& p,
                                             const Eigen::Vector2d& target);

/// A solution near q0 within the machine's joint limits; std::nullopt when none was found.
std::optional<Eigen::VectorXd> solveInverseKinematics(const Machine& machine,
                                                      const Eigen::VectorXd& p,
                                                      const Eigen::VectorXd& target,
                                                      const Eigen::VectorXd& q0,
                                                      const IkOptions& options = {});

/// Up to `count` postures reaching `target` within the limits, spread in joint space.
std::vector<Eigen::VectorXd> diversePostures(const Machine& machine, const Eigen::VectorXd& p,
                                             const Eigen::VectorXd& target, int count,
                                             std::mt19937_64& rng, int attempts = 24,
                                             const IkOptions& options = {});

/// Puts q inside the joint limits: revolute joints with at least a full turn wrap, others clamp.
void applyJointLimits(const Machine& machine, Eigen::VectorXd& q);

}  // namespace artcal
