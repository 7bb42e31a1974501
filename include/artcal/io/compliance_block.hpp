#pragma once
// The parts of a machine block's "compliance" (docs/compliance.md, docs/plan-format.md) that every
// serial family's codec reads alike: a mass {"mass": kg, "centre": [x, y, z] mm}, the gravity
// vector (m/s^2, base frame) and a payload (the same form as a mass, its centre in the tip
// frame). Each family's codec reads its own list of masses and values with them.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "artcal/io/json_node.hpp"
#include "artcal/model/joint_compliance.hpp"

namespace artcal {

/// {"mass": kg (>= 0), "centre": [x, y, z] mm (default 0)}.
MassPoint readMassPoint(const Node& node, std::vector<std::string>& warnings);
/// The compliance block's "gravity" (m/s^2), kDefaultGravity when absent.
Eigen::Vector3d readGravity(const Node& compliance);
nlohmann::json massPointToJson(const MassPoint& mass);
/// The members every family's compliance block writes besides its masses and values.
void writeGravity(const ComplianceSpec& spec, nlohmann::json& compliance);

}  // namespace artcal
