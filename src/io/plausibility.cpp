#include "artcal/io/plausibility.hpp"

#include "artcal/estimation/plane_rows.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>

#include "artcal/artifact/rigid_transform.hpp"
#include "artcal/core/error.hpp"
#include "artcal/core/units.hpp"
#include "artcal/model/rotation_vector.hpp"

namespace artcal {

namespace {

constexpr double kNoiseFactor = 100.0;      // residuals beyond 100 s_p are no noise
constexpr double kAbsoluteFloor = 1.0;      // mm: an uncalibrated machine errs by about this
constexpr double kArtifactFraction = 0.25;  // wrong units err by the artifact's own size
constexpr double kPoseFloor = 10.0;         // mm: a pose entered by hand may be this rough
constexpr double kReachFactor = 10.0;       // an artifact 10 x the machine's diameter is not on it
constexpr double kMachineFraction = 0.05;   // a real machine may be off nominal by 5 % of its reach
constexpr double kCollapsedRatio = 0.5;     // features probed closer than half their true spacing
constexpr double kAngleFloorDeg = 5.0;      // deg: a real machine's tip frame is not turned more

std::string millimetres(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.4g mm", value);
  return text;
}

/// RMS distance of the artifact's features from their centroid (mm).
double artifactSpread(const Artifact& artifact) {
  const Eigen::VectorXd centroid = artifact.features.rowwise().mean();
  return std::sqrt((artifact.features.colwise() - centroid).colwise().squaredNorm().mean());
}

/// The residual of a point in the artifact frame against feature i: valued coordinates only.
double valuedDistance(const Artifact& artifact, const Eigen::VectorXd& W, int feature) {
  const Eigen::VectorXd d = W - artifact.features.col(feature);
  return d.head(artifact.valuedPerFeature()).norm();
}

/// The probe positions of a placement's readings at parameters p; false when the machine cannot
/// evaluate one of them (left to the numerical code to report).
bool probedPoints(const Plan& plan, const Eigen::VectorXd& p, const Placement& placement,
                  Eigen::MatrixXd& points) {
  points.resize(plan.machine.dimension(), static_cast<int>(placement.measurements.size()));
  Eigen::VectorXd x;
  for (std::size_t i = 0; i < placement.measurements.size(); ++i) {
    const Measurement& m = placement.measurements[i];
    if (forwardReading(plan.machine, p, m, x) != ForwardStatus::Ok) {
      return false;
    }
    if (x.size() != points.rows() || !x.allFinite()) return false;
    points.col(static_cast<int>(i)) = x;
  }
  return true;
}

/// The mean probed position of each measured feature (by feature index).
std::map<int, Eigen::VectorXd> featureMeans(const Placement& placement,
                                            const Eigen::MatrixXd& points) {
  std::map<int, Eigen::VectorXd> sums;
  std::map<int, int> counts;
  for (std::size_t i = 0; i < placement.measurements.size(); ++i) {
    const int feature = placement.measurements[i].feature;
    auto [it, fresh] = sums.try_emplace(feature, Eigen::VectorXd::Zero(points.rows()));
    it->second += points.col(static_cast<int>(i));
    ++counts[feature];
  }
  for (auto& [feature, sum] : sums) sum /= counts[feature];
  return sums;
}

/// RMS residual length of the rigid fit of `points` onto the measured features.
double fitResidual(const Artifact& artifact, const Placement& placement,
                   const Eigen::MatrixXd& points) {
  Eigen::MatrixXd targets(artifact.dimension, points.cols());
  std::set<int> distinct;
  for (std::size_t i = 0; i < placement.measurements.size(); ++i) {
    targets.col(static_cast<int>(i)) = artifact.features.col(placement.measurements[i].feature);
    distinct.insert(placement.measurements[i].feature);
  }
  if (distinct.size() < 2) {  // one feature: the fit puts it at the mean of its postures
    const Eigen::VectorXd mean = points.rowwise().mean();
    return std::sqrt((points.colwise() - mean).colwise().squaredNorm().mean());
  }
  const RigidTransform fit = fitRigid(points, targets);
  double sum = 0.0;
  for (std::size_t i = 0; i < placement.measurements.size(); ++i) {
    const double r = valuedDistance(artifact, fit.apply(points.col(static_cast<int>(i))),
                                    placement.measurements[i].feature);
    sum += r * r;
  }
  return std::sqrt(sum / static_cast<double>(points.cols()));
}

/// Largest distance between a measured feature and the mean of its probed positions, in the
/// frame the placement's pose gives the artifact.
double poseDisagreement(const Plan& plan, const Artifact& artifact, const Placement& placement,
                        const Eigen::MatrixXd& points) {
  const Pose& pose = *placement.pose;
  const RigidTransform placed =
      plan.machine.dimension() == 2
          ? placePlanar(pose.center.head<2>(), pose.angle)
          : placeSpatial(pose.center.head<3>(), pose.direction, pose.roll);
  double worst = 0.0;
  for (const auto& [feature, mean] : featureMeans(placement, points)) {
    worst = std::max(worst, valuedDistance(artifact, placed.apply(mean), feature));
  }
  return worst;
}

/// False for an instrument's station planned without its measured points: its pose (where the
/// instrument will stand) has nothing yet to be compared with.
bool everyPointGiven(const Placement& placement) {
  return std::all_of(placement.measurements.begin(), placement.measurements.end(),
                     [](const Measurement& m) { return m.point_given; });
}

/// A pose instrument's station: the RMS angle (deg) between the measured orientations and the
/// machine's at p, after the best rigid fit of the probed points onto the measured ones (the
/// station). 0 when a reading's orientation cannot be evaluated (left to the numerical code).
double orientationResidualDeg(const Plan& plan, const Eigen::VectorXd& p,
                              const Placement& placement, const Eigen::MatrixXd& points) {
  Eigen::MatrixXd measured(points.rows(), points.cols());
  for (std::size_t i = 0; i < placement.measurements.size(); ++i)
    measured.col(static_cast<int>(i)) = placement.measurements[i].point;
  const RigidTransform station = fitRigid(points, measured);
  double sum = 0.0;
  Eigen::VectorXd x;
  Eigen::Matrix3d R;
  for (const Measurement& m : placement.measurements) {
    if (forwardReadingPose(plan.machine, p, m, x, R) != ForwardStatus::Ok) return 0.0;
    sum += orientationResidual(Eigen::Matrix3d(station.R * R), m.orientation).squaredNorm();
  }
  return radToDeg(std::sqrt(sum / static_cast<double>(placement.measurements.size())));
}

/// A pose instrument's orientations must agree with the machine's to within a machine error
/// (kAngleFloorDeg) or 100 x their noise: otherwise their units or their frame are wrong.
void checkOrientations(const Plan& plan, const Eigen::VectorXd& p, const Placement& placement,
                       const Eigen::MatrixXd& points, const std::string& where,
                       const std::string& machine) {
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  if (!artifact.measures_pose) return;
  const double threshold = std::max(kAngleFloorDeg, kNoiseFactor * radToDeg(artifact.noise_angle));
  const double residual = orientationResidualDeg(plan, p, placement, points);
  if (residual <= threshold) return;
  char text[64], limit[64];
  std::snprintf(text, sizeof text, "%.4g deg (RMS)", residual);
  std::snprintf(limit, sizeof limit, "%.3g deg", threshold);
  throw InputError(plan.source, where,
                   machine + " turns the tip " + text +
                       " away from the measured orientations after the best rigid fit of the "
                       "station, more than a machine error or noise explains (" +
                       limit +
                       "): check the orientation's units (a rotation vector in deg) and "
                       "that it is the tip frame's (serial-dh: the last joint's frame; chain: "
                       "the tip link's)");
}

/// The largest distance between two of the artifact's features (mm).
double artifactDiameter(const Artifact& artifact) {
  double diameter = 0.0;
  for (int a = 0; a < artifact.featureCount(); ++a) {
    for (int b = a + 1; b < artifact.featureCount(); ++b) {
      diameter = std::max(diameter, (artifact.features.col(a) - artifact.features.col(b)).norm());
    }
  }
  return diameter;
}

int distinctFeatures(const Placement& placement) {
  std::set<int> distinct;
  for (const Measurement& m : placement.measurements) distinct.insert(m.feature);
  return static_cast<int>(distinct.size());
}

/// The farthest the machine at p probes from its origin over every reading of the plan (mm).
double planReach(const Plan& plan, const Eigen::VectorXd& p) {
  double reach = 0.0;
  Eigen::MatrixXd points;
  for (const Placement& placement : plan.placements) {
    if (!probedPoints(plan, p, placement, points) || points.cols() == 0) continue;
    reach = std::max(reach, points.colwise().norm().maxCoeff());
  }
  return reach;
}

// A placement that reads one feature only has no length to fit (its residual is 0 whatever the
// units): a machine in metres is told by the artifact's size instead. Its features must fit
// within kReachFactor times the diameter 2 R of the sphere the plan's readings probe within.
void checkArtifactFitsTheMachine(const Plan& plan, const Placement& placement,
                                 const std::string& where, double reach) {
  if (distinctFeatures(placement) != 1) return;
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  const double diameter = artifactDiameter(artifact);
  if (diameter <= kReachFactor * 2.0 * reach) return;
  throw InputError(plan.source, where,
                   "the nominal machine probes every reading of the plan within " +
                       millimetres(reach) + " of its origin, but the artifact \"" + artifact.id +
                       "\" is " + millimetres(diameter) +
                       " across: check the units (lengths in mm, not metres)");
}

// An arm whose model ends at the flange while the readings are of a ball beyond it (a tool its
// URDF does not have) misses by about the tool's length: the other cause a robot user meets.
// The arms are the models with a tip frame (chain, serial-dh: Mechanism::hasOrientation).
std::string tipHint(const Plan& plan) {
  if (!plan.machine.mechanism->hasOrientation()) return "";
  return "; and that the machine's tip is the ball's centre (a URDF chain's --tip link: a tool "
         "beyond the flange needs a fixed joint of its own in the URDF; serial-dh: its probe)";
}

// Wrong units collapse the probed points (readings in radians read as degrees turn each joint a
// 57th of the way; a machine in metres is a thousand times too small): the mean probed positions
// of the measured features then lie much closer together than the features themselves, however
// far off nominal the machine is. Compared as RMS distances from their centroids.
void checkFeaturesNotCollapsed(const Plan& plan, const Placement& placement,
                               const Eigen::MatrixXd& points, const std::string& where,
                               const std::string& machine) {
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  // A step gauge values one coordinate: where on a face it is probed is free, so only the
  // features whose every coordinate is valued (balls) are compared.
  const int k = artifact.valuedPerFeature();
  const std::map<int, Eigen::VectorXd> means = featureMeans(placement, points);
  if (means.size() < 2 || k != artifact.dimension) return;
  Eigen::MatrixXd probed(k, static_cast<int>(means.size()));
  Eigen::MatrixXd true_features(k, probed.cols());
  int column = 0;
  for (const auto& [feature, mean] : means) {
    probed.col(column) = mean.head(k);
    true_features.col(column++) = artifact.features.col(feature).head(k);
  }
  auto spread = [](const Eigen::MatrixXd& x) {
    const Eigen::VectorXd centroid = x.rowwise().mean();
    return std::sqrt((x.colwise() - centroid).colwise().squaredNorm().mean());
  };
  const double probed_spread = spread(probed);
  const double true_spread = spread(true_features);
  if (!(true_spread > 0.0) || probed_spread >= kCollapsedRatio * true_spread) return;
  throw InputError(plan.source, where,
                   machine + " probes the artifact's features " + millimetres(probed_spread) +
                       " (RMS) from their centre where the artifact has them " +
                       millimetres(true_spread) +
                       " from it: check the units (joint readings in degrees, not radians; "
                       "lengths in mm, not metres)");
}

// A plane's touches (docs/planes.md) lie anywhere on its faces: what can be wrong is their
// distance from the faces where the placement's pose puts them (RMS over the readings), beyond a
// machine error, the pose's own error (kPoseFloor) or noise: wrong units or a wrong pose.
void checkTouches(const Plan& plan, const Eigen::VectorXd& p, const Placement& placement,
                  const std::string& where, const std::string& machine, double reach) {
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  const RigidTransform placed = poseTransform(plan.machine.dimension(), *placement.pose);
  PlaneRows rows;
  PlaneRowsScratch scratch;
  double sum = 0.0;
  for (const Measurement& m : placement.measurements) {
    try {
      planeRows(artifact, plan.machine, p, m, placed, Eigen::VectorXd(), false, rows, scratch);
    } catch (const KinematicsError&) {
      return;  // left to the numerical code to report
    }
    sum += rows.residual[0] * rows.residual[0];
  }
  const double residual = std::sqrt(sum / static_cast<double>(placement.measurements.size()));
  const double threshold =
      std::max(plausibleResidual(artifact, plan.noise.probe, reach), kPoseFloor);
  if (residual <= threshold) return;
  throw InputError(plan.source, where,
                   machine + " puts these touches " + millimetres(residual) +
                       " (RMS) off the faces where the pose puts them, more than a machine "
                       "error or the pose's own error explains (" +
                       millimetres(threshold) +
                       "): check the pose (center in mm on the face, direction along its "
                       "normal) and the units (joint readings in degrees, lengths in mm)" +
                       tipHint(plan));
}

}  // namespace

double plausibleResidual(const Artifact& artifact, double probe_sigma, double reach) {
  return std::max({kNoiseFactor * probe_sigma, kAbsoluteFloor,
                   kArtifactFraction * artifactSpread(artifact), kMachineFraction * reach});
}

void checkPlausibility(const Plan& plan) {
  checkPlausibility(plan, plan.machine.nominal, "the nominal machine");
}

void checkPlausibility(const Plan& plan, const Eigen::VectorXd& p, const std::string& machine) {
  const double reach = planReach(plan, p);
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const Placement& placement = plan.placements[j];
    if (placement.measurements.empty()) continue;
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    Eigen::MatrixXd points;
    if (!probedPoints(plan, p, placement, points)) continue;
    const std::string where = "/placements/" + std::to_string(j);
    if (artifact.kind().touches_faces) {
      checkTouches(plan, p, placement, where, machine, reach);
      continue;
    }
    checkFeaturesNotCollapsed(plan, placement, points, where, machine);
    const double threshold = plausibleResidual(artifact, plan.noise.probe, reach);
    const double residual = fitResidual(artifact, placement, points);
    if (!(residual <= threshold)) {
      throw InputError(
          plan.source, where,
          machine + " puts these readings " + millimetres(residual) +
              " (RMS) off the artifact's features after the best rigid fit, more than a machine "
              "error (5 % of the machine's reach) or noise explains (" +
              millimetres(threshold) +
              "): check the units (joint readings in degrees, not radians; lengths in mm, not "
              "metres) and that each reading's feature index is right" +
              tipHint(plan));
    }
    checkArtifactFitsTheMachine(plan, placement, where, reach);
    checkOrientations(plan, p, placement, points, where, machine);
    if (!placement.pose || !everyPointGiven(placement)) continue;
    const double pose_threshold = std::max(threshold, kPoseFloor);
    const double disagreement = poseDisagreement(plan, artifact, placement, points);
    if (!(disagreement <= pose_threshold)) {
      throw InputError(plan.source, where + "/pose",
                       "the pose puts the artifact " + millimetres(disagreement) +
                           " away from where the readings probe it (more than " +
                           millimetres(pose_threshold) +
                           "): check the pose (center in mm, angles in degrees) or leave it out");
    }
  }
}

void checkPlausibilityOfVerified(const Plan& plan, const Eigen::VectorXd& p,
                                 const std::string& machine) {
  try {
    checkPlausibility(plan, p, machine);
  } catch (const InputError&) {
    bool nominal_fits = true;
    try {
      checkPlausibility(plan);
    } catch (const InputError&) {
      nominal_fits = false;
    }
    if (!nominal_fits) throw;  // the machine verified's error
  }
}

}  // namespace artcal
