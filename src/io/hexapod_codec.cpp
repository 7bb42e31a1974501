#include "artcal/io/hexapod_codec.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <memory>

#include "artcal/model/hexapod.hpp"

namespace artcal {

namespace {

// Six points of one frame, written into p at `offset(leg)`.
void readPoints(const Node& points, Eigen::VectorXd& p, int (*offset)(int)) {
  points.arraySize(Hexapod::kLegs, Hexapod::kLegs);
  for (int leg = 0; leg < Hexapod::kLegs; ++leg) {
    p.segment<3>(offset(leg)) = points[static_cast<std::size_t>(leg)].numbers(3);
  }
}

ChainPose readHome(const Node& home, std::vector<std::string>& warnings) {
  home.object();
  home.warnUnknown({"xyz", "rpy"}, warnings);
  ChainPose pose;
  pose.t = home.at("xyz").numbers(3);
  if (const auto rpy = home.find("rpy")) pose.R = rotationFromRpy(rpy->numbers(3) * kDegree);
  return pose;
}

MachineBlock readHexapod(const Node& machine, std::vector<std::string>& warnings) {
  machine.warnUnknown({"base", "platform", "probe", "home", "offsets"}, warnings);
  MachineBlock block;
  Eigen::VectorXd& p = block.nominal;
  p.setZero(Hexapod::kProbeOffset + 3);
  readPoints(machine.at("base"), p, &Hexapod::baseOffset);
  const Node platform = machine.at("platform");
  readPoints(platform, p, &Hexapod::platformOffset);
  if (const auto offsets = machine.find("offsets")) {
    const Eigen::VectorXd values = offsets->numbers(Hexapod::kLegs);
    for (int leg = 0; leg < Hexapod::kLegs; ++leg) p[Hexapod::legOffsetIndex(leg)] = values[leg];
  }
  p.tail<3>() = machine.at("probe").numbers(3);
  double radius = 0.0;
  for (int leg = 0; leg < Hexapod::kLegs; ++leg)
    radius = std::max(radius, p.segment<3>(Hexapod::platformOffset(leg)).norm());
  if (!(radius > 0.0)) platform.fail("platform points must not all be at the platform origin");
  block.mechanism = std::make_shared<Hexapod>(readHome(machine.at("home"), warnings), radius);
  return block;
}

nlohmann::json pointsToJson(const Eigen::VectorXd& p, int (*offset)(int)) {
  nlohmann::json out = nlohmann::json::array();
  for (int leg = 0; leg < Hexapod::kLegs; ++leg) {
    const auto v = p.segment<3>(offset(leg));
    out.push_back({v[0], v[1], v[2]});
  }
  return out;
}

void writeHexapod(const Mechanism& mechanism, const Eigen::VectorXd& p, nlohmann::json& out) {
  const auto& hexapod = static_cast<const Hexapod&>(mechanism);
  out["base"] = pointsToJson(p, &Hexapod::baseOffset);
  out["platform"] = pointsToJson(p, &Hexapod::platformOffset);
  nlohmann::json offsets = nlohmann::json::array();
  for (int leg = 0; leg < Hexapod::kLegs; ++leg) offsets.push_back(p[Hexapod::legOffsetIndex(leg)]);
  out["offsets"] = offsets;
  out["probe"] = {p[Hexapod::kProbeOffset], p[Hexapod::kProbeOffset + 1],
                  p[Hexapod::kProbeOffset + 2]};
  const ChainPose& home = hexapod.homePose();
  // R = Rz(yaw) Ry(pitch) Rx(roll): Eigen's Z-Y-X Euler angles, returned as (yaw, pitch, roll).
  const Eigen::Vector3d ypr = home.R.eulerAngles(2, 1, 0);
  out["home"] = {{"xyz", {home.t[0], home.t[1], home.t[2]}},
                 {"rpy", {radToDeg(ypr[2]), radToDeg(ypr[1]), radToDeg(ypr[0])}}};
}

}  // namespace

ModelCodec hexapodCodec() {
  return {"hexapod", readHexapod, writeHexapod};
}

}  // namespace artcal
