#include "artcal/io/truth_io.hpp"

#include <cmath>

#include "artcal/core/error.hpp"
#include "artcal/io/json_node.hpp"
#include "artcal/io/model_registry.hpp"
#include "artcal/io/plan_io.hpp"

namespace artcal {

namespace {

using nlohmann::json;

// The structure of two machines of one model (names, axes, styli: everything but the parameter
// values) is equal when the codec writes the same block for both with the same parameters; the
// first entry of the JSON diff is the first difference (a machine of another robot).
void checkSameStructure(const Mechanism& mine, const Mechanism& theirs, const Eigen::VectorXd& same,
                        const std::string& source, const std::string& pointer) {
  const ModelCodec* codec = findModelCodec(mine.modelName());
  if (!codec) return;
  for (int i = 0; i < mine.parameterCount(); ++i) {
    const std::string& name = mine.parameters()[static_cast<std::size_t>(i)].name;
    if (theirs.parameters()[static_cast<std::size_t>(i)].name != name) {
      throw InputError(source, pointer.empty() ? "/" : pointer,
                       "parameter " + std::to_string(i + 1) + " is \"" +
                           theirs.parameters()[static_cast<std::size_t>(i)].name +
                           "\", the plan's machine has \"" + name +
                           "\": a machine of another robot?");
    }
  }
  json a, b;
  codec->write(mine, same, a);
  codec->write(theirs, same, b);
  const json patch = json::diff(a, b);
  if (patch.empty()) return;
  const std::string at = patch[0].at("path").get<std::string>();
  const json::json_pointer where(at);
  const auto shown = [&](const json& doc) {
    return doc.contains(where) ? doc.at(where).dump() : std::string("nothing");
  };
  throw InputError(source, pointer + at,
                   "the plan's machine has " + shown(a) + " here, this machine " + shown(b) +
                       ": a machine of another robot?");
}

// A machine block is read by the plan reader itself (one parser for one format): it is wrapped
// in a minimal plan, and the reader's JSON pointers are mapped back into the TRUTH file.
Eigen::VectorXd parseMachineBlock(const json& block, const std::string& source,
                                  const std::string& pointer, const Plan& plan) {
  const json wrapper = {{"format", "artcal-plan/1"},
                        {"machine", block},
                        {"noise", {{"probe", 1.0}, {"encoder", 1.0}}},
                        {"artifacts", {{"a", {{"type", "ball_bar"}, {"length", 1.0}}}}}};
  Plan truth;
  try {
    truth = parsePlan(wrapper, source, false);
  } catch (const InputError& e) {
    std::string where = e.pointer();
    if (where.rfind("/machine", 0) == 0) where = pointer + where.substr(8);
    throw InputError(source, where.empty() ? "/" : where, e.what());
  }
  const Mechanism& mine = *plan.machine.mechanism;
  const Mechanism& theirs = *truth.machine.mechanism;
  if (theirs.modelName() != mine.modelName()) {
    throw InputError(source, pointer + "/model",
                     "expected the plan's model \"" + mine.modelName() + "\", got \"" +
                         theirs.modelName() + "\"");
  }
  if (theirs.jointCount() != mine.jointCount() ||
      theirs.parameterCount() != mine.parameterCount()) {
    throw InputError(source, pointer.empty() ? "/" : pointer,
                     "expected a machine with the plan's " + std::to_string(mine.jointCount()) +
                         " joints, got " + std::to_string(theirs.jointCount()));
  }
  for (int j = 0; j < mine.jointCount(); ++j) {
    if (theirs.jointKind(j) != mine.jointKind(j)) {
      throw InputError(source, pointer + "/joints/" + std::to_string(j) + "/type",
                       "joint type differs from the plan's machine");
    }
  }
  checkSameStructure(mine, theirs, plan.machine.nominal, source, pointer);
  return truth.machine.nominal;
}

void applyNamedParameters(const json& values, const std::string& source, const Plan& plan,
                          Eigen::VectorXd& p) {
  const std::string pointer = "/parameters";
  if (!values.is_object()) throw InputError(source, pointer, "expected an object of name: value");
  const Mechanism& mech = *plan.machine.mechanism;
  for (const auto& [name, value] : values.items()) {
    const int index = mech.parameterIndex(name);
    if (index < 0) {
      throw InputError(source, pointer + "/" + name,
                       "unknown parameter of model " + mech.modelName());
    }
    const std::string where = pointer + "/" + escapePointerToken(name);
    p[index] = fromFileUnit(mech.parameters()[static_cast<std::size_t>(index)].quantity,
                            Node(value, where, source).number());
  }
}

}  // namespace

Eigen::VectorXd parseTruth(const json& document, const std::string& source, const Plan& plan) {
  if (!document.is_object()) throw InputError(source, "/", "expected an object");
  if (document.contains("model")) return parseMachineBlock(document, source, "", plan);
  if (!document.contains("machine") && !document.contains("parameters")) {
    throw InputError(source, "/",
                     "expected a machine block (with \"model\"), \"machine\" or \"parameters\"");
  }
  for (const auto& [key, value] : document.items()) {
    if (key != "machine" && key != "parameters") {
      throw InputError(source, "/" + key, "unknown field (expected machine or parameters)");
    }
  }
  Eigen::VectorXd p = plan.machine.nominal;
  if (document.contains("machine"))
    p = parseMachineBlock(document["machine"], source, "/machine", plan);
  if (document.contains("parameters"))
    applyNamedParameters(document["parameters"], source, plan, p);
  return p;
}

Eigen::VectorXd loadTruth(const std::string& path, const Plan& plan) {
  return parseTruth(readJsonFile(path), path, plan);
}

json truthToJson(const Machine& machine, const Eigen::VectorXd& parameters) {
  json values = json::object();
  const Mechanism& mech = *machine.mechanism;
  for (int i = 0; i < mech.parameterCount(); ++i) {
    const ParameterInfo& info = mech.parameters()[static_cast<std::size_t>(i)];
    values[info.name] = toFileUnit(info.quantity, parameters[i]);
  }
  return {{"parameters", values}};
}

}  // namespace artcal
