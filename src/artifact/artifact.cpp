#include "artcal/artifact/artifact.hpp"

#include <Eigen/Geometry>
#include <stdexcept>

namespace artcal {

std::string artifactTypeName(const Artifact& artifact) {
  const ArtifactKind& kind = artifact.kind();
  return kind.type_name ? kind.type_name(artifact) : kind.name;
}

int Artifact::appendFeature(const Eigen::VectorXd& point) {
  const int index = featureCount();
  features.conservativeResize(Eigen::NoChange, index + 1);
  features.col(index) = point;
  return index;
}

const RigidOrders& everyRigidDirection(int dimension) {
  static const RigidOrders all2{{0, 1, 2}, {0, 1, 2}};
  static const RigidOrders all3{{0, 1, 2, 3, 4, 5}, {0, 1, 2, 3, 4, 5}};
  return dimension == 2 ? all2 : all3;
}

const RigidOrders& rigidDirectionsMovingX(int dimension) {
  static const RigidOrders gauge2{{0, 2, 1}, {0, 2}}, gauge3{{0, 4, 5, 1, 2, 3}, {0, 4, 5}};
  return dimension == 2 ? gauge2 : gauge3;
}

const RigidOrders& rigidTranslations(int dimension) {
  static const RigidOrders translations2{{0, 1}, {0, 1}}, translations3{{0, 1, 2}, {0, 1, 2}};
  return dimension == 2 ? translations2 : translations3;
}

const std::vector<int>& Artifact::rigidDirections() const {
  return kind_->rigid_orders(*this).table;
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
  return kind_->rigid_orders(*this).full;
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
