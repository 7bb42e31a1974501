#include "artcal/calibration/simulation.hpp"

#include <cmath>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "artcal/core/error.hpp"
#include "artcal/core/random.hpp"
#include "artcal/estimation/design_matrix.hpp"
#include "artcal/estimation/plane_rows.hpp"
#include "artcal/estimation/reading_noise.hpp"
#include "artcal/model/rotation_vector.hpp"

namespace artcal {

double NormalSource::uniform() {
  return unitUniformNonZero(engine_);  // never zero: the logarithm below is finite
}

double NormalSource::operator()() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double radius = std::sqrt(-2.0 * std::log(uniform()));
  const double angle = 2.0 * std::numbers::pi * uniform();
  spare_ = radius * std::sin(angle);
  has_spare_ = true;
  return radius * std::cos(angle);
}

namespace {
std::uint64_t splitMix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}
}  // namespace

std::uint64_t trialSeed(std::uint64_t seed, std::uint64_t trial) {
  return splitMix64(splitMix64(seed) ^ splitMix64(trial + 0x632be59bd9b4e019ull));
}

bool SimulationOptions::isValid(std::string* error) const {
  if (!(noise_scale >= 0.0) || !std::isfinite(noise_scale)) {
    if (error) *error = "noise_scale must be a finite number >= 0";
    return false;
  }
  return true;
}

namespace {

// The limits of `joint` (all joints when -1) opened by a full turn and the range on each side.
Machine withLimitsOpened(const Machine& machine, int joint) {
  Machine open = machine;
  for (std::size_t i = 0; i < open.joint_limits.size(); ++i) {
    if (joint >= 0 && static_cast<int>(i) != joint) continue;
    auto& [lo, hi] = open.joint_limits[i];
    const double widen = (hi - lo) + 2 * std::numbers::pi;
    lo -= widen;
    hi += widen;
  }
  return open;
}

// q moved by whole turns (a revolute joint) to the value nearest the machine's limits: inverse
// kinematics with opened limits wraps angles anywhere in the opened range.
Eigen::VectorXd nearestToLimits(const Machine& machine, Eigen::VectorXd q) {
  constexpr double kTurn = 2 * std::numbers::pi;
  for (int i = 0; i < q.size(); ++i) {
    if (machine.mechanism->jointKind(i) != JointKind::Revolute) continue;
    const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
    const double centre = 0.5 * (lo + hi);
    q[i] = centre + std::remainder(q[i] - centre, kTurn);
  }
  return q;
}

// The joint of q farthest outside the machine's limits (-1 when q is within all of them).
std::pair<int, double> farthestOutside(const Machine& machine, const Eigen::VectorXd& q) {
  int worst = -1;
  double worst_excess = 0.0;
  for (int i = 0; i < q.size(); ++i) {
    const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
    const double excess = std::max(lo - q[i], q[i] - hi);
    if (excess > worst_excess) {
      worst = i;
      worst_excess = excess;
    }
  }
  return {worst, worst_excess};
}

// The reading of one point by the simulated machine, or why there is none.
struct SimulatedReading {
  std::optional<Eigen::VectorXd> q;
  std::string why;  ///< when q is empty
};

// Inverse kinematics within the limits from the planned reading. The damped solver clamps at
// the limits and can stall at one it need not touch; the same solve with one joint's limits opened
// at a time, then all of them, may land within the limits, and that is the reading. Otherwise why:
// the joint whose limits alone block (the least excess when several do), with the value it would
// need at its representative nearest the limits; failing that, the joint farthest out with every
// limit open (a redundant arm, a 7-joint Panda reading a 3-D point, drifts in its null space then,
// so it comes second); no solution even then: out of reach.
SimulatedReading simulatedReading(const Machine& machine, const Eigen::VectorXd& p,
                                  const Eigen::VectorXd& target, const Eigen::VectorXd& q0,
                                  const IkOptions& options) {
  if (auto q = solveInverseKinematics(machine, p, target, q0, options)) return {std::move(q), {}};
  int worst = -1;
  double worst_excess = 0.0, value = 0.0;
  bool any_solution = false;
  for (int opened = 0; opened <= machine.jointCount(); ++opened) {
    const bool all = opened == machine.jointCount();
    auto q = solveInverseKinematics(withLimitsOpened(machine, all ? -1 : opened), p, target, q0,
                                    options);
    if (!q) continue;
    any_solution = true;
    q = nearestToLimits(machine, *q);
    if (machine.withinLimits(*q)) return {std::move(q), {}};
    const auto [joint, excess] = farthestOutside(machine, *q);
    if (joint >= 0 && (worst < 0 || (!all && excess < worst_excess))) {
      worst = joint;
      worst_excess = excess;
      value = (*q)[joint];
    }
  }
  if (!any_solution)
    return {{}, "out of its reach (inverse kinematics found no joint values at all)"};
  const Quantity unit = jointQuantity(machine.mechanism->jointKind(worst));
  const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(worst)];
  auto file = [&](double v) {
    std::ostringstream out;
    out << toFileUnit(unit, v);
    return out.str();
  };
  return {{},
          "joint " + std::to_string(worst + 1) + " would have to read " + file(value) + " " +
              std::string(unitName(unit)) + ", outside its limits [" + file(lo) + ", " + file(hi) +
              "] (plan the readings farther inside the limits: design.joint_margin)"};
}

// An instrument's station (instruments.md): the machine drives to the planned configurations
// q, the instrument reports the true tip in its frame, point = r_j f(p_true, q) + its noise and
// the probe's (each coordinate drawn), and the joints read q + delta_q. A pose instrument also
// reports the true orientation turned by its angular noise n: exp([n]x) R_r R(p_true, q), whose
// residual against the truth is -n. Draw order per reading: the d point deviates, a pose's 3
// angular deviates, then the joint deviates.
void simulateStation(const Plan& plan, const Eigen::VectorXd& p_true, const RigidTransform& station,
                     const Artifact& instrument, double scale, Placement& placement,
                     NormalSource& normal) {
  const double point_sigma = scale * std::hypot(plan.noise.probe, instrument.noise);
  const double angle_sigma =
      scale * std::sqrt(readingAngleVariance(plan.noise.probe, plan.noise.estimate_probe,
                                             instrument.noise, instrument.noise_angle));
  Eigen::VectorXd x;
  Eigen::Matrix3d R;
  for (Measurement& m : placement.measurements) {
    if (instrument.measures_pose)
      forwardReadingPoseOrThrow(plan.machine, p_true, m, x, R);
    else
      forwardReadingOrThrow(plan.machine, p_true, m, x);
    m.point = station.apply(x);
    m.point_given = true;
    for (int k = 0; k < m.point.size(); ++k) m.point[k] += point_sigma * normal();
    if (instrument.measures_pose) {
      Eigen::Vector3d n;
      for (int k = 0; k < 3; ++k) n[k] = angle_sigma * normal();
      m.orientation = rotationVector(Eigen::Matrix3d(rotationFromVector(n) * station.R * R));
    }
    for (int k = 0; k < m.joints.size(); ++k)
      m.joints[k] += scale * plan.noise.encoder[k] * normal();
  }
}

// A plane's touches (docs/planes.md): from each planned configuration the true machine moves as
// little as it can until it touches the true face (a flush contact: lies flush on it), at the
// drawn probing error along the normal (and the drawn tilts); the joints read q + delta_q. Draw
// order per reading: the distance row's deviate, a flush contact's 2 tilt deviates, the joints'.
void simulateTouches(const Plan& plan, const Eigen::VectorXd& p_true, const RigidTransform& pose,
                     const Artifact& artifact, const Eigen::VectorXd& c, double scale,
                     std::size_t placement_index, Placement& placement, NormalSource& normal) {
  const double distance_sigma = scale * std::hypot(plan.noise.probe, artifact.noise);
  const double tilt_sigma =
      scale * std::sqrt(readingAngleVariance(plan.noise.probe, plan.noise.estimate_probe,
                                             artifact.noise, artifact.noise_angle));
  const int rows = artifact.rowsPerReading();
  Eigen::VectorXd offsets(rows);
  for (std::size_t i = 0; i < placement.measurements.size(); ++i) {
    Measurement& m = placement.measurements[i];
    for (int k = 0; k < rows; ++k) offsets[k] = (k == 0 ? distance_sigma : tilt_sigma) * normal();
    const std::optional<Eigen::VectorXd> q =
        touchPlane(artifact, plan.machine, p_true, m, pose, c, offsets);
    if (!q) {
      const ReadingLocation location = readingLocation(plan, placement_index, i);
      throw RunError(location.file, location.where,
                     "the simulated machine cannot touch the plane from this reading's joints");
    }
    m.joints = *q;
    for (int k = 0; k < m.joints.size(); ++k)
      m.joints[k] += scale * plan.noise.encoder[k] * normal();
  }
}

}  // namespace

Simulator::Simulator(const Plan& plan, const SimulationOptions& options)
    : plan_(&plan), options_(options) {
  std::string error;
  if (!options_.isValid(&error)) throw std::invalid_argument("simulation options: " + error);
  poses_ = fitPlacements(plan, plan.placements, plan.machine.nominal);
  for (const RigidTransform& pose : poses_) inverse_poses_.push_back(pose.inverse());
}

namespace {

// The joints a reading shows when the true machine sits at `deflected` under its load: q with
// q + C tau(q) = deflected (docs/compliance.md section 3), by fixed-point steps (tau changes
// with q at second order); `deflected` itself without compliance.
Eigen::VectorXd undeflected(const Machine& machine, const Eigen::VectorXd& p_true,
                            const Eigen::VectorXd& deflected, Measurement m) {
  const JointCompliance* compliance = machine.mechanism->jointCompliance();
  if (!compliance) return deflected;
  const std::vector<int>& index = compliance->complianceParameters();
  m.joints = deflected;
  for (int step = 0; step < 4; ++step) {
    const Eigen::VectorXd tau = readingTorques(machine, m);
    for (int r = 0; r < tau.size(); ++r)
      m.joints[r] = deflected[r] - p_true[index[static_cast<std::size_t>(r)]] * tau[r];
  }
  return m.joints;
}

}  // namespace

SimulatedRun Simulator::simulate(const Eigen::VectorXd& p_true, NormalSource& normal) const {
  const Plan& plan = *plan_;
  const Machine& machine = plan.machine;
  const double scale = options_.noise_scale;
  SimulatedRun run;
  // One draw per physical artifact's systematic error (docs/method.md section 2).
  std::vector<Eigen::VectorXd> artifact_c;
  std::vector<double> drawn;
  for (const Artifact& artifact : plan.artifacts) {
    Eigen::VectorXd c = Eigen::VectorXd::Zero(artifact.systematicCount());
    for (int s = 0; s < c.size(); ++s) {
      if (options_.artifact_errors)
        c[s] = scale * artifact.systematic[static_cast<std::size_t>(s)].sigma * normal();
      drawn.push_back(c[s]);
    }
    artifact_c.push_back(c);
  }
  run.systematic = Eigen::Map<Eigen::VectorXd>(drawn.data(), static_cast<int>(drawn.size()));
  run.placements = plan.placements;
  const int d = machine.dimension();
  Eigen::VectorXd target(d);
  // A probing cycle commands these joints (a machine tool's rotary axes): they read as planned.
  const std::vector<int> commanded = machine.mechanism->commandedJoints();
  Eigen::VectorXd delta(machine.jointCount());
  for (std::size_t j = 0; j < run.placements.size(); ++j) {
    Placement& placement = run.placements[j];
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    const Eigen::VectorXd& c = artifact_c[static_cast<std::size_t>(placement.artifact)];
    if (artifact.kind().readings_are_features) {
      simulateStation(plan, p_true, poses_[j], artifact, scale, placement, normal);
      continue;
    }
    if (artifact.kind().touches_faces) {
      simulateTouches(plan, p_true, poses_[j], artifact, c, scale, j, placement, normal);
      continue;
    }
    for (std::size_t i = 0; i < placement.measurements.size(); ++i) {
      Measurement& m = placement.measurements[i];
      target = inverse_poses_[j].apply(artifact.feature(m.feature, c));
      for (int k = 0; k < d; ++k) target[k] += scale * plan.noise.probe * normal();
      IkOptions ik = options_.ik;
      ik.stylus = m.stylus;
      // The joints' deviates (drawn before the solve; the draw order is unchanged): each reads
      // its true value plus its deviate.
      for (int k = 0; k < delta.size(); ++k) delta[k] = scale * plan.noise.encoder[k] * normal();
      if (!commanded.empty()) {
        // A commanded joint reads its planned value exactly and truly sits at that value less
        // its deviate; the other joints are solved there and read with their deviates.
        Eigen::VectorXd q0 = m.joints;
        for (int k : commanded) q0[k] -= delta[k];
        std::optional<Eigen::VectorXd> q =
            solveHoldingJoints(machine, p_true, target, q0, commanded, ik);
        if (!q) {
          const ReadingLocation location = readingLocation(plan, j, i);
          throw RunError(location.file, location.where,
                         "the simulated machine cannot reach this reading's point with its "
                         "commanded axes at their planned positions (a slide would leave its "
                         "limits: plan the readings farther inside them, design.joint_margin)");
        }
        *q += delta;
        for (int k : commanded) (*q)[k] = m.joints[k];
        m.joints = *q;
        continue;
      }
      SimulatedReading reading = simulatedReading(machine, p_true, target, m.joints, ik);
      if (!reading.q) {
        const ReadingLocation location = readingLocation(plan, j, i);
        throw RunError(location.file, location.where,
                       "the simulated machine cannot reach this reading's point: " + reading.why);
      }
      m.joints = undeflected(machine, p_true, *reading.q, m) + delta;
    }
  }
  attachTorques(machine, run.placements);
  return run;
}

}  // namespace artcal
