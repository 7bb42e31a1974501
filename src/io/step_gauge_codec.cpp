#include "artcal/io/step_gauge_codec.hpp"

#include <set>

namespace artcal {
namespace {

Artifact readStepGauge(const std::string& id, const Node& entry, const Machine& machine,
                       std::vector<std::string>& warnings) {
  entry.warnUnknown({"type", "positions", "u"}, warnings);
  const Node positions = entry.at("positions");
  const std::size_t n = positions.arraySize(2, kMaxArtifactFeatures);
  std::vector<double> values;
  for (std::size_t i = 0; i < n; ++i) values.push_back(positions[i].number());
  if (std::set<double>(values.begin(), values.end()).size() != values.size()) {
    positions.fail("positions must be distinct");
  }
  return Artifact::stepGauge(id, machine.dimension(), values, artifactUncertainty(entry, "u"));
}

}  // namespace

ArtifactCodec stepGaugeArtifactCodec() {
  return {"step_gauge", readStepGauge};
}

}  // namespace artcal
