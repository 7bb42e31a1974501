#pragma once
// `artcal export-urdf --machine M --urdf U`: the URDF with the chain's origins set to a
// (calibrated) machine's (io/urdf.hpp, exportUrdf), and the corrections a metrologist would not
// believe against the URDF's own origins (calibration/corrections.hpp) as warnings. The command
// line and the Python module export here.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace artcal {

struct CalibratedUrdf {
  std::string text;                   ///< the URDF file's text
  std::vector<std::string> warnings;  ///< one per implausible correction (the file is written)
  /// A URDF cannot carry joint compliance (docs/compliance.md section 5): the machine's
  /// compliances as YAML for the user's controller, written apart; empty without compliance.
  std::string compliance_yaml;
};

/// The URDF at `urdf_path` with the origins of the chain machine `machine` (a machine block or a
/// plan, read from `machine_source`). InputError naming the machine or the URDF file.
CalibratedUrdf calibratedUrdf(const nlohmann::json& machine, const std::string& machine_source,
                              const std::string& urdf_path);

/// `artcal export-xacro`: xacro properties of the calibrated origins (docs/exports.md) that a
/// robot description includes (<xacro:include filename="..."/>) and uses in its joints' origins:
/// per chain joint (and per off-chain joint an offset is folded into), "<joint>_origin_xyz" (m)
/// and "<joint>_origin_rpy" (rad), the
/// joint name with every character outside [A-Za-z0-9_] as '_'. `summary`: {"format",
/// "values": [{"joint", "xyz_property", "rpy_property", "xyz_m", "rpy_rad"}], "not_carried"}.
struct XacroProperties {
  std::string text;
  nlohmann::json summary;
  std::vector<std::string> warnings;  ///< as CalibratedUrdf's
};
XacroProperties calibratedXacro(const nlohmann::json& machine, const std::string& machine_source,
                                const std::string& urdf_path);

}  // namespace artcal
