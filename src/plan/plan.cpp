#include "artcal/plan/plan.hpp"

#include <filesystem>
#include <stdexcept>

#include "artcal/model/rotation_vector.hpp"

namespace artcal {

bool Region::contains(const Eigen::VectorXd& x) const {
  if (reach) {
    const double r = x.norm();
    if (r < (*reach)[0] || r > (*reach)[1]) return false;
  }
  if (box) {
    for (int i = 0; i < x.size(); ++i) {
      const double lo = std::min((*box)[0][i], (*box)[1][i]);
      const double hi = std::max((*box)[0][i], (*box)[1][i]);
      if (x[i] < lo || x[i] > hi) return false;
    }
  }
  return true;
}

Eigen::VectorXd readingTarget(const Artifact& artifact, const Measurement& m,
                              const Eigen::VectorXd& c) {
  if (artifact.kind().readings_are_features && m.point.size() == artifact.dimension) return m.point;
  return artifact.feature(m.feature, c);
}

Eigen::VectorXd readingTorques(const Machine& machine, const Measurement& m) {
  const JointCompliance* compliance = machine.mechanism->jointCompliance();
  if (!compliance) return {};
  const Measurement::Torques& kept = m.torques;
  if (kept.model == machine.mechanism.get() && kept.joints.size() == m.joints.size() &&
      kept.joints == m.joints && kept.payload.mass == m.payload.mass &&
      kept.payload.centre == m.payload.centre)
    return kept.tau;
  return compliance->gravityTorques(machine.nominal, m.joints, m.payload);
}

void attachTorques(const Machine& machine, std::vector<Placement>& placements) {
  if (!machine.mechanism->jointCompliance()) return;
  for (Placement& placement : placements) {
    for (Measurement& m : placement.measurements) {
      m.torques = {};
      m.torques = {readingTorques(machine, m), m.joints, m.payload, machine.mechanism.get()};
    }
  }
}

ForwardStatus forwardReading(const Machine& machine, const Eigen::VectorXd& p, const Measurement& m,
                             Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p, Eigen::MatrixXd* J_x_q) {
  return forwardLoaded(*machine.mechanism, m.stylus, p, m.joints, readingTorques(machine, m), x,
                       J_x_p, J_x_q);
}

ForwardStatus forwardReadingPose(const Machine& machine, const Eigen::VectorXd& p,
                                 const Measurement& m, Eigen::VectorXd& x, Eigen::Matrix3d& R,
                                 Eigen::MatrixXd* J_x_p, Eigen::MatrixXd* J_x_q,
                                 Eigen::MatrixXd* J_w_p, Eigen::MatrixXd* J_w_q) {
  return forwardLoadedPose(*machine.mechanism, m.stylus, p, m.joints, readingTorques(machine, m), x,
                           R, J_x_p, J_x_q, J_w_p, J_w_q);
}

void forwardReadingOrThrow(const Machine& machine, const Eigen::VectorXd& p, const Measurement& m,
                           Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p, Eigen::MatrixXd* J_x_q) {
  const ForwardStatus status = forwardReading(machine, p, m, x, J_x_p, J_x_q);
  if (status != ForwardStatus::Ok) throw KinematicsError(forwardStatusName(status));
}

void forwardReadingPoseOrThrow(const Machine& machine, const Eigen::VectorXd& p,
                               const Measurement& m, Eigen::VectorXd& x, Eigen::Matrix3d& R,
                               Eigen::MatrixXd* J_x_p, Eigen::MatrixXd* J_x_q,
                               Eigen::MatrixXd* J_w_p, Eigen::MatrixXd* J_w_q) {
  const ForwardStatus status = forwardReadingPose(machine, p, m, x, R, J_x_p, J_x_q, J_w_p, J_w_q);
  if (status != ForwardStatus::Ok) throw KinematicsError(forwardStatusName(status));
}

void setNominalReading(const Machine& machine, const Artifact& instrument, Measurement& m) {
  Eigen::VectorXd x;
  if (!instrument.measures_pose) {
    forwardReadingOrThrow(machine, machine.nominal, m, x);
    m.point = x;
    return;
  }
  Eigen::Matrix3d R;
  forwardReadingPoseOrThrow(machine, machine.nominal, m, x, R);
  m.point = x;
  m.orientation = rotationVector(R);
}

RigidTransform poseTransform(int dimension, const Pose& pose) {
  return dimension == 2 ? placePlanar(pose.center.head<2>(), pose.angle)
                        : placeSpatial(pose.center.head<3>(), pose.direction, pose.roll);
}

Eigen::MatrixXd placedFeatures(const Artifact& artifact, const Pose& pose) {
  const RigidTransform machine_from_artifact = poseTransform(artifact.dimension, pose).inverse();
  Eigen::MatrixXd out(artifact.dimension, artifact.featureCount());
  for (int i = 0; i < artifact.featureCount(); ++i) {
    out.col(i) = machine_from_artifact.apply(artifact.features.col(i));
  }
  return out;
}

ReadingLocation readingLocation(const Plan& plan, std::size_t placement, std::size_t measurement) {
  const Measurement& m = plan.placements.at(placement).measurements.at(measurement);
  if (m.csv_row > 0) {
    const std::filesystem::path csv(m.csv);
    const std::filesystem::path file =
        csv.is_absolute() ? csv : std::filesystem::path(plan.source).parent_path() / csv;
    return {file.lexically_normal().string(), "row " + std::to_string(m.csv_row)};
  }
  return {plan.source,
          "/placements/" + std::to_string(placement) + "/measurements/" + std::to_string(m.entry)};
}

std::string placementLabel(const std::vector<Placement>& placements, std::size_t index) {
  if (index < placements.size() && !placements[index].name.empty()) return placements[index].name;
  return std::to_string(index);
}

int Plan::artifactIndex(const std::string& id) const {
  for (std::size_t i = 0; i < artifacts.size(); ++i) {
    if (artifacts[i].id == id) return static_cast<int>(i);
  }
  return -1;
}

std::string criterionName(Criterion criterion) {
  return nameOf(kCriterionNames, criterion);
}

std::optional<Criterion> criterionFromName(const std::string& name) {
  return fromName(kCriterionNames, name);
}

}  // namespace artcal
