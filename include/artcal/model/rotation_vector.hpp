#pragma once
// Orientations as rotation vectors (instruments.md, "measures": "pose": the orientation part of a
// reading is a rotation vector w, R = exp([w]x), |w| the angle about w / |w|), and the residual of
// a predicted orientation against a measured one with its exact derivative.
//
// Perturbations are spatial (left): a step dw turns R into exp([dw]x) R, the convention of the
// models' angular Jacobians (Mechanism::forwardPose) and of a station's rigid motion.

#include <Eigen/Core>

namespace artcal {

/// exp([w]x): the rotation by |w| about w / |w| (identity for w = 0).
Eigen::Matrix3d rotationFromVector(const Eigen::Vector3d& w);
/// log(R): the rotation vector of R, angle in [0, pi].
Eigen::Vector3d rotationVector(const Eigen::Matrix3d& R);
/// J_l^-1(phi): d log(exp([dw]x) exp([phi]x)) / d dw at dw = 0, the inverse left Jacobian of
/// SO(3); exact, with its series below a small angle.
Eigen::Matrix3d inverseLeftJacobian(const Eigen::Vector3d& phi);

/// The orientation residual e = log(R_predicted exp([measured]x)^T): the rotation vector that
/// takes the measured orientation to the predicted one (zero when they agree, no wrap at pi for
/// small residuals). With J_e_w filled: de / dw for R_predicted <- exp([dw]x) R_predicted,
/// which is inverseLeftJacobian(e).
Eigen::Vector3d orientationResidual(const Eigen::Matrix3d& R_predicted,
                                    const Eigen::Vector3d& measured,
                                    Eigen::Matrix3d* J_e_w = nullptr);

/// Rz(yaw) Ry(pitch) Rx(roll), URDF's fixed-axis roll-pitch-yaw (radians).
Eigen::Matrix3d rpyToMatrix(const Eigen::Vector3d& rpy);
/// Roll, pitch, yaw of a rotation matrix with rpyToMatrix(rpyFromMatrix(R)) == R to rounding,
/// also at and near pitch = +-90 deg (there roll and yaw are not unique: one pair is returned).
Eigen::Vector3d rpyFromMatrix(const Eigen::Matrix3d& R);
/// Rotation by `angle` (rad) about the unit vector `axis` (Rodrigues).
Eigen::Matrix3d axisAngleMatrix(const Eigen::Vector3d& axis, double angle);

}  // namespace artcal
