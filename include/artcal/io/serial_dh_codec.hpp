#pragma once
// The serial-dh machine block (docs/plan-format.md): {"model": "serial-dh", "joints": [{"type":
// "revolute" | "prismatic", "theta": deg, "d": mm, "a": mm, "alpha": deg}, ...], "probe": [x, y,
// z] mm}; absent DH values are 0.

#include "artcal/io/model_registry.hpp"

namespace artcal {

ModelCodec serialDhCodec();

}  // namespace artcal
