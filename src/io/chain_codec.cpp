#include "artcal/io/chain_codec.hpp"

#include "artcal/io/model_registry.hpp"

#include "artcal/io/compliance_block.hpp"

#include <map>
#include <memory>
#include <set>

#include "artcal/model/chain.hpp"

namespace artcal {

namespace {

ChainJointType readJointType(const Node& joint) {
  const Node type = joint.at("type");
  const std::string t = type.string();
  if (const auto known = fromName(kChainJointTypeNames, t)) return *known;
  type.fail("unknown joint type \"" + t + "\" (expected revolute, prismatic or fixed)");
}

Eigen::Vector3d readAxis(const Node& joint) {
  const Node axis = joint.at("axis");
  const Eigen::Vector3d v = axis.numbers(3);
  if (!(v.norm() > 1e-12)) axis.fail("the axis must not be zero");
  return v.normalized();
}

// Appends joint's x y z (mm), roll pitch yaw (rad) and, when movable, offset to `values`.
void readOriginAndOffset(const Node& joint, ChainJointType type, std::vector<double>& values,
                         std::vector<std::string>& warnings) {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero(), rpy = Eigen::Vector3d::Zero();
  if (const auto origin = joint.find("origin")) {
    origin->object();
    origin->warnUnknown({"xyz", "rpy"}, warnings);
    if (origin->has("xyz")) xyz = origin->at("xyz").numbers(3);
    if (origin->has("rpy")) rpy = origin->at("rpy").numbers(3);
  }
  values.insert(values.end(),
                {xyz[0], xyz[1], xyz[2], degToRad(rpy[0]), degToRad(rpy[1]), degToRad(rpy[2])});
  if (!Chain::isMovable(type)) {
    if (joint.has("offset")) joint.at("offset").fail("a fixed joint has no offset");
    return;
  }
  const double offset = joint.find("offset") ? joint.at("offset").number() : 0.0;
  values.push_back(type == ChainJointType::Revolute ? degToRad(offset) : offset);
}

// A joint's "mimic": {"joint": NAME, "multiplier": m, "offset": c} (c in mm or deg; defaults as
// URDF's: m = 1, c = 0).
ChainMimic readMimic(const Node& joint, ChainJointType type, std::vector<std::string>& warnings) {
  const Node mimic = joint.at("mimic");
  mimic.object();
  mimic.warnUnknown({"joint", "multiplier", "offset"}, warnings);
  ChainMimic out;
  out.joint = mimic.at("joint").string();
  if (mimic.has("multiplier")) out.multiplier = mimic.at("multiplier").number();
  const double offset = mimic.has("offset") ? mimic.at("offset").number() : 0.0;
  out.offset = type == ChainJointType::Revolute ? degToRad(offset) : offset;
  return out;
}

// "reversed": true (a joint traversed from its URDF child to its parent); false when absent.
bool readReversed(const Node& joint) {
  const auto reversed = joint.find("reversed");
  if (!reversed) return false;
  if (!reversed->value().is_boolean()) reversed->fail("expected true or false");
  return reversed->value().get<bool>();
}

// "tips": [{"name": N, "joints": [joint names from the base]}, ...] (docs/urdf.md); none: one
// tip through every joint.
std::vector<ChainTip> readTips(const Node& machine, const std::vector<ChainJoint>& chain,
                               std::vector<std::string>& warnings) {
  std::vector<ChainTip> tips;
  const auto list = machine.find("tips");
  if (!list) return tips;
  std::map<std::string, int> index;
  for (std::size_t i = 0; i < chain.size(); ++i) index[chain[i].name] = static_cast<int>(i);
  std::vector<bool> used(chain.size(), false);
  std::set<std::string> names;
  const std::size_t n = list->arraySize(1, static_cast<std::size_t>(Chain::kMaxJoints));
  for (std::size_t t = 0; t < n; ++t) {
    const Node tip = (*list)[t];
    tip.object();
    tip.warnUnknown({"name", "joints"}, warnings);
    ChainTip entry;
    const Node name = tip.at("name");
    entry.name = name.string();
    if (entry.name.empty()) name.fail("a tip name must not be empty");
    if (!names.insert(entry.name).second) name.fail("tip name \"" + entry.name + "\" used twice");
    const Node joints = tip.at("joints");
    const std::size_t m = joints.arraySize(1, chain.size());
    std::set<int> on_path;
    for (std::size_t j = 0; j < m; ++j) {
      const Node joint = joints[j];
      const std::string joint_name = joint.string();
      const auto found = index.find(joint_name);
      if (found == index.end()) joint.fail("no joint named \"" + joint_name + "\" in /joints");
      if (!on_path.insert(found->second).second) {
        joint.fail("joint \"" + joint_name + "\" twice on this tip's path");
      }
      used[static_cast<std::size_t>(found->second)] = true;
      entry.joints.push_back(found->second);
    }
    tips.push_back(std::move(entry));
  }
  for (std::size_t i = 0; i < chain.size(); ++i) {
    if (!used[i]) {
      list->fail("joint \"" + chain[i].name +
                 "\" is on no tip's path (its parameters would move no tip): add it to a tip or "
                 "remove it from /joints");
    }
  }
  return tips;
}

// docs/compliance.md, docs/plan-format.md: {"gravity": [..], "masses": {JOINT: the mass riding
// on the frame after JOINT, centre in that frame}, "values": {READING: C, deg/(N m) or mm/N;
// default 0}}. Joints not in "masses" carry none. The values are appended to `values`.
ComplianceSpec readChainCompliance(const Node& compliance, const std::vector<ChainJoint>& chain,
                                   std::vector<double>& values,
                                   std::vector<std::string>& warnings) {
  compliance.object();
  compliance.warnUnknown({"gravity", "masses", "values"}, warnings);
  ComplianceSpec spec;
  spec.gravity = readGravity(compliance);
  spec.masses.assign(chain.size(), MassPoint{});
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < chain.size(); ++i) index[chain[i].name] = i;
  const Node masses = compliance.at("masses");
  for (const auto& [name, value] : masses.object().items()) {
    (void)value;
    const Node mass = masses.at(name);
    const auto found = index.find(name);
    if (found == index.end()) mass.fail("no joint named \"" + name + "\" in /joints");
    spec.masses[found->second] = readMassPoint(mass, warnings);
  }
  // The readings (driving joints) in order, as Chain resolves them.
  const Chain probe(chain);
  const auto given = compliance.find("values");
  std::set<std::string> readings;
  for (const ChainReading& reading : probe.readings()) {
    readings.insert(reading.name);
    const double v = given && given->has(reading.name) ? given->at(reading.name).number() : 0.0;
    values.push_back(reading.type == ChainJointType::Revolute
                         ? fromFileUnit(kDegreePerNewtonMetre, v)
                         : fromFileUnit(kMillimetrePerNewton, v));
  }
  if (given) {
    for (const auto& [name, value] : given->object().items()) {
      (void)value;
      if (!readings.count(name))
        given->at(name).fail("no reading (driving joint) named \"" + name + "\"");
    }
  }
  return spec;
}

MachineBlock readChain(const Node& machine, std::vector<std::string>& warnings) {
  machine.warnUnknown({"joints", "tips", "compliance"}, warnings);
  const Node joints = machine.at("joints");
  const std::size_t n = joints.arraySize(1, Chain::kMaxJoints);
  std::vector<ChainJoint> chain;
  std::vector<double> values;
  std::set<std::string> names;
  for (std::size_t i = 0; i < n; ++i) {
    const Node joint = joints[i];
    joint.object();
    joint.warnUnknown({"name", "type", "origin", "axis", "offset", "mimic", "reversed"}, warnings);
    const Node name = joint.at("name");
    ChainJoint entry{name.string(), readJointType(joint), Eigen::Vector3d::UnitZ()};
    if (entry.name.empty()) name.fail("a joint name must not be empty");
    if (!names.insert(entry.name).second) name.fail("joint name \"" + entry.name + "\" used twice");
    if (Chain::isMovable(entry.type)) entry.axis = readAxis(joint);
    readOriginAndOffset(joint, entry.type, values, warnings);
    if (joint.has("mimic")) entry.mimic = readMimic(joint, entry.type, warnings);
    entry.reversed = readReversed(joint);
    chain.push_back(std::move(entry));
  }
  if (const auto problem = Chain::mimicProblem(chain)) {
    const Node mimic = joints[static_cast<std::size_t>(problem->joint)].at("mimic");
    (chain[static_cast<std::size_t>(problem->joint)].type == ChainJointType::Fixed
         ? mimic
         : mimic.at("joint"))
        .fail(problem->message);
  }
  std::vector<ChainTip> tips = readTips(machine, chain, warnings);
  std::optional<ComplianceSpec> compliance;
  if (const auto node = machine.find("compliance")) {
    if (!tips.empty()) node->fail("compliance needs a machine of one tip (remove \"tips\")");
    compliance = readChainCompliance(*node, chain, values, warnings);
  }
  MachineBlock block;
  block.nominal = Eigen::Map<Eigen::VectorXd>(values.data(), static_cast<int>(values.size()));
  block.mechanism =
      std::make_shared<Chain>(std::move(chain), std::move(tips), std::move(compliance));
  return block;
}

void writeChain(const Mechanism& mechanism, const Eigen::VectorXd& parameters,
                nlohmann::json& out) {
  const auto& chain = static_cast<const Chain&>(mechanism);  // made by readChain
  auto fileValue = [&](int i) {
    return toFileUnit(chain.parameters()[static_cast<std::size_t>(i)].quantity, parameters[i]);
  };
  nlohmann::json joints = nlohmann::json::array();
  for (int i = 0; i < static_cast<int>(chain.joints().size()); ++i) {
    const ChainJoint& joint = chain.joints()[static_cast<std::size_t>(i)];
    const int k = chain.parameterOffset(i);
    nlohmann::json entry = {{"name", joint.name},
                            {"type", nameOf(kChainJointTypeNames, joint.type)},
                            {"origin",
                             {{"xyz", {fileValue(k), fileValue(k + 1), fileValue(k + 2)}},
                              {"rpy", {fileValue(k + 3), fileValue(k + 4), fileValue(k + 5)}}}}};
    if (Chain::isMovable(joint.type)) {
      entry["axis"] = {joint.axis[0], joint.axis[1], joint.axis[2]};
      entry["offset"] = fileValue(k + 6);
    }
    if (joint.mimic) {
      const double offset = joint.type == ChainJointType::Revolute ? radToDeg(joint.mimic->offset)
                                                                   : joint.mimic->offset;
      entry["mimic"] = {{"joint", joint.mimic->joint},
                        {"multiplier", joint.mimic->multiplier},
                        {"offset", offset}};
    }
    if (joint.reversed) entry["reversed"] = true;
    joints.push_back(entry);
  }
  out["joints"] = joints;
  if (chain.jointCompliance()) {
    nlohmann::json compliance, masses = nlohmann::json::object(), values = nlohmann::json::object();
    writeGravity(chain.complianceSpec(), compliance);
    for (std::size_t i = 0; i < chain.joints().size(); ++i) {
      const MassPoint& mass = chain.complianceSpec().masses[i];
      if (mass.mass != 0.0) masses[chain.joints()[i].name] = massPointToJson(mass);
    }
    for (std::size_t r = 0; r < chain.readings().size(); ++r)
      values[chain.readings()[r].name] = fileValue(chain.complianceParameters()[r]);
    compliance["masses"] = masses;
    compliance["values"] = values;
    out["compliance"] = compliance;
  }
  if (!chain.namesTips()) return;
  nlohmann::json tips = nlohmann::json::array();
  for (const ChainTip& tip : chain.tips()) {
    nlohmann::json path = nlohmann::json::array();
    for (const int j : tip.joints) path.push_back(chain.joints()[static_cast<std::size_t>(j)].name);
    tips.push_back({{"name", tip.name}, {"joints", path}});
  }
  out["tips"] = tips;
}

}  // namespace

ModelCodec chainCodec() {
  return {"chain", readChain, writeChain};
}

MachineBlock readChainMachine(const nlohmann::json& document, const std::string& source) {
  const Node root(document, "", source);
  root.object();
  const Node machine = root.has("model") ? root : root.at("machine");
  const Node model = machine.at("model");
  if (model.string() != "chain") model.fail("expected the model \"chain\" (a URDF chain)");
  std::vector<std::string> warnings;  // extra fields of a plan's machine block do not matter here
  return readOwnMembers(chainCodec(), machine, warnings);
}

}  // namespace artcal
