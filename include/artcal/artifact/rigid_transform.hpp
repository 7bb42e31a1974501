#pragma once
// Rigid transforms between the machine frame and an artifact frame (docs/method.md section 1):
//   W = R x + t    (x in the machine frame, W in the artifact frame)
// in 2-D or 3-D. Small motions are applied on the artifact side: W' = exp(delta) W, with
// delta = (translation, rotation): 2 + 1 numbers in 2-D, 3 + 3 in 3-D.

#include <Eigen/Core>

namespace artcal {

struct RigidTransform {
  Eigen::MatrixXd R;  ///< dimension x dimension rotation
  Eigen::VectorXd t;  ///< dimension

  int dimension() const { return static_cast<int>(t.size()); }
  static RigidTransform identity(int dimension);
  Eigen::VectorXd apply(const Eigen::VectorXd& x) const { return R * x + t; }
  RigidTransform inverse() const;
  /// exp(delta) * this, delta = (translation, rotation) in the artifact frame.
  RigidTransform perturbed(const Eigen::VectorXd& delta) const;
};

/// Number of numbers in a full rigid motion: 3 in 2-D, 6 in 3-D.
inline int rigidMotionSize(int dimension) {
  return dimension == 2 ? 3 : 6;
}

/// Least-squares rigid fit W ~ R x + t of machine points (columns of `machine`) onto artifact
/// points (columns of `artifact`), no scaling (Kabsch / Umeyama, Eigen::umeyama). With one point
/// the rotation is the identity; with collinear points the roll about their line is arbitrary.
RigidTransform fitRigid(const Eigen::MatrixXd& machine, const Eigen::MatrixXd& artifact);

/// The transform of an artifact placed at `center` with its X axis turned by `angle` (2-D, rad).
RigidTransform placePlanar(const Eigen::Vector2d& center, double angle);
/// The transform of an artifact placed at `center` with its X axis along `direction` and turned
/// by `roll` about it (3-D, rad). The zero-roll Y axis is horizontal (perpendicular to z) unless
/// the direction is vertical, then it is the machine's y.
RigidTransform placeSpatial(const Eigen::Vector3d& center, const Eigen::Vector3d& direction,
                            double roll);

}  // namespace artcal
