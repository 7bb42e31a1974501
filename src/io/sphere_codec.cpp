#include "artcal/io/sphere_codec.hpp"

namespace artcal {
namespace {

/// A sphere on a machine tool's table (five-axis.md): its probed centre, position unknown.
Artifact readSphere(const std::string& id, const Node& entry, const Machine& machine,
                    std::vector<std::string>& warnings) {
  entry.warnUnknown({"type", "diameter"}, warnings);
  if (machine.dimension() != 3) entry.at("type").fail("a sphere needs a 3-D machine");
  if (const auto diameter = entry.find("diameter")) diameter->positive();
  return Artifact::sphere(id);
}

}  // namespace

ArtifactCodec sphereArtifactCodec() {
  return {"sphere", readSphere};
}

}  // namespace artcal
