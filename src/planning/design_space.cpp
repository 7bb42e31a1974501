#include "artcal/planning/design_space.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "artcal/core/error.hpp"
#include "artcal/core/random.hpp"
#include "artcal/estimation/plane_rows.hpp"
#include "artcal/model/inverse_kinematics.hpp"
#include "artcal/planning/plane_touches.hpp"

namespace artcal {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kAngleBound = 4 * kPi;  // angles are free; the bound only serves BOBYQA

// The centre may go wherever a feature may: the region's bounding box.
std::array<Eigen::VectorXd, 2> regionExtent(const Region& region, int dimension) {
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(dimension, -1e300);
  Eigen::VectorXd hi = Eigen::VectorXd::Constant(dimension, 1e300);
  if (region.reach) {
    lo.setConstant(-(*region.reach)[1]);
    hi.setConstant((*region.reach)[1]);
  }
  if (region.box) {
    lo = lo.cwiseMax((*region.box)[0].cwiseMin((*region.box)[1]));
    hi = hi.cwiseMin((*region.box)[0].cwiseMax((*region.box)[1]));
  }
  return {lo, hi};
}

}  // namespace

Eigen::VectorXd defaultJointMargin(const Mechanism& mechanism) {
  Eigen::VectorXd margin(mechanism.jointCount());
  for (int i = 0; i < margin.size(); ++i) {
    margin[i] = mechanism.jointKind(i) == JointKind::Revolute ? degToRad(kDefaultRevoluteMarginDeg)
                                                              : kDefaultPrismaticMarginMm;
  }
  return margin;
}

// The machine whose joint limits are narrowed by `margin` (internal units, per joint). A
// revolute joint with a full turn of range or more wraps and keeps its limits; a margin that
// would leave less than half of a joint's range is cut to a quarter of the range.
Machine withJointMargin(const Machine& machine, const Eigen::VectorXd& margin) {
  Machine narrowed = machine;
  for (int i = 0; i < margin.size(); ++i) {
    auto& [lo, hi] = narrowed.joint_limits[static_cast<std::size_t>(i)];
    const bool wraps =
        machine.mechanism->jointKind(i) == JointKind::Revolute && hi - lo >= 2 * kPi - 1e-12;
    if (wraps) continue;
    const double m = std::min(margin[i], 0.25 * (hi - lo));
    lo += m;
    hi -= m;
  }
  return narrowed;
}

DesignSpace::DesignSpace(const Plan& plan) : plan_(&plan) {
  if (!plan.design) throw InputError(plan.source, "/design", "the spec has no design block");
  const DesignSpec& spec = *plan.design;
  reading_machine_ =
      withJointMargin(plan.machine, spec.joint_margin.size() == plan.machine.jointCount()
                                        ? spec.joint_margin
                                        : defaultJointMargin(*plan.machine.mechanism));
  if (artifact().dimension != dimension()) {
    throw InputError(plan.source, "/design/artifact",
                     "the artifact's dimension does not match the machine's");
  }
  if (!spec.region.reach && !spec.region.box) {
    throw InputError(plan.source, "/design/region", "expected \"reach\" and/or \"box\"");
  }
  const int most_postures = plan.machine.mechanism->posturesPerPoint();
  if (most_postures > 0 && spec.postures > most_postures) {
    throw InputError(plan.source, "/design/postures",
                     plan.machine.mechanism->modelName() + " has " + std::to_string(most_postures) +
                         " postures per point, got " + std::to_string(spec.postures));
  }
  has_roll_ = dimension() == 3 && artifact().kind().design_rolls;
  if (artifact().translatesOnly()) commanded_ = plan.machine.mechanism->commandedJoints();
  const auto [lo, hi] = regionExtent(spec.region, dimension());
  if ((lo.array() > hi.array()).any()) {
    throw InputError(plan.source, "/design/region", "the region is empty");
  }
  lower_ = Eigen::VectorXd::Constant(poseSize(), -kAngleBound);
  upper_ = Eigen::VectorXd::Constant(poseSize(), kAngleBound);
  lower_.head(dimension()) = lo;
  upper_.head(dimension()) = hi;
  // Commanded joints: within the reading machine's limits.
  const int c = static_cast<int>(commanded_.size());
  for (int k = 0; k < spec.postures; ++k) {
    for (int j = 0; j < c; ++j) {
      const auto [joint_lo, joint_hi] =
          reading_machine_
              .joint_limits[static_cast<std::size_t>(commanded_[static_cast<std::size_t>(j)])];
      lower_[dimension() + k * c + j] = joint_lo;
      upper_[dimension() + k * c + j] = joint_hi;
    }
  }
}

const Artifact& DesignSpace::artifact() const {
  return plan_->artifacts[static_cast<std::size_t>(design().artifact)];
}

int DesignSpace::poseSize() const {
  if (!commanded_.empty())
    return dimension() + design().postures * static_cast<int>(commanded_.size());
  return dimension() == 2 ? 3 : (has_roll_ ? 6 : 5);
}

Eigen::VectorXd DesignSpace::initialSteps() const {
  // A tenth of the region's extent for the centre, 0.2 rad for angles.
  Eigen::VectorXd steps = Eigen::VectorXd::Constant(poseSize(), 0.2);
  steps.head(dimension()) =
      (0.1 * (upper_ - lower_).head(dimension())).cwiseMin(50.0).cwiseMax(1.0);
  // Commanded prismatic joints as the centre; revolute ones 0.2 rad as the angles.
  const int c = static_cast<int>(commanded_.size());
  for (int i = dimension(); c > 0 && i < poseSize(); ++i) {
    const int joint = commanded_[static_cast<std::size_t>((i - dimension()) % c)];
    if (plan_->machine.mechanism->jointKind(joint) == JointKind::Prismatic)
      steps[i] = std::clamp(0.1 * (upper_[i] - lower_[i]), 1.0, 50.0);
  }
  return steps;
}

namespace {

Eigen::Vector3d directionOf(double azimuth, double elevation) {
  return {std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
          std::sin(elevation)};
}

}  // namespace

RigidTransform DesignSpace::transformOf(const Eigen::VectorXd& v) const {
  if (!commanded_.empty()) return placeSpatial(v.head<3>(), Eigen::Vector3d::UnitX(), 0.0);
  if (dimension() == 2) return placePlanar(v.head<2>(), v[2]);
  return placeSpatial(v.head<3>(), directionOf(v[3], v[4]), has_roll_ ? v[5] : 0.0);
}

Pose DesignSpace::poseOf(const Eigen::VectorXd& v) const {
  Pose pose;
  pose.center = v.head(dimension());
  if (!commanded_.empty()) return pose;  // a sphere: its centre only
  if (dimension() == 2) {
    pose.angle = std::remainder(v[2], 2 * kPi);
  } else {
    pose.direction = directionOf(v[3], v[4]);
    pose.roll = has_roll_ ? std::remainder(v[5], 2 * kPi) : 0.0;
  }
  return pose;
}

Eigen::MatrixXd DesignSpace::featurePositions(const Eigen::VectorXd& v) const {
  // The transform maps machine -> artifact (W = R x + t); features go the other way.
  const RigidTransform artifact_to_machine = transformOf(v).inverse();
  const Eigen::MatrixXd& W = artifact().features;
  Eigen::MatrixXd x(W.rows(), W.cols());
  for (int i = 0; i < W.cols(); ++i) x.col(i) = artifact_to_machine.apply(W.col(i));
  return x;
}

double DesignSpace::regionViolation(const Eigen::VectorXd& v) const {
  const Region& region = design().region;
  const Eigen::MatrixXd x = featurePositions(v);
  double violation = 0.0;
  for (int i = 0; i < x.cols(); ++i) {
    if (region.reach) {
      const double r = x.col(i).norm();
      violation += std::max(0.0, (*region.reach)[0] - r) + std::max(0.0, r - (*region.reach)[1]);
    }
    if (region.box) {
      const Eigen::VectorXd lo = (*region.box)[0].cwiseMin((*region.box)[1]);
      const Eigen::VectorXd hi = (*region.box)[0].cwiseMax((*region.box)[1]);
      violation += (lo - x.col(i)).cwiseMax(0.0).sum() + (x.col(i) - hi).cwiseMax(0.0).sum();
    }
  }
  return violation;
}

Eigen::VectorXd DesignSpace::randomPose(std::mt19937_64& rng) const {
  Eigen::VectorXd v(poseSize());
  for (int i = 0; i < dimension(); ++i)
    v[i] = lower_[i] + (upper_[i] - lower_[i]) * unitUniform(rng);
  if (!commanded_.empty()) {
    for (int i = dimension(); i < poseSize(); ++i)
      v[i] = lower_[i] + (upper_[i] - lower_[i]) * unitUniform(rng);
    return v;
  }
  if (dimension() == 2) {
    v[2] = kPi * (2 * unitUniform(rng) - 1);
  } else {
    v[3] = kPi * (2 * unitUniform(rng) - 1);
    v[4] = std::asin(2 * unitUniform(rng) - 1);  // uniform directions on the sphere
    if (has_roll_) v[5] = kPi * (2 * unitUniform(rng) - 1);
  }
  return v;
}

namespace {

// A Cartesian CMM has one posture per stylus (docs/models.md section 4): the point read with styli
// 0 .. count - 1; fewer when a stylus cannot reach it within the axis ranges.
std::vector<Measurement> stylusPostures(const Machine& machine, int feature,
                                        const Eigen::VectorXd& target, int count) {
  std::vector<Measurement> out;
  const int styli = std::min(count, machine.mechanism->stylusCount());
  for (int s = 0; s < styli; ++s) {
    IkOptions options;
    options.stylus = s;
    if (auto q = solveInverseKinematics(machine, machine.nominal, target, target, options)) {
      out.push_back({feature, *q, s});
    }
  }
  return out;
}

}  // namespace

std::vector<Measurement> featureReadings(const Machine& reading_machine, int feature,
                                         const Eigen::VectorXd& target, int count,
                                         std::mt19937_64& rng, int stylus) {
  if (stylus >= 0) {
    IkOptions options;
    options.stylus = stylus;
    std::vector<Measurement> out;
    for (Eigen::VectorXd& q :
         posturesFor(reading_machine, reading_machine.nominal, target, count, rng, options))
      out.push_back({feature, std::move(q), stylus});
    return out;
  }
  if (reading_machine.mechanism->stylusCount() > 1)
    return stylusPostures(reading_machine, feature, target, count);
  std::vector<Measurement> out;
  for (Eigen::VectorXd& q :
       posturesFor(reading_machine, reading_machine.nominal, target, count, rng))
    out.push_back({feature, std::move(q)});
  return out;
}

std::optional<Placement> DesignSpace::commandedPlacement(const Eigen::VectorXd& v) const {
  if (regionViolation(v) > 0.0) return std::nullopt;
  const Eigen::MatrixXd x = featurePositions(v);
  const Machine& machine = reading_machine_;
  Placement placement;
  placement.artifact = design().artifact;
  placement.pose = poseOf(v);
  const int c = static_cast<int>(commanded_.size());
  // The free joints start at the middle of their limits; the commanded ones are the pose's.
  Eigen::VectorXd q0(machine.jointCount());
  for (int i = 0; i < q0.size(); ++i) {
    const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
    q0[i] = 0.5 * (lo + hi);
  }
  for (int i = 0; i < x.cols(); ++i) {
    for (int k = 0; k < design().postures; ++k) {
      for (int j = 0; j < c; ++j) {
        const int at = dimension() + k * c + j;
        if (v[at] < lower_[at] || v[at] > upper_[at]) return std::nullopt;
        q0[commanded_[static_cast<std::size_t>(j)]] = v[at];
      }
      auto q = solveHoldingJoints(machine, machine.nominal, x.col(i), q0, commanded_);
      if (!q) return std::nullopt;
      placement.measurements.push_back({i, std::move(*q)});
    }
  }
  return placement;
}

std::optional<Placement> DesignSpace::placeWithNewPostures(const Eigen::VectorXd& v,
                                                           std::mt19937_64& rng) const {
  if (!commanded_.empty()) return commandedPlacement(v);
  if (regionViolation(v) > 0.0) return std::nullopt;
  const Eigen::MatrixXd x = featurePositions(v);
  Placement placement;
  placement.artifact = design().artifact;
  placement.pose = poseOf(v);
  const bool plane = artifact().kind().touches_faces;
  // A plane's face is touched at points spread over it (plane_touches.hpp), on a machine with
  // named tips (docs/urdf.md) by each tip in turn; a ball at its centre (featureReadings: one
  // posture per tip).
  const int tips =
      plane ? std::max(1, static_cast<int>(reading_machine_.mechanism->stylusNames().size())) : 1;
  for (int i = 0; i < x.cols(); ++i) {
    for (int t = 0; t < tips; ++t) {
      const int count = design().postures / tips + (t < design().postures % tips ? 1 : 0);
      if (count == 0) continue;
      const int stylus = tips > 1 ? t : -1;
      const auto readings =
          plane ? planeTouches(reading_machine_, artifact(),
                               poseTransform(dimension(), *placement.pose), i, count, rng, stylus)
                : featureReadings(reading_machine_, i, x.col(i), count, rng);
      if (static_cast<int>(readings.size()) < count) return std::nullopt;
      placement.measurements.insert(placement.measurements.end(), readings.begin(), readings.end());
    }
  }
  return placement;
}

std::optional<Placement> DesignSpace::movePlacement(const Placement& previous,
                                                    const Eigen::VectorXd& v) const {
  if (!commanded_.empty()) return commandedPlacement(v);
  if (regionViolation(v) > 0.0) return std::nullopt;
  const Eigen::MatrixXd x = featurePositions(v);
  Placement placement;
  placement.artifact = previous.artifact;
  placement.pose = poseOf(v);
  const bool plane = artifact().kind().touches_faces;
  const RigidTransform before =
      plane ? poseTransform(dimension(), *previous.pose) : RigidTransform{};
  const RigidTransform after =
      plane ? poseTransform(dimension(), *placement.pose) : RigidTransform{};
  for (const Measurement& m : previous.measurements) {
    IkOptions options;
    options.stylus = m.stylus;
    // A plane's touch keeps its point on the face (artifact frame) as the face moves.
    Eigen::VectorXd target = x.col(m.feature);
    Eigen::Vector3d on_face = Eigen::Vector3d::Zero();  // artifact frame
    if (plane) {
      forwardOrThrow(*reading_machine_.mechanism, reading_machine_.nominal, m.joints, target,
                     nullptr, nullptr, m.stylus);
      on_face = before.apply(target);
      target = after.inverse().apply(on_face);
    }
    auto q = solveInverseKinematics(reading_machine_, reading_machine_.nominal, target, m.joints,
                                    options);
    if (q && plane && artifact().plane.flush) {
      q = touchPlane(artifact(), reading_machine_, reading_machine_.nominal, {m.feature, *q}, after,
                     Eigen::VectorXd(), Eigen::VectorXd::Zero(3), on_face);
      if (q && !reading_machine_.withinLimits(*q)) q.reset();
    }
    if (!q) return std::nullopt;
    placement.measurements.push_back({m.feature, *q, m.stylus});
  }
  return placement;
}

std::optional<std::pair<Eigen::VectorXd, Placement>> DesignSpace::randomPlacement(
    std::mt19937_64& rng, int attempts) const {
  for (int a = 0; a < attempts; ++a) {
    Eigen::VectorXd v = randomPose(rng);
    if (auto placement = placeWithNewPostures(v, rng)) return std::pair{std::move(v), *placement};
  }
  return std::nullopt;
}

}  // namespace artcal
