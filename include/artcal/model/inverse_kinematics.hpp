#pragma once
// Inverse kinematics: joint readings that put the probe centre on a target point.
//   a model with a closed form (Mechanism::closedFormInverse; planar2r: both elbow branches):
//   the solution nearest the start within the limits.
//   any other model (serial-dh): damped least squares (Levenberg-Marquardt on |f(p, q) - x*|^2),
//   joint limits respected (revolute joints with a full turn of range wrap, others are clamped),
//   each angle returned as the equivalent (by whole turns) nearest the start.
// `diversePostures` returns genuinely different postures for the same point (the seed's o > 1):
// many seeded starts, then a farthest-point choice in joint space.

#include <Eigen/Core>
#include <optional>
#include <random>
#include <vector>

#include "artcal/core/units.hpp"
#include "artcal/model/machine.hpp"

namespace artcal {

struct IkOptions {
  int max_iterations = 200;
  double tolerance = 1e-10;  ///< mm, on |f(p, q) - target|
  int stylus = 0;            ///< the stylus put on the target (Cartesian CMMs)
  /// Models whose posture is an orientation (OrientedPostures, the hexapod): postures are drawn
  /// within `tilt` rad of home.
  double tilt = 15.0 * kDegree;
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

/// The posture generator: up to `count` postures reading `target`. A model with a closed-form
/// inverse gives its solutions within the limits (seeded random ones dropped when there are
/// more than `count`: planar2r's elbow branch when one is asked); any other spreads numerical
/// solutions (diversePostures).
std::vector<Eigen::VectorXd> posturesFor(const Machine& machine, const Eigen::VectorXd& p,
                                         const Eigen::VectorXd& target, int count,
                                         std::mt19937_64& rng, const IkOptions& options = {});

/// The joints `held` kept at their values in q0 and the others solved (Gauss-Newton on the free
/// joints' columns of J_x_q) so that the probe sits on `target`; std::nullopt when the free joints
/// cannot reach it (|f - target| above options.tolerance after options.max_iterations) or a joint
/// ends outside the machine's limits (a revolute free joint with a full turn of range wraps). A
/// machine tool's slides at commanded rotary positions: f is affine in them, one step solves it.
std::optional<Eigen::VectorXd> solveHoldingJoints(const Machine& machine, const Eigen::VectorXd& p,
                                                  const Eigen::VectorXd& target,
                                                  const Eigen::VectorXd& q0,
                                                  const std::vector<int>& held,
                                                  const IkOptions& options = {});

/// Puts q inside the joint limits: revolute joints with at least a full turn wrap, others clamp.
void applyJointLimits(const Machine& machine, Eigen::VectorXd& q);

/// Each revolute angle of q moved by whole turns to the equivalent angle nearest `reference`
/// within the limits (a prismatic joint must already be inside them); false, q partly moved,
/// when some joint has no equivalent within its limits.
bool nearestEquivalentWithinLimits(const Machine& machine, const Eigen::VectorXd& reference,
                                   Eigen::VectorXd& q);

}  // namespace artcal
