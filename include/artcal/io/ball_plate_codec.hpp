#pragma once
// The ball plate in a plan file (docs/plan-format.md): calibrated ball centres.

#include "artcal/io/artifact_registry.hpp"

namespace artcal {

/// `{"type": "ball_plate", "centers": [[x, y(, z)], ...], "u": mm}`: distinct centres, not
/// collinear in 3-D.
ArtifactCodec ballPlateArtifactCodec();

}  // namespace artcal
