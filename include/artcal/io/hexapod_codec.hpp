#pragma once
// The hexapod machine block (docs/models.md section 3): {"model": "hexapod", "base": [6 x [x, y,
// z]], "platform": [6 x [x, y, z]], "probe": [x, y, z], "home": {"xyz": [mm], "rpy": [deg]},
// optional "offsets": [6 leg offsets, mm] (default 0; a calibrated machine writes its estimates
// here)}. The leg ranges are the machine's joint_limits (required: the legs are prismatic).

#include "artcal/io/model_registry.hpp"

namespace artcal {

ModelCodec hexapodCodec();

}  // namespace artcal
