#include "artcal/io/compliance_block.hpp"

namespace artcal {

MassPoint readMassPoint(const Node& node, std::vector<std::string>& warnings) {
  node.object();
  node.warnUnknown({"mass", "centre"}, warnings);
  MassPoint out;
  out.mass = node.at("mass").nonNegative();
  if (const auto centre = node.find("centre")) out.centre = centre->numbers(3);
  return out;
}

Eigen::Vector3d readGravity(const Node& compliance) {
  const auto gravity = compliance.find("gravity");
  return gravity ? Eigen::Vector3d(gravity->numbers(3)) : kDefaultGravity;
}

nlohmann::json massPointToJson(const MassPoint& mass) {
  return {{"mass", mass.mass}, {"centre", {mass.centre[0], mass.centre[1], mass.centre[2]}}};
}

void writeGravity(const ComplianceSpec& spec, nlohmann::json& compliance) {
  compliance["gravity"] = {spec.gravity[0], spec.gravity[1], spec.gravity[2]};
}

}  // namespace artcal
