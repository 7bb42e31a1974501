#include "artcal/io/serial_dh_codec.hpp"

#include <memory>

#include "artcal/io/compliance_block.hpp"
#include "artcal/model/serial_dh.hpp"

namespace artcal {

namespace {

JointKind readJointKind(const Node& joint) {
  const auto type = joint.find("type");
  if (!type) return JointKind::Revolute;
  const std::string t = type->string();
  if (t == "prismatic") return JointKind::Prismatic;
  if (t != "revolute")
    type->fail("unknown joint type \"" + t + "\" (expected revolute or prismatic)");
  return JointKind::Revolute;
}

DHConvention readConvention(const Node& machine) {
  const auto convention = machine.find("convention");
  if (!convention) return DHConvention::Standard;
  const std::string c = convention->string();
  if (const auto known = fromName(kDHConventionNames, c)) return *known;
  convention->fail("unknown convention \"" + c + "\" (expected standard or modified)");
}

// docs/compliance.md, docs/plan-format.md: {"gravity": [..], "masses": [one per joint: link i's
// mass, centre in frame i], "values": [C_i per joint, deg/(N m) or mm/N; default 0]}. The values
// are appended to `values` (the parameters after the probe's).
ComplianceSpec readDhCompliance(const Node& compliance, const std::vector<DHJoint>& joints,
                                std::vector<double>& values, std::vector<std::string>& warnings) {
  compliance.object();
  compliance.warnUnknown({"gravity", "masses", "values"}, warnings);
  ComplianceSpec spec;
  spec.gravity = readGravity(compliance);
  const Node masses = compliance.at("masses");
  masses.arraySize(joints.size(), joints.size());
  for (std::size_t i = 0; i < joints.size(); ++i)
    spec.masses.push_back(readMassPoint(masses[i], warnings));
  const auto given = compliance.find("values");
  if (given) given->arraySize(joints.size(), joints.size());
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const double v = given ? (*given)[i].number() : 0.0;
    values.push_back(joints[i].kind == JointKind::Revolute ? fromFileUnit(kDegreePerNewtonMetre, v)
                                                           : fromFileUnit(kMillimetrePerNewton, v));
  }
  return spec;
}

// docs/models.md section 2: a joint may carry a Hayati "beta" (deg); jN.beta exists only then.
MachineBlock readSerialDH(const Node& machine, std::vector<std::string>& warnings) {
  machine.warnUnknown({"joints", "probe", "convention", "compliance"}, warnings);
  const DHConvention convention = readConvention(machine);
  const Node joints = machine.at("joints");
  const std::size_t n = joints.arraySize(1, SerialDH::kMaxJoints);
  std::vector<DHJoint> dh_joints;
  std::vector<double> values;
  for (std::size_t i = 0; i < n; ++i) {
    const Node joint = joints[i];
    joint.object();
    joint.warnUnknown({"type", "theta", "d", "a", "alpha", "beta"}, warnings);
    dh_joints.push_back({readJointKind(joint), joint.has("beta")});
    auto value = [&](const char* key) { return joint.find(key) ? joint.at(key).number() : 0.0; };
    values.insert(values.end(),
                  {degToRad(value("theta")), value("d"), value("a"), degToRad(value("alpha"))});
    if (dh_joints.back().has_beta) values.push_back(degToRad(value("beta")));
  }
  const Eigen::VectorXd probe = machine.at("probe").numbers(3);
  values.insert(values.end(), probe.data(), probe.data() + 3);
  std::optional<ComplianceSpec> compliance;
  if (const auto node = machine.find("compliance"))
    compliance = readDhCompliance(*node, dh_joints, values, warnings);
  MachineBlock block;
  block.nominal = Eigen::Map<Eigen::VectorXd>(values.data(), static_cast<int>(values.size()));
  block.mechanism =
      std::make_shared<SerialDH>(std::move(dh_joints), convention, std::move(compliance));
  return block;
}

void writeSerialDH(const Mechanism& mechanism, const Eigen::VectorXd& parameters,
                   nlohmann::json& out) {
  const auto& arm = static_cast<const SerialDH&>(mechanism);  // made by readSerialDH
  auto fileValue = [&](int i) {
    return toFileUnit(arm.parameters()[static_cast<std::size_t>(i)].quantity, parameters[i]);
  };
  nlohmann::json joints = nlohmann::json::array();
  for (int j = 0; j < arm.jointCount(); ++j) {
    const int k = arm.parameterOffset(j);
    nlohmann::json joint = {
        {"type", arm.jointKind(j) == JointKind::Revolute ? "revolute" : "prismatic"},
        {"theta", fileValue(k)},
        {"d", fileValue(k + 1)},
        {"a", fileValue(k + 2)},
        {"alpha", fileValue(k + 3)}};
    if (arm.hasBeta(j)) joint["beta"] = fileValue(k + 4);
    joints.push_back(joint);
  }
  if (arm.convention() == DHConvention::Modified)
    out["convention"] = nameOf(kDHConventionNames, arm.convention());
  out["joints"] = joints;
  const int k = arm.probeParameterOffset();
  out["probe"] = {fileValue(k), fileValue(k + 1), fileValue(k + 2)};
  if (!arm.jointCompliance()) return;
  nlohmann::json compliance, masses = nlohmann::json::array(), values = nlohmann::json::array();
  writeGravity(arm.complianceSpec(), compliance);
  for (const MassPoint& mass : arm.complianceSpec().masses) masses.push_back(massPointToJson(mass));
  for (const int c : arm.complianceParameters()) values.push_back(fileValue(c));
  compliance["masses"] = masses;
  compliance["values"] = values;
  out["compliance"] = compliance;
}

}  // namespace

ModelCodec serialDhCodec() {
  return {"serial-dh", readSerialDH, writeSerialDH};
}

}  // namespace artcal
