#pragma once
// The sphere on a machine tool's table in a plan file (docs/five-axis.md): its probed centre.

#include "artcal/io/artifact_registry.hpp"

namespace artcal {

/// `{"type": "sphere", "diameter": mm}`: 3-D machines only; the diameter is informative.
ArtifactCodec sphereArtifactCodec();

}  // namespace artcal
