#pragma once
// `artcal import-readings`: a plan from a folder of CSV readings and a machine
// (docs/plan-format.md, "A plan from a folder of CSV files"; docs/calibrate-your-robot.md).
//
// Layout: DIR holds one sub-folder per artifact placement (the placement is named after it); each
// sub-folder holds one CSV file per feature, one posture's joint readings per row (docs/models.md
// section 7):
//   - MUKCa's layout: `hole_<k>.csv`, joint angles in rad, no header (`hole_<k>_pose.csv`, the
//     controller's own pose, is ignored);
//   - the general layout: `feature_<k>.csv`, whose header names each column's unit as its last
//     word: `q1_deg, q2_deg, ...`, `joint1 [rad]`, `z (mm)`; units deg, rad, mm or m.
// A folder whose files are themselves feature files (no sub-folders) is one placement; so is each
// CSV file given instead of DIR (its rows are feature 0's readings). Sub-folders
// are taken in name order, features in index order. Every fault is an InputError naming the folder
// or file.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace artcal {

struct ReadingsImport {
  std::string folder;  ///< DIR (used when `inputs` is empty)
  /// DIR, or CSV files of one placement each (named after the file, its rows feature 0's
  /// readings, a plane's touches: docs/planes.md).
  std::vector<std::string> inputs;
  /// The machine: a machine block file (import-urdf, calibrate --write-machine) ...
  std::string machine_file;
  /// ... or a URDF chain from `base` to `tip` (imported as import-urdf does).
  std::string urdf, base, tip;
  /// Several tips of one machine (import-urdf's repeated --tip; `tip` unused then), and which tip
  /// touched in each placement: placement name -> tip name (a tip of the machine).
  std::vector<std::string> tips;
  std::vector<std::pair<std::string, std::string>> tip_of;
  /// The artifact: a ball bar of this length (mm) ...
  std::optional<double> ball_bar;
  double u_length = 0.0;
  /// ... or an artifacts block ({"id": {"type": ...}}) read from this file (its first artifact is
  /// placed).
  std::string artifact_file;
  /// ... or an instrument (a laser tracker, a total station) of this noise, mm per coordinate
  /// (instruments.md): DIR then holds one CSV file per station (or one sub-folder of CSV files
  /// per station), each row the joint readings then the measured x, y, z; an artifacts block
  /// whose first artifact is an instrument reads DIR the same way.
  std::optional<double> instrument;
  /// With `instrument`: the instrument measures poses (a 6-DOF tracker), of this orientation noise
  /// (deg per rotation-vector coordinate, the plan's `noise_angle`); each row is then the joint
  /// readings, x, y, z, then the orientation as a rotation vector rx, ry, rz.
  std::optional<double> instrument_angle;
  /// The measured points' unit ("mm" or "m") for every station file, overriding the header's.
  std::string point_unit;
  /// A pose's orientation unit ("deg" or "rad") for every station file, overriding the header's.
  std::string orientation_unit;
  /// noise.probe (mm, or "estimate" where the plan format allows it) and noise.encoder (deg).
  nlohmann::json probe = 0.1;
  double encoder = 0.0;
  /// The readings' unit for every file ("deg", "rad", "mm", "m"), overriding the layout's.
  std::string unit;
  /// Files whose header names its columns (docs/plan-format.md, "Columns by name"): the markers
  /// whose <name>_x, <name>_y, <name>_z an instrument's readings take (empty: the header's only
  /// one). Several: each row is one reading of each marker, each marker a tip of its own
  /// (withMarkerTips: a fixed joint "marker_<name>" after the chain's last joint).
  std::vector<std::string> markers;
  /// A pose's orientation columns: "rotation_vector", "rpy" (roll, pitch, yaw: the URDF's
  /// fixed-axis x-y-z, R = Rz(yaw) Ry(pitch) Rx(roll)) or "quaternion" (w, x, y, z); empty: what
  /// the header names (rotation_vector for a file without names).
  std::string orientation;
  /// Joints no file reads, held at a value (deg, or mm for a prismatic joint), by reading name.
  std::vector<std::pair<std::string, double>> holds;
  /// The machine's tolerances as built, a prior on every parameter (plan-format.md, "prior":
  /// default.length mm, default.angle deg); 0: none (a machine file's own prior is kept).
  double prior_length = 0.0, prior_angle = 0.0;
  /// Keep the machine file's own "calibrate" instead of "identifiable".
  bool keep_calibrate = false;
  /// Keep the machine's joint limits even where the readings pass them (they are then refused).
  bool keep_limits = false;
  /// Where the plan will be written: CSV paths are made relative to its folder ("" or "-": the
  /// current folder).
  std::string output;
};

struct ImportedPlan {
  nlohmann::json plan;  ///< the plan document (artcal-plan/1)
  /// What errors in the plan name it by: the output path, or "import-readings" for stdout. CSV
  /// paths in the plan are relative to its folder.
  std::string source;
  /// CSV files under the folder not read (one line), joint limits widened to the readings,
  /// columns of header-named files that were not read.
  std::vector<std::string> warnings;
};

/// The plan of the import. Joint limits: a real robot's readings may pass the limits its URDF
/// states (the Kinova Gen3 lite's joint 6 reads up to 157 deg against 120); the machine reported
/// them, so a revolute joint's limits are widened to its readings' range, with a warning, as long
/// as that stays within +-360 deg (beyond, the readings are refused like any reading outside
/// its limits: wrong units, not a robot). `keep_limits` widens nothing. The plan is not validated
/// here: the caller parses it (parsePlan) before writing it.
ImportedPlan importReadings(const ReadingsImport& import);

}  // namespace artcal
