#pragma once
// The step gauge in a plan file (docs/plan-format.md): faces along its axis.

#include "artcal/io/artifact_registry.hpp"

namespace artcal {

/// `{"type": "step_gauge", "positions": [mm, ...], "u": mm}`: distinct positions.
ArtifactCodec stepGaugeArtifactCodec();

}  // namespace artcal
