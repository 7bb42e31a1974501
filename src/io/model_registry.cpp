#include "artcal/io/model_registry.hpp"

#include <array>

#include "artcal/io/cartesian_codec.hpp"
#include "artcal/io/chain_codec.hpp"
#include "artcal/io/hexapod_codec.hpp"
#include "artcal/io/machine_tool_codec.hpp"
#include "artcal/io/planar2r_codec.hpp"
#include "artcal/io/serial_dh_codec.hpp"

namespace artcal {

const std::vector<ModelCodec>& modelCodecs() {
  // The registry: one line per family (model_registry.hpp says how to add one).
  static const std::vector<ModelCodec> codecs = {
      planar2rCodec(),  serialDhCodec(), hexapodCodec(),
      cartesianCodec(), chainCodec(),    machineToolCodec(),
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

MachineBlock readOwnMembers(const ModelCodec& codec, const Node& machine,
                            std::vector<std::string>& warnings) {
  static constexpr std::array<const char*, 6> kShared = {"model",      "calibrate", "joint_limits",
                                                         "covariance", "prior",     "frames"};
  nlohmann::json own = machine.object();
  for (const char* shared : kShared) own.erase(shared);
  const Node own_node = Node(own, machine.pointer(), machine.source()).withSuggestions(kShared);
  return codec.read(own_node, warnings);
}

}  // namespace artcal
