// Plane artifacts (docs/planes.md): their faces as features, one valued coordinate each.
#include <stdexcept>

#include "artcal/artifact/artifact.hpp"

namespace artcal {
namespace {

/// Faces all normal to X (a plane, a gauge block) see what a step gauge's faces see; a cube
/// corner's faces see every motion; a table-spindle bar's sphere about its table ball sees the
/// translations only (a turn about the ball moves nothing).
const RigidOrders& planeRigidOrders(const Artifact& artifact) {
  switch (artifact.plane.shape) {
    case PlaneShape::CubeCorner:
      return everyRigidDirection(artifact.dimension);
    case PlaneShape::TableBall:
      return rigidTranslations(artifact.dimension);
    case PlaneShape::Single:
    case PlaneShape::GaugeBlock:
      break;
  }
  return rigidDirectionsMovingX(artifact.dimension);
}

std::string planeTypeName(const Artifact& artifact) {
  return artifact.plane.shape == PlaneShape::TableBall ? "ball_bar (table-spindle)" : "plane";
}

const ArtifactKind kPlane{.name = "plane",
                          .one_valued_coordinate = true,
                          .touches_faces = true,
                          .centre = "the table ball's centre",
                          .rigid_orders = planeRigidOrders,
                          .type_name = planeTypeName};

}  // namespace

Artifact Artifact::planeArtifact(std::string id, int dimension, PlaneGeometry geometry,
                                 double flatness, double u_tilt, double u_length) {
  Artifact a(kPlane);
  a.id = std::move(id);
  a.dimension = dimension;
  a.noise = flatness;
  a.noise_angle = u_tilt;
  geometry.faces.clear();
  switch (geometry.shape) {
    case PlaneShape::Single:
      geometry.faces.push_back({0, 1.0, 0.0});
      break;
    case PlaneShape::GaugeBlock:
      geometry.faces.push_back({0, -1.0, 0.0});
      geometry.faces.push_back({0, 1.0, geometry.length});
      // The length error moves the second face along its normal (docs/method.md section 2).
      if (u_length > 0.0) a.systematic.push_back({1, 0, u_length});
      break;
    case PlaneShape::CubeCorner:
      for (int axis = 0; axis < dimension; ++axis) geometry.faces.push_back({axis, 1.0, 0.0});
      break;
    case PlaneShape::TableBall:
      // One "face", the sphere about the table ball (the artifact's origin); the bar's length
      // error moves it along the bar (docs/method.md section 2).
      geometry.faces.push_back({0, 1.0, 0.0});
      if (u_length > 0.0) a.systematic.push_back({0, 0, u_length});
      a.features = Eigen::MatrixXd::Zero(dimension, 1);
      a.plane = std::move(geometry);
      return a;
  }
  // Each face's feature: where the tip's reference point sits when it touches the face's middle
  // (a ball's centre one radius out along the normal; a flush frame's origin on the face).
  a.features = Eigen::MatrixXd::Zero(dimension, static_cast<int>(geometry.faces.size()));
  const double out = geometry.flush ? 0.0 : geometry.radius;
  for (std::size_t f = 0; f < geometry.faces.size(); ++f) {
    const PlaneFace& face = geometry.faces[f];
    const int col = static_cast<int>(f);
    if (geometry.shape == PlaneShape::CubeCorner)
      a.features.col(col).setConstant(-0.5 * geometry.length);
    a.features(face.axis, col) = face.offset + face.sign * out;
  }
  a.plane = std::move(geometry);
  return a;
}

}  // namespace artcal
