#include "artcal/io/planar2r_codec.hpp"

#include <memory>

#include "artcal/model/planar2r.hpp"

namespace artcal {

namespace {

MachineBlock readPlanar2R(const Node& machine, std::vector<std::string>& warnings) {
  machine.warnUnknown({"parameters"}, warnings);
  MachineBlock block;
  auto mechanism = std::make_shared<Planar2R>();
  const Node params = machine.at("parameters");
  params.object();
  // Read before the comma initializer: an InputError thrown inside it would unwind through
  // Eigen's CommaInitializer destructor, which asserts that every coefficient was given.
  const double l1 = params.at("l1").positive();
  const double l2 = params.at("l2").positive();
  const double dt2 = degToRad(params.find("dt2") ? params.at("dt2").number() : 0.0);
  block.nominal.resize(3);
  block.nominal << l1, l2, dt2;
  for (const auto& [key, v] : params.object().items()) {
    if (mechanism->parameterIndex(key) < 0) {
      params.at(key).fail("unknown parameter of planar2r (expected l1, l2, dt2)");
    }
  }
  block.mechanism = std::move(mechanism);
  return block;
}

void writePlanar2R(const Mechanism& mechanism, const Eigen::VectorXd& parameters,
                   nlohmann::json& out) {
  for (int i = 0; i < mechanism.parameterCount(); ++i) {
    const ParameterInfo& info = mechanism.parameters()[static_cast<std::size_t>(i)];
    out["parameters"][info.name] = toFileUnit(info.quantity, parameters[i]);
  }
}

}  // namespace

ModelCodec planar2rCodec() {
  return {"planar2r", readPlanar2R, writePlanar2R};
}

}  // namespace artcal
