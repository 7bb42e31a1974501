#include "artcal/model/hexapod.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

#include "artcal/model/frame_turns.hpp"

namespace artcal {

namespace {}  // namespace

Hexapod::Hexapod(const ChainPose& home, double platform_radius)
    : home_(home), platform_radius_(platform_radius) {
  if (!(platform_radius > 0.0)) throw std::invalid_argument("hexapod: platform radius <= 0");
  for (int leg = 1; leg <= kLegs; ++leg) {
    const std::string n = std::to_string(leg);
    for (const char* axis : {".x", ".y", ".z"})
      parameters_.push_back({"b" + n + axis, Quantity::Length});
    for (const char* axis : {".x", ".y", ".z"})
      parameters_.push_back({"a" + n + axis, Quantity::Length});
    parameters_.push_back({"l" + n + ".offset", Quantity::Length});
  }
  for (const char* axis : {"probe.x", "probe.y", "probe.z"}) {
    parameters_.push_back({axis, Quantity::Length});
  }
}

void Hexapod::constraints(const ChainPose& pose, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                          ConstraintVector& g, ConstraintPoseJacobian* G_s, Eigen::MatrixXd* G_p,
                          Eigen::MatrixXd* G_q) const {
  g.resize(kLegs);
  if (G_s) G_s->resize(kLegs, 6);
  if (G_p) G_p->setZero(kLegs, parameterCount());
  if (G_q) G_q->setZero(kLegs, kLegs);
  for (int i = 0; i < kLegs; ++i) {
    const Eigen::Vector3d u = pose.R * p.segment<3>(platformOffset(i));
    const Eigen::Vector3d leg = pose.t + u - p.segment<3>(baseOffset(i));
    const double length = leg.norm();
    g[i] = length - (q[i] + p[legOffsetIndex(i)]);
    const Eigen::Vector3d n = leg / length;
    if (G_s) {
      G_s->block<1, 3>(i, 0) = n.transpose();
      G_s->block<1, 3>(i, 3) = u.cross(n).transpose();
    }
    if (G_p) {
      G_p->block<1, 3>(i, baseOffset(i)) = -n.transpose();
      G_p->block<1, 3>(i, platformOffset(i)) = (pose.R.transpose() * n).transpose();
      (*G_p)(i, legOffsetIndex(i)) = -1.0;
    }
    if (G_q) (*G_q)(i, i) = -1.0;
  }
}

void Hexapod::tip(const ChainPose& pose, const Eigen::VectorXd& p, Eigen::VectorXd& x,
                  Eigen::MatrixXd* H_s, Eigen::MatrixXd* H_p) const {
  const Eigen::Vector3d arm = pose.R * p.segment<3>(kProbeOffset);
  x.resize(3);
  x = pose.t + arm;
  if (H_s) {
    H_s->resize(3, 6);
    H_s->leftCols<3>().setIdentity();
    H_s->rightCols<3>() = -skew(arm);
  }
  if (H_p) {
    H_p->setZero(3, parameterCount());
    H_p->middleCols<3>(kProbeOffset) = pose.R;
  }
}

Eigen::VectorXd Hexapod::legReadings(const Eigen::VectorXd& p, const Eigen::Vector3d& target,
                                     const Eigen::Matrix3d& R) const {
  const Eigen::Vector3d t = target - R * p.segment<3>(kProbeOffset);
  Eigen::VectorXd q(kLegs);
  for (int i = 0; i < kLegs; ++i) {
    q[i] = (t + R * p.segment<3>(platformOffset(i)) - p.segment<3>(baseOffset(i))).norm() -
           p[legOffsetIndex(i)];
  }
  return q;
}

std::optional<Eigen::Matrix3d> Hexapod::orientationOf(const Eigen::VectorXd& p,
                                                      const Eigen::VectorXd& q) const {
  ChainPose pose;
  if (solvePose(p, q, pose) != ForwardStatus::Ok) return std::nullopt;
  return pose.R;
}

std::vector<Eigen::VectorXd> Hexapod::skeleton(const Eigen::VectorXd& p,
                                               const Eigen::VectorXd& q) const {
  ChainPose pose;
  if (solvePose(p, q, pose) != ForwardStatus::Ok) return {};
  auto base = [&](int i) -> Eigen::VectorXd { return p.segment<3>(baseOffset(i % kLegs)); };
  auto platform = [&](int i) -> Eigen::VectorXd {
    return pose.t + pose.R * p.segment<3>(platformOffset(i % kLegs));
  };
  std::vector<Eigen::VectorXd> points;
  for (int i = 0; i <= kLegs; ++i) points.push_back(base(i));
  points.push_back(platform(0));
  for (int i = 1; i < kLegs; ++i) {
    points.push_back(platform(i));
    points.push_back(base(i));
    points.push_back(platform(i));
  }
  points.push_back(platform(0));
  points.push_back(pose.t);
  points.push_back(pose.t + pose.R * p.segment<3>(kProbeOffset));
  return points;
}

}  // namespace artcal
