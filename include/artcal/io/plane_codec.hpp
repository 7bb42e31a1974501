#pragma once
// The plane artifact in a plan file (docs/planes.md): `"type": "plane"` with its shape (one plane,
// a gauge block, a cube corner), what a reading measures (a ball's point contact or a flush
// contact of the tip frame) and its stated uncertainties. Faults raise InputError with the JSON
// pointer.

#include <string>
#include <vector>

#include "artcal/io/artifact_registry.hpp"
#include "artcal/io/json_node.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// `{"type": "plane", "shape": "plane" | "gauge_block" | "cube_corner", "measures": "point" |
/// "flush", "radius": mm, "axis": [x, y, z], "flatness": mm, "u_tilt": deg, "length": mm,
/// "u_length": mm}`. "flush" needs a 3-D model whose forward kinematics gives an orientation.
ArtifactCodec planeArtifactCodec();

}  // namespace artcal
