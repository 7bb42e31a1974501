// The ball bar (docs/method.md section 2): two balls a calibrated length apart along X.
#include "artcal/artifact/artifact.hpp"

namespace artcal {
namespace {

/// In 3-D a bar does not see its roll about its own axis (X): the table leaves it out.
const RigidOrders& ballBarRigidOrders(const Artifact& artifact) {
  static const RigidOrders bar3{{0, 1, 2, 4, 5, 3}, {0, 1, 2, 4, 5}};
  return artifact.dimension == 2 ? everyRigidDirection(2) : bar3;
}

const ArtifactKind kBallBar{.name = "ball_bar", .rigid_orders = ballBarRigidOrders};

}  // namespace

Artifact Artifact::ballBar(std::string id, int dimension, double length, double u_length) {
  Artifact a(kBallBar);
  a.id = std::move(id);
  a.dimension = dimension;
  a.features = Eigen::MatrixXd::Zero(dimension, 2);
  a.features(0, 1) = length;
  // The length error moves the second ball along X (docs/method.md section 2).
  if (u_length > 0.0) a.systematic.push_back({1, 0, u_length});
  return a;
}

}  // namespace artcal
