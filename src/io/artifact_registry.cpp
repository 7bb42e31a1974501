#include "artcal/io/artifact_registry.hpp"

#include "artcal/io/ball_bar_codec.hpp"
#include "artcal/io/ball_plate_codec.hpp"
#include "artcal/io/instrument_codec.hpp"
#include "artcal/io/plane_codec.hpp"
#include "artcal/io/sphere_codec.hpp"
#include "artcal/io/step_gauge_codec.hpp"

namespace artcal {

const std::vector<ArtifactCodec>& artifactCodecs() {
  // The registry: one line per kind (artifact_registry.hpp says how to add one).
  static const std::vector<ArtifactCodec> codecs = {
      ballBarArtifactCodec(),    ballPlateArtifactCodec(), stepGaugeArtifactCodec(),
      instrumentArtifactCodec(), planeArtifactCodec(),     sphereArtifactCodec(),
  };
  return codecs;
}

double artifactUncertainty(const Node& entry, const char* key) {
  return entry.find(key) ? entry.at(key).standardDeviation(true) : 0.0;
}

Artifact readArtifact(const std::string& id, const Node& entry, const Machine& machine,
                      std::vector<std::string>& warnings) {
  entry.object();
  const Node type = entry.at("type");
  const auto& codecs = artifactCodecs();
  std::string known;
  for (std::size_t i = 0; i < codecs.size(); ++i) {
    if (codecs[i].type == type.string()) return codecs[i].read(id, entry, machine, warnings);
    if (i > 0) known += i + 1 == codecs.size() ? " or " : ", ";
    known += codecs[i].type;
  }
  type.fail("unknown artifact type \"" + type.string() + "\" (expected " + known + ")");
}

}  // namespace artcal
