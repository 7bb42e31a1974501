#include "artcal/io/model_registry.hpp"

#include "artcal/io/cartesian_codec.hpp"
#include "artcal/io/chain_codec.hpp"
#include "artcal/io/hexapod_codec.hpp"
#include "artcal/io/planar2r_codec.hpp"
#include "artcal/io/serial_dh_codec.hpp"

namespace artcal {

const std::vector<ModelCodec>& modelCodecs() {
  // The registry: one line per family (model_registry.hpp says how to add one).
  static const std::vector<ModelCodec> codecs = {
      planar2rCodec(), serialDhCodec(), hexapodCodec(), cartesianCodec(), chainCodec(),
  };
  return codecs;
}

const ModelCodec* findModelCodec(const std::string& name) {
  for (const ModelCodec& codec : modelCodecs()) {
    if (codec.name == name) return &codec;
  }
  return nullptr;
}

std::string modelNameList() {
  const auto& codecs = modelCodecs();
  std::string out;
  for (std::size_t i = 0; i < codecs.size(); ++i) {
    if (i > 0) out += i + 1 == codecs.size() ? " or " : ", ";
    out += codecs[i].name;
  }
  return out;
}

}  // namespace artcal
