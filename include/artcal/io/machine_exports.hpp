#pragma once
// Exports of a calibrated machine file (`calibrate --write-machine`) to what a controller or a
// robot description loads (docs/exports.md). Each export is the file's text and a JSON summary:
// the values written (with their status and u), and what the format cannot carry.
//   - LinuxCNC xyzac-trt-kins (trunnion-AC machine tools): the HAL pins the kinematics reads,
//     x/y/z-rot-point, y-offset and z-offset (trtfuncs of LinuxCNC 2.9 and later); the location
//     errors its exact A and C axes and square slides cannot hold are listed, not written.
//   - Universal Robots kinematics_config YAML (serial-dh arms of 6 revolute joints): the six
//     joint origins ur_description builds its URDF from (metres, radians); the fixed transform
//     after the last joint and the probe (the TCP) are listed, not written.
// The chain's xacro properties live with the URDF export (io/calibrated_urdf.hpp).

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "artcal/calibration/verification.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// A machine file read as a plan of that machine alone: plan.machine.nominal holds the file's
/// (calibrated) values, plan.machine.calibrated its "calibrate" list (the determined ones).
struct MachineFile {
  Plan plan;
  std::optional<ParameterUncertainty> uncertainty;  ///< the file's "covariance"
  nlohmann::json document;
  std::string source;
};
/// InputError naming `source` and the pointer.
MachineFile readMachineFile(const nlohmann::json& document, const std::string& source);

/// An export: the file's text and its summary ({"format", "values": [...], "not_carried":
/// [...]}, file units stated in each entry).
struct MachineExport {
  std::string text;
  nlohmann::json summary;
};

/// LinuxCNC xyzac-trt-kins of a trunnion-AC machine tool. `pivot`: LinuxCNC's machine
/// coordinates (mm) of the slides where artcal's readings X, Y, Z are zero (the nominal pivot
/// with a tool of length L reaching it sits at pivot + (0, 0, L)). InputError for another
/// model or configuration.
MachineExport linuxcncExport(const MachineFile& file, const Eigen::Vector3d& pivot);

/// Universal Robots' kinematics_config YAML of a serial-dh arm with 6 revolute joints.
/// InputError for another model.
MachineExport urKinematicsExport(const MachineFile& file);

/// A summary as a table for a person: the values, then what the format cannot carry.
std::string exportSummaryTable(const nlohmann::json& summary);

}  // namespace artcal
