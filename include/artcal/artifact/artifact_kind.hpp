#pragma once
// What an artifact kind is to the layers above it: its rows, its rigid motions, how the
// planner, the estimator and the report treat its readings. Each kind is one object in its own
// file (src/artifact/<kind>.cpp) that its factory puts on every artifact it builds; the plan
// format reaches it through the kind's codec, one line of the registry (io/artifact_registry.hpp).
// The layers ask the kind what it does, never which kind it is.

#include <string>
#include <vector>

namespace artcal {

class Artifact;

/// The full rigid motion's directions (translation, rotation: 2-D tx, ty, rz; 3-D tx, ty, tz,
/// wx, wy, wz) in the order the observation blocks use, and the leading ones the artifact's
/// table counts (N(r_j), docs/method.md section 1).
struct RigidOrders {
  std::vector<int> full;
  std::vector<int> table;
};

/// Every direction of the full rigid motion in 2-D and 3-D (a ball plate, an instrument's
/// station, a cube corner): the order the kinds share.
const RigidOrders& everyRigidDirection(int dimension);
/// What faces normal to X see (a step gauge, a plane, a gauge block): the translation along X
/// and the turns that tilt X.
const RigidOrders& rigidDirectionsMovingX(int dimension);
/// The translations alone (a sphere's centre, which no turn about it moves).
const RigidOrders& rigidTranslations(int dimension);

struct ArtifactKind {
  /// The plan format's artifact "type" ("ball_bar", "plane", ...).
  const char* name;
  /// A reading values one coordinate of its feature (a step gauge's face along its axis, a
  /// plane's face along its normal) rather than all of them (a ball's centre).
  bool one_valued_coordinate = false;
  /// Placements are an instrument's stations: each reading brings its own point, appended as a
  /// feature (docs/instruments.md), and a design places stations, not the artifact.
  bool readings_are_features = false;
  /// Readings touch a face anywhere on it (docs/planes.md): each is a distance along the face's
  /// normal (estimation/plane_rows.hpp), planned as touches spread over the face, and the
  /// placement starts from the plan's pose (the touches do not locate it).
  bool touches_faces = false;
  /// The report draws the features joined by a line (a bar, a gauge, a station's track); a
  /// ball plate's grid is drawn as its balls alone.
  bool drawn_as_line = true;
  /// A 3-D design also turns the artifact about its normal (a ball plate's roll).
  bool design_rolls = false;
  /// What a placement's centre is when its translations alone place it (translatesOnly()).
  const char* centre = "the artifact's centre";
  /// The rigid motions of an artifact of this kind (its dimension, its shape).
  const RigidOrders& (*rigid_orders)(const Artifact&) = nullptr;
  /// What a person calls the artifact when the kind's name does not say it all ("ball_bar
  /// (table-spindle)"); null for the kind's name.
  std::string (*type_name)(const Artifact&) = nullptr;
};

}  // namespace artcal
