// The ball plate (docs/method.md section 2): calibrated ball centres, every coordinate valued.
#include "artcal/artifact/artifact.hpp"

namespace artcal {
namespace {

const RigidOrders& ballPlateRigidOrders(const Artifact& artifact) {
  return everyRigidDirection(artifact.dimension);
}

const ArtifactKind kBallPlate{.name = "ball_plate",
                              .drawn_as_line = false,
                              .design_rolls = true,
                              .rigid_orders = ballPlateRigidOrders};

}  // namespace

Artifact Artifact::ballPlate(std::string id, const Eigen::MatrixXd& centers, double u) {
  Artifact a(kBallPlate);
  a.id = std::move(id);
  a.dimension = static_cast<int>(centers.rows());
  a.features = centers;
  if (u > 0.0) {
    for (int i = 0; i < centers.cols(); ++i) {
      for (int k = 0; k < a.dimension; ++k) a.systematic.push_back({i, k, u});
    }
  }
  return a;
}

}  // namespace artcal
