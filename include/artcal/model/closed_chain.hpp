#pragma once
// Closed-chain mechanisms (docs/models.md section 3): a model given as constraints g(s, p, q) = 0
// on a pose s of the moving body, with the probe centre x = h(s, p). One shared piece of code
// solves and differentiates every such model:
//
//   forward kinematics  Newton on g from the model's home pose: s += ds, ds = -G_s^-1 g, to
//                       max |g_i| < 1e-10 mm; 50 iterations without convergence, or a singular
//                       G_s = dg/ds, is a reported failure (ForwardStatus), never an exception;
//   Jacobians           the implicit function theorem on g(s(p, q), p, q) = 0:
//                       ds/dq = -G_s^-1 G_q,  ds/dp = -G_s^-1 G_p, so that
//                       J_x_q = H_s ds/dq,    J_x_p = H_p + H_s ds/dp.
//
// The pose is a ChainPose (t, R): a translation and, for a moving body that turns, a rotation.
// poseDimension() says which pose coordinates s are free, and so how many constraints there are:
//   2  planar translation (t.x, t.y)            e.g. a planar five-bar, g_i = |t - e_i(q_i)| - l_i
//   3  spatial translation (t)                  e.g. a delta robot (its platform does not turn),
//                                               g_i = |t + a_i - e_i(q_i)| - l_i
//   6  rigid motion (t, w), R <- exp([dw]) R    e.g. the Stewart-Gough hexapod (hexapod.hpp)
// A new closed-chain family implements home(), constraints() and tip() and nothing else; see
// docs/hexapod.md ("Adding a closed-chain family").

#include <Eigen/Core>
#include <optional>
#include <random>

#include "artcal/model/mechanism.hpp"

namespace artcal {

/// Pose of the moving body: x_base = t + R x_body.
struct ChainPose {
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
};

/// At most 6 constraints; the Jacobians in p and q are sized by the model (no allocation when
/// they already have the right size).
using ConstraintVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
using ConstraintPoseJacobian = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;

struct ClosedChainOptions {
  double tolerance = 1e-10;  ///< mm, on max |g_i|
  int max_iterations = 50;
  /// G_s is singular when its smallest pivot (columns scaled to a common unit) is below this
  /// times its largest.
  double singular_pivot = 1e-9;
};

class ClosedChainMechanism : public Mechanism {
 public:
  explicit ClosedChainMechanism(const ClosedChainOptions& options = {}) : options_(options) {}

  /// 2, 3 or 6: the free pose coordinates s, and the number of constraints.
  virtual int poseDimension() const = 0;
  /// Where Newton starts (parameters p, internal units).
  virtual ChainPose home(const Eigen::VectorXd& p) const = 0;
  /// A length that turns rotation coordinates into mm for the singularity test (e.g. the
  /// platform's radius); unused when the pose does not turn.
  virtual double rotationScale() const { return 1.0; }
  /// g(s, p, q) and, when not null, G_s (poseDimension square), G_p, G_q (resized as needed).
  virtual void constraints(const ChainPose& pose, const Eigen::VectorXd& p,
                           const Eigen::VectorXd& q, ConstraintVector& g,
                           ConstraintPoseJacobian* G_s, Eigen::MatrixXd* G_p,
                           Eigen::MatrixXd* G_q) const = 0;
  /// x = h(s, p) and, when not null, H_s (dimension x poseDimension) and H_p (dimension x
  /// parameters; resized as needed).
  virtual void tip(const ChainPose& pose, const Eigen::VectorXd& p, Eigen::VectorXd& x,
                   Eigen::MatrixXd* H_s, Eigen::MatrixXd* H_p) const = 0;

  /// The pose of the moving body for readings q: Newton from home(p).
  [[nodiscard]] ForwardStatus solvePose(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                        ChainPose& pose) const;

  /// solvePose, then the tip and the Jacobians by the implicit function theorem.
  [[nodiscard]] ForwardStatus forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                      Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p = nullptr,
                                      Eigen::MatrixXd* J_x_q = nullptr) const override;

  const ClosedChainOptions& options() const { return options_; }

 private:
  ClosedChainOptions options_;
};

/// A closed chain whose posture is the orientation of its moving body (the hexapod's platform
/// tilt): a point is read in several postures by several orientations, and inverse kinematics
/// is closed form given the orientation. Inverse kinematics (inverse_kinematics.hpp) asks for it.
class OrientedPostures {
 public:
  virtual ~OrientedPostures() = default;
  virtual Eigen::Matrix3d homeOrientation() const = 0;
  /// The readings that put the probe centre on `target` with the body turned to R (limits not
  /// applied).
  virtual Eigen::VectorXd readingsAt(const Eigen::VectorXd& p, const Eigen::Vector3d& target,
                                     const Eigen::Matrix3d& R) const = 0;
  /// The body's orientation at readings q (forward kinematics); std::nullopt when it fails.
  virtual std::optional<Eigen::Matrix3d> orientationOf(const Eigen::VectorXd& p,
                                                       const Eigen::VectorXd& q) const = 0;
};

/// Rz(yaw) Ry(pitch) Rx(roll) (URDF's fixed-axis roll-pitch-yaw), angles in rad.
Eigen::Matrix3d rotationFromRpy(const Eigen::Vector3d& rpy);

/// An orientation within `tilt` rad of `home`: exp([w]) home, w along a uniformly random
/// direction with |w| uniform in [0, tilt] (the same on every platform).
Eigen::Matrix3d randomTilt(const Eigen::Matrix3d& home, double tilt, std::mt19937_64& rng);

/// The pose moved by ds: the first min(3, n) coordinates translate, the last three of a 6-vector
/// turn (R <- exp([w]) R, the exact exponential).
void retractPose(ChainPose& pose, const Eigen::Ref<const Eigen::VectorXd>& ds);

}  // namespace artcal
