// The step gauge (docs/method.md section 2): faces along X, each valued along X only.
#include "artcal/artifact/artifact.hpp"

namespace artcal {
namespace {

const RigidOrders& stepGaugeRigidOrders(const Artifact& artifact) {
  return rigidDirectionsMovingX(artifact.dimension);
}

const ArtifactKind kStepGauge{
    .name = "step_gauge", .one_valued_coordinate = true, .rigid_orders = stepGaugeRigidOrders};

}  // namespace

Artifact Artifact::stepGauge(std::string id, int dimension, const std::vector<double>& positions,
                             double u) {
  Artifact a(kStepGauge);
  a.id = std::move(id);
  a.dimension = dimension;
  a.features = Eigen::MatrixXd::Zero(dimension, static_cast<int>(positions.size()));
  for (std::size_t i = 0; i < positions.size(); ++i) {
    a.features(0, static_cast<int>(i)) = positions[i];
    if (u > 0.0) a.systematic.push_back({static_cast<int>(i), 0, u});
  }
  return a;
}

}  // namespace artcal
