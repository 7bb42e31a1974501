#include "artcal/io/machine_tool_codec.hpp"

#include <memory>

#include "artcal/model/machine_tool.hpp"

namespace artcal {

namespace {

MachineBlock readMachineTool(const Node& machine, std::vector<std::string>& warnings) {
  machine.warnUnknown({"configuration", "tool_length", "pivot_length", "parameters"}, warnings);
  const Node configuration_node = machine.at("configuration");
  const std::string name = configuration_node.string();
  const auto named = fromName(kMachineToolConfigurationNames, name);
  if (!named) configuration_node.fail("expected \"trunnion-AC\" or \"head-B-table-C\"");
  const MachineToolConfiguration configuration = *named;
  const bool head = configuration == MachineToolConfiguration::HeadBTableC;
  double pivot = 0.0;
  if (head) {
    pivot = machine.at("pivot_length").nonNegative();
  } else if (const auto extra = machine.find("pivot_length")) {
    extra->fail("pivot_length belongs to head-B-table-C only (the trunnion has no head axis)");
  }
  auto tool = std::make_shared<MachineTool>(configuration, pivot);
  MachineBlock block;
  block.nominal = Eigen::VectorXd::Zero(tool->parameterCount());
  block.nominal[MachineTool::kToolLength] = machine.at("tool_length").number();
  if (const auto parameters = machine.find("parameters")) {
    for (const auto& [key, value] : parameters->object().items()) {
      const int index = tool->parameterIndex(key);
      const Node entry = parameters->at(key);
      if (index < 0) {
        std::string names;
        for (const ParameterInfo& info : tool->parameters()) names += " " + info.name;
        entry.fail("unknown parameter of machine-tool " + name + " (expected one of" + names + ")");
      }
      block.nominal[index] = fromFileUnit(
          tool->parameters()[static_cast<std::size_t>(index)].quantity, entry.number());
    }
  }
  block.mechanism = std::move(tool);
  return block;
}

void writeMachineTool(const Mechanism& mechanism, const Eigen::VectorXd& parameters,
                      nlohmann::json& out) {
  const auto& tool = dynamic_cast<const MachineTool&>(mechanism);
  out["configuration"] = machineToolConfigurationName(tool.configuration());
  out["tool_length"] = parameters[MachineTool::kToolLength];
  if (tool.configuration() == MachineToolConfiguration::HeadBTableC)
    out["pivot_length"] = tool.pivotLength();
  nlohmann::json values = nlohmann::json::object();
  for (int i = 0; i < tool.parameterCount(); ++i) {
    if (i == MachineTool::kToolLength) continue;
    const ParameterInfo& info = tool.parameters()[static_cast<std::size_t>(i)];
    values[info.name] = toFileUnit(info.quantity, parameters[i]);
  }
  out["parameters"] = values;
}

}  // namespace

ModelCodec machineToolCodec() {
  return {"machine-tool", readMachineTool, writeMachineTool};
}

}  // namespace artcal
