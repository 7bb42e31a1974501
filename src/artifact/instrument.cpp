// An instrument (docs/instruments.md): a laser tracker, total station or optical tracker. Each
// placement is one station; every reading is its own feature, the point the instrument reported
// in its own frame (all coordinates valued, N(r_j) = 6 as for a ball plate).
#include "artcal/artifact/artifact.hpp"

namespace artcal {
namespace {

const RigidOrders& instrumentRigidOrders(const Artifact& artifact) {
  return everyRigidDirection(artifact.dimension);
}

const ArtifactKind kInstrument{
    .name = "instrument", .readings_are_features = true, .rigid_orders = instrumentRigidOrders};

}  // namespace

Artifact Artifact::instrument(std::string id, int dimension, double noise) {
  Artifact a(kInstrument);
  a.id = std::move(id);
  a.dimension = dimension;
  a.features = Eigen::MatrixXd::Zero(dimension, 0);
  a.noise = noise;
  return a;
}

}  // namespace artcal
