// The URDF of a calibrated chain machine (io/calibrated_urdf.hpp).

#include "artcal/io/calibrated_urdf.hpp"

#include "artcal/calibration/corrections.hpp"
#include "artcal/io/chain_codec.hpp"
#include "artcal/io/urdf.hpp"

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
  out.text = exportUrdf(chain, block.nominal, urdf_path, machine_source);
  out.warnings = implausibleCorrectionLines(block, urdfNominal(chain, block.nominal, urdf_path));
  out.compliance_yaml = complianceYaml(chain, block.nominal);
  return out;
}

}  // namespace artcal
