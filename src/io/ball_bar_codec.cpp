#include "artcal/io/ball_bar_codec.hpp"

namespace artcal {
namespace {

/// A double ball bar between a ball on the table and the spindle's (five-axis.md section 3): a
/// sphere about the table ball, held as a plane-like surface (artifact/plane_geometry.hpp).
Artifact readTableSpindleBar(const std::string& id, const Node& entry, const Machine& machine) {
  const Node ends = entry.at("ends");
  if (ends.string() != "table-spindle")
    ends.fail("unknown ends \"" + ends.string() +
              "\" (expected table-spindle; leave \"ends\" "
              "out for a bar between two sockets the machine holds in turn)");
  if (machine.dimension() != 3) ends.fail("a table-spindle ball bar needs a 3-D machine");
  PlaneGeometry geometry;
  geometry.shape = PlaneShape::TableBall;
  geometry.length = entry.at("length").positive();
  return Artifact::planeArtifact(id, machine.dimension(), geometry, 0.0, 0.0,
                                 artifactUncertainty(entry, "u_length"));
}

Artifact readBallBar(const std::string& id, const Node& entry, const Machine& machine,
                     std::vector<std::string>& warnings) {
  entry.warnUnknown({"type", "length", "u_length", "ends"}, warnings);
  if (entry.has("ends")) return readTableSpindleBar(id, entry, machine);
  return Artifact::ballBar(id, machine.dimension(), entry.at("length").positive(),
                           artifactUncertainty(entry, "u_length"));
}

}  // namespace

ArtifactCodec ballBarArtifactCodec() {
  return {"ball_bar", readBallBar};
}

}  // namespace artcal
