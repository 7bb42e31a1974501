// The URDF of a calibrated chain machine (io/calibrated_urdf.hpp).

#include "artcal/io/calibrated_urdf.hpp"

#include "artcal/core/error.hpp"

#include "artcal/calibration/corrections.hpp"
#include "artcal/io/chain_codec.hpp"
#include "artcal/io/urdf.hpp"
#include "artcal/io/urdf_origin_edit.hpp"

#include <cctype>
#include <set>
#include <sstream>

#include "artcal/model/joint_compliance.hpp"

namespace artcal {

namespace {

/// The corrections of `block` against the URDF's own origins (`nominal`) a metrologist would not
/// believe, one line each.
std::vector<std::string> implausibleCorrectionLines(const MachineBlock& block,
                                                    const Eigen::VectorXd& nominal) {
  Machine machine;
  machine.mechanism = block.mechanism;
  machine.nominal = nominal;
  for (int i = 0; i < block.mechanism->parameterCount(); ++i) machine.calibrated.push_back(i);
  std::vector<std::string> lines;
  for (const ImplausibleCorrection& c : implausibleCorrections(machine, nominal, block.nominal))
    lines.push_back(describeCorrection(machine, c));
  return lines;
}

/// The model indices of a machine block's (or a plan's machine's) "calibrate" list; empty (every
/// joint) when it is not a list of names of the model.
std::vector<int> calibratedIndices(const nlohmann::json& machine, const Mechanism& mechanism) {
  std::vector<int> out;
  const nlohmann::json& block = machine.contains("machine") ? machine.at("machine") : machine;
  const auto list = block.find("calibrate");
  if (list == block.end() || !list->is_array()) return out;
  for (const nlohmann::json& name : *list) {
    const int k = name.is_string() ? mechanism.parameterIndex(name.get<std::string>()) : -1;
    if (k < 0) return {};
    out.push_back(k);
  }
  return out;
}

// docs/compliance.md section 5: each reading's compliance in its file unit, and the gravity.
std::string complianceYaml(const Mechanism& mechanism, const Eigen::VectorXd& p) {
  const JointCompliance* compliance = mechanism.jointCompliance();
  if (!compliance) return {};
  std::ostringstream out;
  out.precision(10);
  const Eigen::Vector3d& g = compliance->complianceSpec().gravity;
  out << "# Joint compliance (artcal, docs/compliance.md): a URDF cannot carry it.\n"
      << "# A joint's deflection is compliance x gravity torque (payload included), added to its\n"
      << "# reading.\ngravity: [" << g[0] << ", " << g[1] << ", " << g[2]
      << "]  # m/s^2, base frame\n"
      << "joints:\n";
  for (const int k : compliance->complianceParameters()) {
    const ParameterInfo& info = mechanism.parameters()[static_cast<std::size_t>(k)];
    std::string joint = info.name;
    joint.resize(joint.size() - std::string(".compliance").size());
    out << "  " << joint << ": {compliance: " << toFileUnit(info.quantity, p[k]) << ", unit: \""
        << unitName(info.quantity) << "\"}\n";
  }
  return out.str();
}

}  // namespace

CalibratedUrdf calibratedUrdf(const nlohmann::json& machine, const std::string& machine_source,
                              const std::string& urdf_path) {
  const MachineBlock block = readChainMachine(machine, machine_source);
  const auto& chain = static_cast<const Chain&>(*block.mechanism);
  CalibratedUrdf out;
  out.text = exportUrdf(chain, block.nominal, urdf_path, machine_source,
                        calibratedIndices(machine, chain));
  out.warnings = implausibleCorrectionLines(block, urdfNominal(chain, block.nominal, urdf_path));
  out.compliance_yaml = complianceYaml(chain, block.nominal);
  return out;
}

namespace {

// A xacro property name of a joint name: [A-Za-z0-9_] kept, every other character '_'.
std::string propertyStem(const std::string& joint) {
  std::string out = joint;
  for (char& c : out)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') c = '_';
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "_" + out;
  return out;
}

std::string tripleText(const Eigen::Vector3d& v) {
  return shortestNumber(v[0]) + " " + shortestNumber(v[1]) + " " + shortestNumber(v[2]);
}

}  // namespace

XacroProperties calibratedXacro(const nlohmann::json& machine, const std::string& machine_source,
                                const std::string& urdf_path) {
  const MachineBlock block = readChainMachine(machine, machine_source);
  const auto& chain = static_cast<const Chain&>(*block.mechanism);
  // Every chain joint's: the same properties whatever a calibration calibrates, so that the
  // description's joints use them once and a later calibration replaces the file only.
  const std::vector<OriginEdit> origins =
      calibratedOrigins(chain, block.nominal, urdf_path, machine_source);
  std::ostringstream text;
  text << "<?xml version=\"1.0\"?>\n<!-- artcal export-xacro of " << machine_source << " for "
       << urdf_path
       << ": the calibrated joint origins (xyz m, rpy rad; joint offsets folded in as export-urdf\n"
          "     does). Include it and use the properties in each joint's origin:\n"
          "     <xacro:include filename=\"THIS FILE\"/>\n"
          "     <origin xyz=\"${JOINT_origin_xyz}\" rpy=\"${JOINT_origin_rpy}\"/>\n"
          "     Not carried: the parameters' uncertainties (the machine file's covariance). -->\n"
       << "<robot xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n";
  nlohmann::json values = nlohmann::json::array();
  std::set<std::string> stems;
  for (const OriginEdit& o : origins) {
    const std::string stem = propertyStem(o.joint);
    if (!stems.insert(stem).second)
      throw InputError(urdf_path, "",
                       "joints \"" + o.joint + "\" and another share the property name \"" + stem +
                           "_origin_xyz\": rename one");
    text << "  <xacro:property name=\"" << stem << "_origin_xyz\" value=\"" << tripleText(o.xyz_m)
         << "\"/>\n  <xacro:property name=\"" << stem << "_origin_rpy\" value=\""
         << tripleText(o.rpy) << "\"/>\n";
    values.push_back({{"joint", o.joint},
                      {"xyz_property", stem + "_origin_xyz"},
                      {"rpy_property", stem + "_origin_rpy"},
                      {"xyz_m", {o.xyz_m[0], o.xyz_m[1], o.xyz_m[2]}},
                      {"rpy_rad", {o.rpy[0], o.rpy[1], o.rpy[2]}}});
  }
  text << "</robot>\n";
  XacroProperties out;
  out.warnings = implausibleCorrectionLines(block, urdfNominal(chain, block.nominal, urdf_path));
  out.text = text.str();
  out.summary = {
      {"format", "xacro-properties"},
      {"values", values},
      {"not_carried",
       {{{"name", "uncertainty"},
         {"why", "a xacro property holds a value only: the machine file's covariance"}},
        {{"name", "joints not using the properties"},
         {"why", "the description must use each property in its joint's <origin> (once)"}}}}};
  return out;
}

}  // namespace artcal
