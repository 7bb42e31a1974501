#pragma once
// The chain machine block (docs/models.md section 1): {"model": "chain", "joints": [{"name": ...,
// "type": "revolute" | "prismatic" | "fixed", "origin": {"xyz": [mm], "rpy": [deg]}, "axis":
// [x, y, z], "offset": deg or mm}, ...]}. `origin` and its members default to zeros, `offset` to 0
// (a calibrated machine carries it); `axis` is required for a movable joint (normalised).

#include "artcal/io/model_registry.hpp"

namespace artcal {

ModelCodec chainCodec();

/// The chain machine of a machine file: a machine block (as `calibrate --write-machine` writes
/// it) or a document with a "machine" member (a plan). InputError naming `source` otherwise.
MachineBlock readChainMachine(const nlohmann::json& document, const std::string& source);

}  // namespace artcal
