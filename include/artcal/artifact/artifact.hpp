#pragma once
// Calibrated artifacts (docs/method.md sections 1 and 2): their features W*_i, which coordinates
// are valued, which rigid motions of a placement move those coordinates (N(r_j)), and their
// systematic calibration errors c (W* = W*_0 + C c, prior covariance Sigma_c), shared by every
// placement of the same physical artifact.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "artcal/artifact/artifact_kind.hpp"
#include "artcal/artifact/plane_geometry.hpp"

namespace artcal {

class Artifact;
/// What a person calls the artifact: its kind's name, "ball_bar (table-spindle)" for a double
/// ball bar between the table and the spindle (held as a plane-like surface, plane_geometry.hpp).
std::string artifactTypeName(const Artifact& artifact);

/// One systematic error of an artifact: moves coordinate `coordinate` of feature `feature` by c,
/// with prior standard deviation `sigma` (mm).
struct SystematicError {
  int feature;
  int coordinate;
  double sigma;
};

/// An artifact of one kind (artifact_kind.hpp), built by its kind's factory below:
/// Artifact::ballBar, ballPlate, stepGauge (calibrated balls and faces); instrument (a laser
/// tracker, total station or optical tracker: each placement is one station and each reading its
/// own feature, docs/instruments.md); planeArtifact (flat faces of known relative geometry
/// touched by the tip, docs/planes.md); sphere (a sphere on a machine tool's table, its probed
/// centre read, docs/five-axis.md).
class Artifact {
 public:
  explicit Artifact(const ArtifactKind& kind) : kind_(&kind) {}
  /// What the kind does (its rows, its rigid motions, how it is planned and drawn).
  const ArtifactKind& kind() const { return *kind_; }

  std::string id;
  int dimension = 2;
  Eigen::MatrixXd features;  ///< dimension x featureCount, calibrated nominal coordinates W*_0
  std::vector<SystematicError> systematic;  ///< only errors with sigma > 0
  /// An instrument's random error per coordinate (mm), added in quadrature to the probe noise of
  /// its readings; 0 for calibrated artifacts.
  double noise = 0.0;
  /// An instrument that measures poses (`"measures": "pose"`, instruments.md): each reading also
  /// values the tip frame's orientation (a rotation vector, 3 more rows), with `noise_angle`
  /// (rad, per rotation-vector coordinate). Only on models whose forward kinematics gives one.
  bool measures_pose = false;
  double noise_angle = 0.0;
  /// A plane artifact's faces and contact (a kind that touches faces): `noise` holds its
  /// flatness (mm), `noise_angle` a flush contact's tilt uncertainty (rad).
  PlaneGeometry plane;

  static Artifact ballBar(std::string id, int dimension, double length, double u_length);
  static Artifact ballPlate(std::string id, const Eigen::MatrixXd& centers, double u);
  static Artifact stepGauge(std::string id, int dimension, const std::vector<double>& positions,
                            double u);
  /// An instrument with no reading yet: each reading appends its measured point as a feature.
  static Artifact instrument(std::string id, int dimension, double noise);
  /// A plane artifact (docs/planes.md): its faces from `geometry`, flatness (mm, per touch) and a
  /// flush contact's tilt uncertainty (rad); a gauge block's length uncertainty `u_length` (mm)
  /// moves its second face along its normal.
  static Artifact planeArtifact(std::string id, int dimension, PlaneGeometry geometry,
                                double flatness, double u_tilt, double u_length);
  /// A sphere on a machine tool's table (3-D): one feature at its centre, the origin.
  static Artifact sphere(std::string id);
  /// Appends a measured point (an instrument's reading) as a feature; returns its index.
  int appendFeature(const Eigen::VectorXd& point);

  int featureCount() const { return static_cast<int>(features.cols()); }
  /// k: valued coordinates per feature (all of them for a ball, the first for a step-gauge face).
  int valuedPerFeature() const { return kind_->one_valued_coordinate ? 1 : dimension; }
  /// The artifact coordinate of feature i's j-th valued row: j, or a plane face's normal axis.
  int valuedCoordinate(int feature, int j) const {
    return kind_->touches_faces ? plane.faces[static_cast<std::size_t>(feature)].axis : j;
  }
  /// Observation rows per reading: the valued coordinates, 3 orientation rows for a pose, 2 tilt
  /// rows for a plane's flush contact.
  int rowsPerReading() const {
    return valuedPerFeature() + (measures_pose ? 3 : 0) + (plane.flush ? 2 : 0);
  }
  /// N(r_j): the rigid-motion directions that move valued coordinates (docs/method.md section 1).
  int rigidDof() const { return static_cast<int>(rigidDirections().size()); }
  /// Indices into the full rigid motion (translation, rotation) that a placement estimates.
  const std::vector<int>& rigidDirections() const;
  /// dW_valued / dr at artifact-frame point W: valuedPerFeature() x rigidDof().
  void rigidJacobian(const Eigen::VectorXd& W, Eigen::Ref<Eigen::MatrixXd> J) const;
  /// The full rigid motion (translation, rotation) for a step in the estimated directions.
  Eigen::VectorXd expandRigidStep(const Eigen::VectorXd& step) const;
  /// Size of the full rigid motion: 3 in 2-D (tx, ty, rz), 6 in 3-D (tx, ty, tz, wx, wy, wz).
  /// A sphere's 3 translations only (its centre is all a probing sees).
  int fullRigidDof() const { return static_cast<int>(fullRigidOrder().size()); }
  /// True when the placement is its translations only (a sphere): no rotation to fit or step.
  bool translatesOnly() const { return fullRigidDof() == dimension; }
  /// The full rigid motion's directions, the estimated ones (rigidDirections()) first, then the
  /// ones the table leaves out (a 3-D ball bar's roll; a step gauge's motions across its axis).
  const std::vector<int>& fullRigidOrder() const;
  /// dW_valued / dr over the full rigid motion at artifact-frame point W, columns in
  /// fullRigidOrder(): valuedPerFeature() x fullRigidDof(). The observation blocks use it (rank
  /// policy, docs/method.md section 5, "Real readings"): a rigid motion of the whole machine is
  /// then absorbed by the placement exactly, whatever the points. On consistent points the
  /// trailing columns move no valued coordinate (zero): gauges the reduction leaves out.
  /// `feature`: whose valued coordinates (valuedCoordinate; a plane face's normal axis).
  void fullRigidJacobian(const Eigen::VectorXd& W, Eigen::Ref<Eigen::MatrixXd> J,
                         int feature = 0) const;
  /// The full rigid motion (translation, rotation) for a step over fullRigidOrder().
  Eigen::VectorXd expandFullRigidStep(const Eigen::VectorXd& step) const;
  int systematicCount() const { return static_cast<int>(systematic.size()); }
  /// Calibrated coordinates of feature i with the systematic errors c added.
  Eigen::VectorXd feature(int i, const Eigen::VectorXd& c) const;

 private:
  const ArtifactKind* kind_;
};

}  // namespace artcal
