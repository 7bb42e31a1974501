#include "artcal/planning/procedure.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "artcal/artifact/rigid_transform.hpp"
#include "artcal/core/error.hpp"
#include "artcal/estimation/design_matrix.hpp"
#include "artcal/model/inverse_kinematics.hpp"

namespace artcal {

namespace {

/// Within this distance (mm) of its placed feature a plan's reading is taken as the target as it
/// is; otherwise the target is solved from it.
constexpr double kOnFeature = 1e-10;

/// The pose (centre, direction, roll) of a machine-from-artifact transform x = R W + t: the
/// inverse of placePlanar / placeSpatial (rigid_transform.hpp).
Pose poseOf(const RigidTransform& artifact_from_machine) {
  const RigidTransform machine = artifact_from_machine.inverse();
  Pose pose;
  pose.center = machine.t;
  if (machine.dimension() == 2) {
    pose.angle = std::atan2(machine.R(1, 0), machine.R(0, 0));
    return pose;
  }
  const Eigen::Vector3d ex = machine.R.col(0);
  const Eigen::Vector3d ey = machine.R.col(1);
  // The zero-roll Y axis of placeSpatial; the roll turns it about ex onto ey.
  const Eigen::Matrix3d zero_roll = placeSpatial(Eigen::Vector3d::Zero(), ex, 0.0).R.transpose();
  const Eigen::Vector3d ey0 = zero_roll.col(1);
  pose.direction = ex;
  pose.roll = std::atan2(ey0.cross(ey).dot(ex), ey0.dot(ey));
  return pose;
}

ProcedureReading targetOf(const Plan& plan, const Measurement& m, const Eigen::VectorXd& position,
                          const ReadingLocation& where) {
  const Machine& machine = plan.machine;
  ProcedureReading reading;
  reading.feature = m.feature;
  reading.stylus = m.stylus;
  reading.position = position;
  Eigen::VectorXd x;
  const bool planned_ok =
      machine.mechanism->forwardStylus(m.stylus, machine.nominal, m.joints, x) == ForwardStatus::Ok;
  reading.planned_offset =
      planned_ok ? (x - position).norm() : std::numeric_limits<double>::infinity();
  if (reading.planned_offset <= kOnFeature) {
    reading.target = m.joints;
    return reading;
  }
  IkOptions options;
  options.stylus = m.stylus;
  options.max_iterations = 500;
  // A machine tool's rotary axes are commanded: the slides are solved at the planned positions.
  const std::vector<int> commanded = machine.mechanism->commandedJoints();
  const auto solved =
      commanded.empty()
          ? solveInverseKinematics(machine, machine.nominal, position, m.joints, options)
          : solveHoldingJoints(machine, machine.nominal, position, m.joints, commanded, options);
  if (!solved) {
    throw RunError(where.file, where.where,
                   "no joint values within the limits put the probe on feature " +
                       std::to_string(m.feature) + " at the placement's pose");
  }
  reading.target = *solved;
  return reading;
}

}  // namespace

Procedure operatorProcedure(const Plan& plan) {
  const std::vector<RigidTransform> fitted =
      fitPlacements(plan, plan.placements, plan.machine.nominal);
  Procedure procedure;
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const Placement& placement = plan.placements[j];
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    ProcedurePlacement out;
    out.artifact = placement.artifact;
    out.pose_from_plan = placement.pose.has_value();
    out.pose = placement.pose ? *placement.pose : poseOf(fitted[j]);
    out.features = placedFeatures(artifact, out.pose);
    const Eigen::MatrixXd& features = out.features;
    std::map<int, int> postures;
    for (std::size_t k = 0; k < placement.measurements.size(); ++k) {
      const Measurement& m = placement.measurements[k];
      // A plane's touch lands anywhere on its face (docs/planes.md): its target is the planned
      // point itself, the nominal probe at the planned joints, not the face's middle.
      Eigen::VectorXd touch;
      const bool touched =
          artifact.kind().touches_faces &&
          plan.machine.mechanism->forwardStylus(m.stylus, plan.machine.nominal, m.joints, touch) ==
              ForwardStatus::Ok;
      ProcedureReading reading =
          targetOf(plan, m, touched ? touch : features.col(m.feature), readingLocation(plan, j, k));
      reading.posture = postures[m.feature]++;
      out.readings.push_back(std::move(reading));
    }
    procedure.placements.push_back(std::move(out));
  }
  return procedure;
}

}  // namespace artcal
