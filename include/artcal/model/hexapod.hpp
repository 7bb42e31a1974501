#pragma once
// The Stewart-Gough hexapod (docs/models.md section 3), the first closed-chain model
// (closed_chain.hpp). Leg i joins base point b_i (base frame) to platform point a_i (platform
// frame); its reading q_i is a length in mm and its true length L_i = q_i + offset_i. The
// platform pose (t, R) satisfies
//   g_i = |t + R a_i - b_i| - L_i = 0,   i = 1..6,
// solved by Newton from `home`; the probe centre is x = t + R probe.
// Parameters (45, all mm), per leg bN.x bN.y bN.z aN.x aN.y aN.z lN.offset, then probe.x
// probe.y probe.z. The derivatives of g (n_i the unit leg direction, u_i = R a_i):
//   dg_i/dt = n_i,  dg_i/dw = u_i x n_i   (R <- exp([dw]) R),
//   dg_i/db_i = -n_i,  dg_i/da_i = R^T n_i,  dg_i/doffset_i = -1,  dg_i/dq_i = -1,
// and dx/dt = I, dx/dw = -[R probe]_x, dx/dprobe = R.
//
// Inverse kinematics is closed form: for a probe target x* and a platform orientation R (the
// posture), t = x* - R probe and q_i = |t + R a_i - b_i| - offset_i.

#include "artcal/model/closed_chain.hpp"

namespace artcal {

class Hexapod final : public ClosedChainMechanism, public OrientedPostures {
 public:
  static constexpr int kLegs = 6;
  static constexpr int kParametersPerLeg = 7;
  static constexpr int kProbeOffset = kLegs * kParametersPerLeg;  ///< index of probe.x

  /// `home`: where forward kinematics starts; `platform_radius`: the platform's size, mm (the
  /// scale of rotations in the singularity test).
  Hexapod(const ChainPose& home, double platform_radius);

  std::string modelName() const override { return "hexapod"; }
  int dimension() const override { return 3; }
  int jointCount() const override { return kLegs; }
  JointKind jointKind(int) const override { return JointKind::Prismatic; }
  const std::vector<ParameterInfo>& parameters() const override { return parameters_; }

  int poseDimension() const override { return 6; }
  ChainPose home(const Eigen::VectorXd&) const override { return home_; }
  double rotationScale() const override { return platform_radius_; }
  void constraints(const ChainPose& pose, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                   ConstraintVector& g, ConstraintPoseJacobian* G_s, Eigen::MatrixXd* G_p,
                   Eigen::MatrixXd* G_q) const override;
  void tip(const ChainPose& pose, const Eigen::VectorXd& p, Eigen::VectorXd& x,
           Eigen::MatrixXd* H_s, Eigen::MatrixXd* H_p) const override;

  const ChainPose& homePose() const { return home_; }
  static int baseOffset(int leg) { return kParametersPerLeg * leg; }
  static int platformOffset(int leg) { return kParametersPerLeg * leg + 3; }
  static int legOffsetIndex(int leg) { return kParametersPerLeg * leg + 6; }

  /// Closed-form inverse kinematics: the leg readings that put the probe centre on `target`
  /// with platform orientation R.
  Eigen::VectorXd legReadings(const Eigen::VectorXd& p, const Eigen::Vector3d& target,
                              const Eigen::Matrix3d& R) const;

  // OrientedPostures: the platform orientation is the posture.
  const OrientedPostures* orientedPostures() const override { return this; }
  Eigen::Matrix3d homeOrientation() const override { return home_.R; }
  Eigen::VectorXd readingsAt(const Eigen::VectorXd& p, const Eigen::Vector3d& target,
                             const Eigen::Matrix3d& R) const override {
    return legReadings(p, target, R);
  }
  std::optional<Eigen::Matrix3d> orientationOf(const Eigen::VectorXd& p,
                                               const Eigen::VectorXd& q) const override;

  /// One polyline through the whole machine at reading q (the pose by solvePose): the
  /// base hexagon b1..b6 b1, leg 1 up to a1, the platform hexagon a1..a6 a1 with each leg i >= 2
  /// drawn out and back from a_i (a_i b_i a_i), then the platform centre t and the probe centre.
  /// Empty when forward kinematics fails.
  std::vector<Eigen::VectorXd> skeleton(const Eigen::VectorXd& p,
                                        const Eigen::VectorXd& q) const override;

 private:
  ChainPose home_;
  double platform_radius_;
  std::vector<ParameterInfo> parameters_;
};

}  // namespace artcal
