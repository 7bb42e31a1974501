#include "artcal/model/chain.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

#include "artcal/model/frame_turns.hpp"

namespace artcal {

namespace {

// Per-joint scratch kept on the stack (no allocation per call).
using ChainColumns =
    Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, Chain::kMaxJoints>;
using Jacobian = Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic>>;

std::vector<ParameterInfo> chainParameters(const std::vector<ChainJoint>& joints) {
  std::vector<ParameterInfo> out;
  for (const ChainJoint& joint : joints) {
    for (const char* axis : {".x", ".y", ".z"})
      out.push_back({joint.name + axis, Quantity::Length});
    for (const char* angle : {".roll", ".pitch", ".yaw"}) {
      out.push_back({joint.name + angle, Quantity::Angle});
    }
    if (joint.type == ChainJointType::Revolute)
      out.push_back({joint.name + ".offset", Quantity::Angle});
    if (joint.type == ChainJointType::Prismatic) {
      out.push_back({joint.name + ".offset", Quantity::Length});
    }
  }
  return out;
}

// R <- R Rot(axis, angle): two columns turned in place when the axis is a coordinate axis (as
// most URDF joints' are), else the product with Rodrigues' matrix.
void turnAboutAxis(Eigen::Matrix3d& R, const Eigen::Vector3d& axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  if (axis.y() == 0.0 && axis.z() == 0.0 && std::abs(axis.x()) == 1.0) {
    turnAboutX(R, c, axis.x() * s);
  } else if (axis.x() == 0.0 && axis.z() == 0.0 && std::abs(axis.y()) == 1.0) {
    turnAboutY(R, c, axis.y() * s);
  } else if (axis.x() == 0.0 && axis.y() == 0.0 && std::abs(axis.z()) == 1.0) {
    turnAboutZ(R, c, axis.z() * s);
  } else {
    R = R * axisAngleMatrix(axis, angle);
  }
}

/// Cosines and sines of every joint's origin turns (roll, pitch, yaw), for the parameters last
/// seen on this thread. A calibration evaluates thousands of readings with one p, and these
/// depend on p alone: computed once per p, not once per reading (the same std::cos and std::sin
/// of the same angles: the same bits).
struct OriginTurns {
  std::vector<double> angles, cos, sin;  ///< 3 per joint: roll, pitch, yaw, in chain order
};

const OriginTurns& originTurns(const std::vector<int>& offsets, const Eigen::VectorXd& p) {
  thread_local OriginTurns turns;
  const std::size_t n = 3 * offsets.size();
  bool same = turns.angles.size() == n;
  for (std::size_t i = 0; same && i < n; ++i)
    same = turns.angles[i] == p[offsets[i / 3] + 3 + static_cast<int>(i % 3)];
  if (!same) {
    turns.angles.resize(n);
    turns.cos.resize(n);
    turns.sin.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double angle = p[offsets[i / 3] + 3 + static_cast<int>(i % 3)];
      turns.angles[i] = angle;
      turns.cos[i] = std::cos(angle);
      turns.sin[i] = std::sin(angle);
    }
  }
  return turns;
}

}  // namespace

Chain::Chain(std::vector<ChainJoint> joints, std::vector<ChainTip> tips,
             std::optional<ComplianceSpec> compliance)
    : joints_(std::move(joints)), tips_(std::move(tips)), compliance_(std::move(compliance)) {
  if (joints_.empty()) throw std::invalid_argument("chain: no joints");
  if (joints_.size() > static_cast<std::size_t>(kMaxJoints)) {
    throw std::invalid_argument("chain: at most " + std::to_string(kMaxJoints) + " joints");
  }
  std::set<std::string> names;
  int offset = 0;
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    ChainJoint& joint = joints_[i];
    if (joint.name.empty()) throw std::invalid_argument("chain: a joint without a name");
    if (!names.insert(joint.name).second) {
      throw std::invalid_argument("chain: joint name \"" + joint.name + "\" used twice");
    }
    offsets_.push_back(offset);
    offset += kOriginParameters;
    if (isMovable(joint.type)) {
      const double norm = joint.axis.norm();
      if (!(norm > 1e-12) || !std::isfinite(norm)) {
        throw std::invalid_argument("chain: joint \"" + joint.name + "\" has a zero axis");
      }
      joint.axis /= norm;
      offset += 1;
    }
  }
  resolveReadings();
  parameters_ = chainParameters(joints_);
  checkTips();
  if (!compliance_) return;
  if (tips_.size() != 1)
    throw std::invalid_argument("chain: compliance needs a machine of one tip");
  if (compliance_->masses.size() != joints_.size())
    throw std::invalid_argument("chain: the compliance block needs one mass per joint");
  std::vector<bool> revolute;
  for (const ChainReading& reading : readings_)
    revolute.push_back(reading.type == ChainJointType::Revolute);
  appendComplianceParameters(readingNames(), revolute, parameters_, compliance_index_);
}

// No tips: one through every joint. Named tips: distinct non-empty names, each a non-empty path
// of distinct joints, every joint on some path (else its parameters would move nothing).
void Chain::checkTips() {
  named_tips_ = !tips_.empty();
  if (tips_.empty()) {
    ChainTip all;
    for (int i = 0; i < static_cast<int>(joints_.size()); ++i) all.joints.push_back(i);
    tips_.push_back(std::move(all));
    return;
  }
  std::set<std::string> names;
  std::vector<bool> used(joints_.size(), false);
  for (const ChainTip& tip : tips_) {
    if (tip.name.empty()) throw std::invalid_argument("chain: a tip without a name");
    if (!names.insert(tip.name).second) {
      throw std::invalid_argument("chain: tip name \"" + tip.name + "\" used twice");
    }
    if (tip.joints.empty())
      throw std::invalid_argument("chain: tip \"" + tip.name + "\" has no joints");
    std::set<int> on_path;
    for (const int j : tip.joints) {
      if (j < 0 || j >= static_cast<int>(joints_.size()) || !on_path.insert(j).second) {
        throw std::invalid_argument("chain: tip \"" + tip.name +
                                    "\" names a joint twice or one that does not exist");
      }
      used[static_cast<std::size_t>(j)] = true;
    }
  }
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    if (!used[i]) {
      throw std::invalid_argument("chain: joint \"" + joints_[i].name + "\" is on no tip's path");
    }
  }
}

std::optional<ChainMimicProblem> Chain::mimicProblem(const std::vector<ChainJoint>& joints) {
  std::map<std::string, std::size_t> index, first_off_chain_mimic;
  for (std::size_t i = 0; i < joints.size(); ++i) index[joints[i].name] = i;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const ChainJoint& joint = joints[i];
    if (!joint.mimic) continue;
    const auto problem = [&](std::string message) {
      return ChainMimicProblem{static_cast<int>(i), std::move(message)};
    };
    const ChainMimic& mimic = *joint.mimic;
    if (!isMovable(joint.type)) return problem("a fixed joint cannot mimic another joint");
    if (mimic.joint.empty()) return problem("name the joint this one mimics");
    if (!std::isfinite(mimic.multiplier) || !std::isfinite(mimic.offset)) {
      return problem("the multiplier and the offset must be finite");
    }
    if (mimic.joint == joint.name) return problem("a joint cannot mimic itself");
    const auto on_chain = index.find(mimic.joint);
    if (on_chain == index.end()) {  // a master off the chain: one type for all its mimics
      const auto [first, inserted] = first_off_chain_mimic.emplace(mimic.joint, i);
      if (!inserted && joints[first->second].type != joint.type) {
        return problem("the joints that mimic \"" + mimic.joint + "\" must be of one type");
      }
      continue;
    }
    const ChainJoint& master = joints[on_chain->second];
    if (!isMovable(master.type) || master.mimic) {
      return problem("joint \"" + mimic.joint +
                     "\" is fixed or a mimic itself (a cycle or a chain of mimics): name the "
                     "driving joint");
    }
    if (master.type != joint.type) {
      return problem("joint \"" + mimic.joint +
                     "\" is of another type than this one (a mimic and its master are both "
                     "revolute or both prismatic)");
    }
  }
  return std::nullopt;
}

// The readings in order (driving joints on the chain; a master off it where its first mimic
// stands), then each movable joint's coupling to them.
void Chain::resolveReadings() {
  std::map<std::string, int> chain_index, reading_of;
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    chain_index[joints_[i].name] = static_cast<int>(i);
  }
  if (const auto problem = mimicProblem(joints_)) {
    throw std::invalid_argument("chain: joint \"" +
                                joints_[static_cast<std::size_t>(problem->joint)].name +
                                "\": " + problem->message);
  }
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    const ChainJoint& joint = joints_[i];
    if (joint.mimic) {
      if (chain_index.count(joint.mimic->joint)) continue;  // the master's own reading
      if (reading_of.emplace(joint.mimic->joint, jointCount()).second) {
        readings_.push_back({joint.mimic->joint, joint.type, -1});
      }
    } else if (isMovable(joint.type)) {
      reading_of[joint.name] = jointCount();
      readings_.push_back({joint.name, joint.type, static_cast<int>(i)});
    }
  }
  couplings_.assign(joints_.size(), Coupling{});
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    const ChainJoint& joint = joints_[i];
    if (joint.mimic) {
      couplings_[i] = {reading_of.at(joint.mimic->joint), joint.mimic->multiplier,
                       joint.mimic->offset};
    } else if (isMovable(joint.type)) {
      couplings_[i].reading = reading_of.at(joint.name);
    }
  }
}

double Chain::jointValue(int chain_joint, const Eigen::VectorXd& p,
                         const Eigen::VectorXd& q) const {
  const Coupling& c = couplings_[static_cast<std::size_t>(chain_joint)];
  return c.scale * q[c.reading] + c.bias + p[offsets_[static_cast<std::size_t>(chain_joint)] + 6];
}

JointKind Chain::jointKind(int joint) const {
  return readings_[static_cast<std::size_t>(joint)].type == ChainJointType::Prismatic
             ? JointKind::Prismatic
             : JointKind::Revolute;
}

// Geometric Jacobian. With R the orientation before joint i and o_i = o + R xyz_i the pivot of
// its rotations (every rotation of T_i, Rz(yaw) Ry(pitch) Rx(roll) M_i, turns about a line
// through o_i):
//   dx/d(x, y, z)_i = R,
//   dx/dyaw_i   = a_yaw x (x - o_i),   a_yaw   = R e_z,
//   dx/dpitch_i = a_pitch x (x - o_i), a_pitch = R Rz(yaw) e_y,
//   dx/droll_i  = a_roll x (x - o_i),  a_roll  = R Rz(yaw) Ry(pitch) e_x,
//   dx/doffset_i = a_i x (x - o_i) (revolute) or a_i (prismatic), a_i the world axis;
//   dx/dq_r = sum over the joints i driven by reading r of scale_i dx/doffset_i (a mimic's
//   multiplier; 1 for the driving joint itself).
// Rotation columns hold their world axis until the tip is known, then the cross product.
//
// A reversed joint contributes M(-v) Rx(-roll) Ry(-pitch) Rz(-yaw) Trans(-xyz): its rotations turn
// about the point o_i reached after M (a prismatic M moves it), each column with its world axis
// negated, and its translation columns are -R after its turns.
ForwardStatus Chain::forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x,
                             Eigen::MatrixXd* J_x_p, Eigen::MatrixXd* J_x_q) const {
  Eigen::Matrix3d R;
  return forwardTipPose(0, p, q, x, R, J_x_p, J_x_q);
}

std::vector<std::string> Chain::stylusNames() const {
  std::vector<std::string> names;
  if (named_tips_)
    for (const ChainTip& tip : tips_) names.push_back(tip.name);
  return names;
}

ForwardStatus Chain::forwardStylus(int stylus, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                   Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p,
                                   Eigen::MatrixXd* J_x_q) const {
  Eigen::Matrix3d R;
  return forwardTipPose(stylus, p, q, x, R, J_x_p, J_x_q);
}

ForwardStatus Chain::forwardPose(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                 Eigen::VectorXd& x, Eigen::Matrix3d& R, Eigen::MatrixXd* J_x_p,
                                 Eigen::MatrixXd* J_x_q, Eigen::MatrixXd* J_w_p,
                                 Eigen::MatrixXd* J_w_q) const {
  return forwardTipPose(0, p, q, x, R, J_x_p, J_x_q, J_w_p, J_w_q);
}

// The angular Jacobians are the world axes of forward()'s rotation columns (yaw, pitch, roll,
// a revolute offset) before their cross product; translations do not turn the tip frame.
ForwardStatus Chain::forwardTipPose(int tip, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                    Eigen::VectorXd& x, Eigen::Matrix3d& R, Eigen::MatrixXd* J_x_p,
                                    Eigen::MatrixXd* J_x_q, Eigen::MatrixXd* J_w_p,
                                    Eigen::MatrixXd* J_w_q) const {
  const std::vector<int>& path = tips_.at(static_cast<std::size_t>(tip)).joints;
  const int n = static_cast<int>(joints_.size());
  const bool whole = static_cast<int>(path.size()) == n;  // every column is written
  R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d o = Eigen::Vector3d::Zero();
  ChainColumns pivots(3, n), joint_axes(3, n);
  Eigen::MatrixXd axes_only;  // the rotation axes when J_w_p is asked for without J_x_p
  if (J_w_p && !J_x_p) J_x_p = &axes_only;
  std::optional<Jacobian> Jp;
  if (J_x_p) {
    J_x_p->resize(3, parameterCount());
    if (!whole) J_x_p->setZero();
    Jp.emplace(J_x_p->data(), 3, parameterCount());
  }
  const OriginTurns& turns = originTurns(offsets_, p);
  // Joint i's origin turn about axis a (0 roll, 1 pitch, 2 yaw) by sign * its angle; none at 0.
  const auto turn = [&](int i, int a, double sign) {
    const std::size_t t = 3 * static_cast<std::size_t>(i) + static_cast<std::size_t>(a);
    if (turns.angles[t] == 0.0) return;
    const double c = turns.cos[t], s = sign * turns.sin[t];
    if (a == 0) turnAboutX(R, c, s);
    if (a == 1) turnAboutY(R, c, s);
    if (a == 2) turnAboutZ(R, c, s);
  };
  for (const int i : path) {
    const ChainJoint& joint = joints_[i];
    const int k = offsets_[i];
    if (joint.reversed) {
      if (isMovable(joint.type)) {
        const double value = jointValue(i, p, q);
        const Eigen::Vector3d axis = R * joint.axis;
        joint_axes.col(i) = -axis;
        if (Jp) Jp->col(k + 6) = -axis;
        if (joint.type == ChainJointType::Revolute) {
          turnAboutAxis(R, joint.axis, -value);
        } else {
          o -= axis * value;
        }
      }
      pivots.col(i) = o;
      if (Jp) Jp->col(k + 3) = -R.col(0);
      turn(i, 0, -1.0);
      if (Jp) Jp->col(k + 4) = -R.col(1);
      turn(i, 1, -1.0);
      if (Jp) Jp->col(k + 5) = -R.col(2);
      turn(i, 2, -1.0);
      if (Jp) Jp->middleCols<3>(k) = -R;
      o -= R * p.segment<3>(k);
      continue;
    }
    if (Jp) Jp->middleCols<3>(k) = R;
    o += R * p.segment<3>(k);
    pivots.col(i) = o;
    if (Jp) Jp->col(k + 5) = R.col(2);
    turn(i, 2, 1.0);
    if (Jp) Jp->col(k + 4) = R.col(1);
    turn(i, 1, 1.0);
    if (Jp) Jp->col(k + 3) = R.col(0);
    turn(i, 0, 1.0);
    if (!isMovable(joint.type)) continue;
    const double value = jointValue(i, p, q);
    const Eigen::Vector3d axis = R * joint.axis;
    joint_axes.col(i) = axis;
    if (Jp) Jp->col(k + 6) = axis;
    if (joint.type == ChainJointType::Revolute) {
      turnAboutAxis(R, joint.axis, value);
    } else {
      o += axis * value;
    }
  }
  x.resize(3);
  Eigen::Map<Eigen::Vector3d>(x.data()) = o;
  if (Jp)
    for (const int c : compliance_index_) Jp->col(c).setZero();  // forwardLoaded writes them
  if (J_w_p) {
    J_w_p->setZero(3, parameterCount());
    Jacobian Jw(J_w_p->data(), 3, parameterCount());
    for (const int i : path) {
      const int k = offsets_[i];
      Jw.middleCols<3>(k + 3) = Jp->middleCols<3>(k + 3);
      if (joints_[i].type == ChainJointType::Revolute) Jw.col(k + 6) = Jp->col(k + 6);
    }
  }
  if (J_w_q) {
    J_w_q->setZero(3, jointCount());
    Jacobian Jw(J_w_q->data(), 3, jointCount());
    for (const int i : path) {
      if (joints_[i].type != ChainJointType::Revolute) continue;
      const Coupling& c = couplings_[static_cast<std::size_t>(i)];
      Jw.col(c.reading) += c.scale * joint_axes.col(i);
    }
  }
  if (Jp) {
    for (const int i : path) {
      const int k = offsets_[i];
      for (int c = k + 3; c < k + 6; ++c)
        Jp->col(c) = tipColumn(true, Jp->col(c), pivots.col(i), o);
      if (joints_[i].type == ChainJointType::Revolute) {
        Jp->col(k + 6) = tipColumn(true, Jp->col(k + 6), pivots.col(i), o);
      }
    }
  }
  if (J_x_q) {
    J_x_q->setZero(3, jointCount());
    Jacobian Jq(J_x_q->data(), 3, jointCount());
    for (const int i : path) {
      const ChainJointType type = joints_[i].type;
      if (!isMovable(type)) continue;
      const Coupling& c = couplings_[static_cast<std::size_t>(i)];
      Jq.col(c.reading) += c.scale * tipColumn(type == ChainJointType::Revolute, joint_axes.col(i),
                                               pivots.col(i), o);
    }
  }
  return ForwardStatus::Ok;
}

// docs/compliance.md section 2 along tip 0's path: each movable joint's pivot and world axis as
// forwardTipPose() turns about them, each body's centre in the frame reached after its joint.
GravityGeometry Chain::gravityGeometry(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                       const Payload& payload) const {
  GravityGeometry out;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d o = Eigen::Vector3d::Zero();
  const std::vector<int>& path = tips_.front().joints;
  for (std::size_t position = 0; position < path.size(); ++position) {
    const int i = path[position];
    const ChainJoint& joint = joints_[static_cast<std::size_t>(i)];
    const Coupling& c = couplings_[static_cast<std::size_t>(i)];
    const int k = offsets_[static_cast<std::size_t>(i)];
    const int at = static_cast<int>(position);
    const bool revolute = joint.type == ChainJointType::Revolute;
    if (joint.reversed) {
      if (isMovable(joint.type)) {
        const double value = jointValue(i, p, q);
        const Eigen::Vector3d axis = R * joint.axis;
        if (revolute)
          turnAboutAxis(R, joint.axis, -value);
        else
          o -= axis * value;
        out.axes.push_back({o, -axis, revolute, at, c.reading, c.scale});
      }
      turnAboutX(R, -p[k + 3]);
      turnAboutY(R, -p[k + 4]);
      turnAboutZ(R, -p[k + 5]);
      o -= R * p.segment<3>(k);
    } else {
      o += R * p.segment<3>(k);
      turnAboutZ(R, p[k + 5]);
      turnAboutY(R, p[k + 4]);
      turnAboutX(R, p[k + 3]);
      if (isMovable(joint.type)) {
        const double value = jointValue(i, p, q);
        const Eigen::Vector3d axis = R * joint.axis;
        out.axes.push_back({o, axis, revolute, at, c.reading, c.scale});
        if (revolute)
          turnAboutAxis(R, joint.axis, value);
        else
          o += axis * value;
      }
    }
    const MassPoint& link = compliance_->masses[static_cast<std::size_t>(i)];
    if (link.mass != 0.0) out.bodies.push_back({o + R * link.centre, link.mass, at});
  }
  if (payload.mass != 0.0)
    out.bodies.push_back({o + R * payload.centre, payload.mass, static_cast<int>(path.size())});
  return out;
}

// The frames of forward() without the Jacobians: each joint's origin, then the probe.
std::vector<Eigen::VectorXd> Chain::skeleton(const Eigen::VectorXd& p,
                                             const Eigen::VectorXd& q) const {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d o = Eigen::Vector3d::Zero();
  std::vector<Eigen::VectorXd> points{o};
  for (const int i : tips_.front().joints) {
    const ChainJoint& joint = joints_[static_cast<std::size_t>(i)];
    const int k = offsets_[static_cast<std::size_t>(i)];
    if (joint.reversed) {
      if (joint.type == ChainJointType::Revolute) {
        turnAboutAxis(R, joint.axis, -jointValue(i, p, q));
      } else if (joint.type == ChainJointType::Prismatic) {
        o -= R * joint.axis * jointValue(i, p, q);
      }
      turnAboutX(R, -p[k + 3]);
      turnAboutY(R, -p[k + 4]);
      turnAboutZ(R, -p[k + 5]);
      o -= R * p.segment<3>(k);
      points.push_back(o);
      continue;
    }
    o += R * p.segment<3>(k);
    points.push_back(o);
    turnAboutZ(R, p[k + 5]);
    turnAboutY(R, p[k + 4]);
    turnAboutX(R, p[k + 3]);
    if (!isMovable(joint.type)) continue;
    const double value = jointValue(i, p, q);
    if (joint.type == ChainJointType::Revolute) {
      turnAboutAxis(R, joint.axis, value);
    } else {
      o += R * joint.axis * value;
    }
  }
  points.push_back(o);
  return points;
}

}  // namespace artcal
