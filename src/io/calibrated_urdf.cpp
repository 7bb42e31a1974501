// The URDF of a calibrated chain machine (io/calibrated_urdf.hpp).

#include "artcal/io/calibrated_urdf.hpp"

#include "artcal/calibration/corrections.hpp"
#include "artcal/io/chain_codec.hpp"
#include "artcal/io/urdf.hpp"

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

}  // namespace

CalibratedUrdf calibratedUrdf(const nlohmann::json& machine, const std::string& machine_source,
                              const std::string& urdf_path) {
  const MachineBlock block = readChainMachine(machine, machine_source);
  const auto& chain = static_cast<const Chain&>(*block.mechanism);
  CalibratedUrdf out;
  out.text = exportUrdf(chain, block.nominal, urdf_path, machine_source);
  out.warnings = implausibleCorrectionLines(block, urdfNominal(chain, block.nominal, urdf_path));
  return out;
}

}  // namespace artcal
