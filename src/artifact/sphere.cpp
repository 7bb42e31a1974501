// A sphere on a machine tool's table (docs/five-axis.md): one feature at its centre, whose
// position only the placement's 3 translations absorb (a turn about the centre moves nothing a
// probing sees).
#include "artcal/artifact/artifact.hpp"

namespace artcal {
namespace {

const RigidOrders& sphereRigidOrders(const Artifact& artifact) {
  return rigidTranslations(artifact.dimension);
}

const ArtifactKind kSphere{
    .name = "sphere", .centre = "the sphere's centre", .rigid_orders = sphereRigidOrders};

}  // namespace

Artifact Artifact::sphere(std::string id) {
  Artifact a(kSphere);
  a.id = std::move(id);
  a.dimension = 3;
  a.features = Eigen::MatrixXd::Zero(3, 1);
  return a;
}

}  // namespace artcal
