#include "artcal/artifact/artifact.hpp"

#include <Eigen/Geometry>
#include <stdexcept>

namespace artcal {

std::string artifactTypeName(const Artifact& artifact) {
  if (artifact.kind == ArtifactKind::Plane && artifact.plane.shape == PlaneShape::TableBall)
    return "ball_bar (table-spindle)";
  return artifactKindName(artifact.kind);
}

std::string artifactKindName(ArtifactKind kind) {
  return nameOf(kArtifactKindNames, kind);
}

Artifact Artifact::ballBar(std::string id, int dimension, double length, double u_length) {
  Artifact a;
  a.id = std::move(id);
  a.kind = ArtifactKind::BallBar;
  a.dimension = dimension;
  a.features = Eigen::MatrixXd::Zero(dimension, 2);
  a.features(0, 1) = length;
  // The length error moves the second ball along X (docs/method.md section 2).
  if (u_length > 0.0) a.systematic.push_back({1, 0, u_length});
  return a;
}

Artifact Artifact::ballPlate(std::string id, const Eigen::MatrixXd& centers, double u) {
  Artifact a;
  a.id = std::move(id);
  a.kind = ArtifactKind::BallPlate;
  a.dimension = static_cast<int>(centers.rows());
  a.features = centers;
  if (u > 0.0) {
    for (int i = 0; i < centers.cols(); ++i) {
      for (int k = 0; k < a.dimension; ++k) a.systematic.push_back({i, k, u});
    }
  }
  return a;
}

Artifact Artifact::stepGauge(std::string id, int dimension, const std::vector<double>& positions,
                             double u) {
  Artifact a;
  a.id = std::move(id);
  a.kind = ArtifactKind::StepGauge;
  a.dimension = dimension;
  a.features = Eigen::MatrixXd::Zero(dimension, static_cast<int>(positions.size()));
  for (std::size_t i = 0; i < positions.size(); ++i) {
    a.features(0, static_cast<int>(i)) = positions[i];
    if (u > 0.0) a.systematic.push_back({static_cast<int>(i), 0, u});
  }
  return a;
}

Artifact Artifact::instrument(std::string id, int dimension, double noise) {
  Artifact a;
  a.id = std::move(id);
  a.kind = ArtifactKind::Instrument;
  a.dimension = dimension;
  a.features = Eigen::MatrixXd::Zero(dimension, 0);
  a.noise = noise;
  return a;
}

Artifact Artifact::sphere(std::string id) {
  Artifact a;
  a.id = std::move(id);
  a.kind = ArtifactKind::Sphere;
  a.dimension = 3;
  a.features = Eigen::MatrixXd::Zero(3, 1);
  return a;
}

int Artifact::appendFeature(const Eigen::VectorXd& point) {
  const int index = featureCount();
  features.conservativeResize(Eigen::NoChange, index + 1);
  features.col(index) = point;
  return index;
}

// Full rigid motion = (translation, rotation): 2-D (tx, ty, rz), 3-D (tx, ty, tz, wx, wy, wz).
// A ball bar in 3-D does not see its roll about X; a step gauge sees only motions that change X.
namespace {

// The full rigid motion's directions (translation, rotation) in the order the observation blocks
// use, and the leading ones the artifact's table counts (N(r_j), docs/method.md section 1).
struct RigidOrders {
  std::vector<int> full;
  std::vector<int> table;
};

const RigidOrders& rigidOrders(int dimension, ArtifactKind kind, PlaneShape shape) {
  static const RigidOrders all2{{0, 1, 2}, {0, 1, 2}}, gauge2{{0, 2, 1}, {0, 2}};
  static const RigidOrders all3{{0, 1, 2, 3, 4, 5}, {0, 1, 2, 3, 4, 5}},
      bar3{{0, 1, 2, 4, 5, 3}, {0, 1, 2, 4, 5}}, gauge3{{0, 4, 5, 1, 2, 3}, {0, 4, 5}},
      sphere3{{0, 1, 2}, {0, 1, 2}};
  // Faces all normal to X (a plane, a gauge block) see what a step gauge's faces see: the
  // translation along X and the turns that tilt X; a cube corner's faces see every motion.
  if (kind == ArtifactKind::Plane) {
    if (shape == PlaneShape::CubeCorner) return dimension == 2 ? all2 : all3;
    if (shape == PlaneShape::TableBall) return sphere3;  // a turn about the ball moves nothing
    return dimension == 2 ? gauge2 : gauge3;
  }
  if (dimension == 2) return kind == ArtifactKind::StepGauge ? gauge2 : all2;
  switch (kind) {
    case ArtifactKind::BallBar:
      return bar3;
    case ArtifactKind::StepGauge:
      return gauge3;
    case ArtifactKind::Sphere:
      return sphere3;
    case ArtifactKind::BallPlate:
    case ArtifactKind::Instrument:
    case ArtifactKind::Plane:
      break;
  }
  return all3;
}

}  // namespace

const std::vector<int>& Artifact::rigidDirections() const {
  return rigidOrders(dimension, kind, plane.shape).table;
}

namespace {

// Column `direction` of the full rigid motion at W: W' = exp(delta) W, dW/dt = I,
// dW/dw = -[W]x (3-D) or (-W_y, W_x) (2-D).
Eigen::Vector3d rigidColumn(int dimension, int direction, const Eigen::VectorXd& W) {
  Eigen::Vector3d column = Eigen::Vector3d::Zero();
  if (direction < dimension) {
    column[direction] = 1.0;
  } else if (dimension == 2) {
    column.head<2>() << -W[1], W[0];
  } else {
    Eigen::Vector3d axis = Eigen::Vector3d::Zero();
    axis[direction - 3] = 1.0;
    column = axis.cross(W.head<3>());
  }
  return column;
}

}  // namespace

void Artifact::rigidJacobian(const Eigen::VectorXd& W, Eigen::Ref<Eigen::MatrixXd> J) const {
  const auto& directions = rigidDirections();
  const int k = valuedPerFeature();
  for (std::size_t c = 0; c < directions.size(); ++c) {
    const Eigen::Vector3d column = rigidColumn(dimension, directions[c], W);
    // Entry by entry: GCC 12 warns falsely (-Warray-bounds) on head(k) of a Vector3d under AVX.
    for (int r = 0; r < k; ++r) J(r, static_cast<int>(c)) = column[r];
  }
}

const std::vector<int>& Artifact::fullRigidOrder() const {
  return rigidOrders(dimension, kind, plane.shape).full;
}

void Artifact::fullRigidJacobian(const Eigen::VectorXd& W, Eigen::Ref<Eigen::MatrixXd> J,
                                 int feature) const {
  const std::vector<int>& order = fullRigidOrder();
  const int k = valuedPerFeature();
  for (std::size_t c = 0; c < order.size(); ++c) {
    const Eigen::Vector3d column = rigidColumn(dimension, order[c], W);
    for (int r = 0; r < k; ++r) J(r, static_cast<int>(c)) = column[valuedCoordinate(feature, r)];
  }
}

Eigen::VectorXd Artifact::expandFullRigidStep(const Eigen::VectorXd& step) const {
  const std::vector<int>& order = fullRigidOrder();
  Eigen::VectorXd full = Eigen::VectorXd::Zero(dimension == 2 ? 3 : 6);
  for (std::size_t c = 0; c < order.size(); ++c) full[order[c]] = step[static_cast<int>(c)];
  return full;
}

Eigen::VectorXd Artifact::expandRigidStep(const Eigen::VectorXd& step) const {
  const auto& directions = rigidDirections();
  Eigen::VectorXd full = Eigen::VectorXd::Zero(dimension == 2 ? 3 : 6);
  for (std::size_t c = 0; c < directions.size(); ++c)
    full[directions[c]] = step[static_cast<int>(c)];
  return full;
}

Eigen::VectorXd Artifact::feature(int i, const Eigen::VectorXd& c) const {
  Eigen::VectorXd W = features.col(i);
  for (int s = 0; s < c.size(); ++s) {
    if (systematic[s].feature == i) W[systematic[s].coordinate] += c[s];
  }
  return W;
}

}  // namespace artcal
