#pragma once
// The design space of the planner (docs/method.md section 7): where one placement of the design's
// artifact may go and in which postures its features are probed.
//
// A placement is described by a short pose vector v:
//   2-D: (center x, center y, angle)                       angle in rad
//   3-D: (center x, y, z, azimuth, elevation[, roll])      direction from the two angles; roll
//                                                          only for ball plates (a bar's roll
//                                                          about its axis is invisible)
// The center is the artifact frame's origin (feature 0 of a ball bar). A placement is feasible
// when every feature lies inside the design region and each planned reading reaches its feature
// within the joint limits. Postures: planar2r has two (the elbow branches); its branch per
// reading is a discrete design choice drawn at random for a candidate. Serial arms get
// `diversePostures` (spread in joint space); moving a pose re-solves each reading from its
// previous joints, so a posture keeps its identity while the optimizer refines the pose.
// Every planned reading stays `design.joint_margin` inside the joint limits (default 2 deg /
// 1 mm; joints that wrap, a full turn of range or more, need none): a real machine, a little off
// its nominal parameters, must reach every planned point too (`artcal simulate`, `confirm`).
//
// Commanded joints (Mechanism::commandedJoints, a machine tool's rotary axes probing a sphere,
// docs/five-axis.md): the pose vector is (centre x, y, z, then each posture's commanded joint
// values in order), so the search chooses the sphere's place and the rotary positions; each
// reading holds those joints and solves the others (solveHoldingJoints). No direction: a sphere's
// centre is all a probing sees.

#include <Eigen/Core>
#include <optional>
#include <random>
#include <utility>
#include <vector>

#include "artcal/artifact/rigid_transform.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// The default of `design.joint_margin` (internal units): 2 deg per revolute joint, 1 mm per
/// prismatic one.
Eigen::VectorXd defaultJointMargin(const Mechanism& mechanism);

/// The machine whose joint limits are narrowed by `margin` (internal units, per joint): where
/// planned readings may lie. A revolute joint with a full turn of range or more wraps and keeps
/// its limits; a margin that would leave less than half of a joint's range is cut to a quarter.
Machine withJointMargin(const Machine& machine, const Eigen::VectorXd& margin);

/// The planner's rule for the nominal readings of one feature at machine-frame point `target`:
/// `count` postures (a Cartesian CMM: styli 0 .. count - 1; other models: posturesFor, spread in
/// joint space) within `reading_machine`'s limits; fewer when not that many reach it. A
/// `stylus` >= 0 (a request naming a chain's tip, docs/urdf.md): `count` postures of that tip.
std::vector<Measurement> featureReadings(const Machine& reading_machine, int feature,
                                         const Eigen::VectorXd& target, int count,
                                         std::mt19937_64& rng, int stylus = -1);

class DesignSpace {
 public:
  /// `plan.design` must be set; InputError when the design does not fit the plan.
  explicit DesignSpace(const Plan& plan);

  const Plan& plan() const { return *plan_; }
  const DesignSpec& design() const { return *plan_->design; }
  /// The plan's machine with each joint's limits narrowed by the design's joint margin: where
  /// planned readings may lie.
  const Machine& readingMachine() const { return reading_machine_; }
  const Artifact& artifact() const;
  int dimension() const { return plan_->machine.dimension(); }
  /// Numbers in one placement's pose vector.
  int poseSize() const;
  /// Box bounds of a pose vector (the centre within the region's extent, angles free).
  Eigen::VectorXd lowerBounds() const { return lower_; }
  Eigen::VectorXd upperBounds() const { return upper_; }
  /// Typical step of each pose coordinate, for the start of a derivative-free search.
  Eigen::VectorXd initialSteps() const;

  RigidTransform transformOf(const Eigen::VectorXd& v) const;
  Pose poseOf(const Eigen::VectorXd& v) const;
  /// The artifact's features in the machine frame (dimension x features) for pose vector v.
  Eigen::MatrixXd featurePositions(const Eigen::VectorXd& v) const;
  /// How far (mm, summed) the features of pose v lie outside the region; 0 inside.
  double regionViolation(const Eigen::VectorXd& v) const;

  /// A random pose with every feature inside the region (not yet checked for reach).
  Eigen::VectorXd randomPose(std::mt19937_64& rng) const;
  /// A feasible placement at pose v with fresh postures (random elbow branches / diverse IK);
  /// std::nullopt when some feature is outside the region or cannot get its postures.
  std::optional<Placement> placeWithNewPostures(const Eigen::VectorXd& v,
                                                std::mt19937_64& rng) const;
  /// The placement at pose v whose readings continue those of `previous` (same features, same
  /// order, each re-solved from its old joints); std::nullopt when one fails.
  std::optional<Placement> movePlacement(const Placement& previous, const Eigen::VectorXd& v) const;
  /// A random feasible placement and its pose vector: up to `attempts` random poses;
  /// std::nullopt when none works.
  std::optional<std::pair<Eigen::VectorXd, Placement>> randomPlacement(std::mt19937_64& rng,
                                                                       int attempts) const;
  /// The commanded joints the pose vector carries per posture (empty: the usual pose vector).
  const std::vector<int>& commandedJoints() const { return commanded_; }

 private:
  /// Commanded mode: the placement at pose v, each posture's readings from its commanded values.
  std::optional<Placement> commandedPlacement(const Eigen::VectorXd& v) const;
  const Plan* plan_;
  Machine reading_machine_;
  Eigen::VectorXd lower_, upper_;
  bool has_roll_ = false;
  std::vector<int> commanded_;
};

}  // namespace artcal
