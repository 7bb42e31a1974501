#pragma once
// The ball bar in a plan file (docs/plan-format.md): two balls a calibrated length apart.

#include "artcal/io/artifact_registry.hpp"

namespace artcal {

/// `{"type": "ball_bar", "length": mm, "u_length": mm}`; with `"ends": "table-spindle"` a double
/// ball bar between a ball on the table and the spindle's (five-axis.md section 3), 3-D only.
ArtifactCodec ballBarArtifactCodec();

}  // namespace artcal
