#pragma once
// The machine-tool machine block (docs/five-axis.md): {"model": "machine-tool",
// "configuration": "trunnion-AC" | "head-B-table-C", "tool_length": L (mm), "pivot_length": P
// (mm, head-B-table-C only), "parameters": {"E_X0C": mm, "E_A0C": deg, ...} (any subset, the
// rest 0; "L" there overrides tool_length)}. joint_limits [[lo, hi] x 5] (mm, deg) are required
// for the linear axes, as for every prismatic joint.

#include "artcal/io/model_registry.hpp"

namespace artcal {

ModelCodec machineToolCodec();

}  // namespace artcal
