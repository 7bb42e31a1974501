#include "artcal/io/acceptance_spec.hpp"

#include <sstream>

#include "artcal/acceptance/acceptance.hpp"
#include "artcal/core/units.hpp"
#include "artcal/io/json_node.hpp"

namespace artcal {

namespace {

void parseLengthTest(const Node& node, AcceptanceSpec& spec, std::vector<std::string>& warnings) {
  node.warnUnknown({"test", "mpe"}, warnings);
  const Node mpe = node.at("mpe");
  spec.mpe = mpe.string();
  std::string error;
  if (!parseMpe(spec.mpe, &error)) mpe.fail(error);
}

/// The cube as the user sets it up: {"center": [x, y, z], "edge": E, "orientation": [roll,
/// pitch, yaw]} (mm, deg; orientation optional).
void parseCubeObject(const Node& cube, AcceptanceSpec& spec, std::vector<std::string>& warnings) {
  cube.warnUnknown({"center", "edge", "orientation"}, warnings);
  spec.cube = cube.at("edge").positive();
  spec.center = Eigen::Vector3d(cube.at("center").numbers(3));
  if (const auto orientation = cube.find("orientation"))
    spec.orientation = Eigen::Vector3d(orientation->numbers(3)) * kDegree;
}

void parsePoseTest(const Node& node, AcceptanceSpec& spec, std::vector<std::string>& warnings) {
  node.warnUnknown({"test", "mpe", "cube", "center", "seed_posture", "unmodelled"}, warnings);
  const Node cube = node.at("cube");
  if (cube.value().is_object()) {
    if (node.find("center"))
      node.at("center").fail("the cube's centre goes in cube.center when the cube is an object");
    parseCubeObject(cube, spec, warnings);
  } else {
    spec.cube = cube.positive();  // the first form: edge, then "center"
    spec.center = Eigen::Vector3d(node.at("center").numbers(3));
  }
  if (const auto unmodelled = node.find("unmodelled"))
    spec.unmodelled = unmodelled->standardDeviation(true);
  // "seed_posture" needs the machine (its joints' units and limits): parsePlan reads it.
  if (const auto mpe = node.find("mpe")) {
    std::ostringstream text;
    text.precision(17);
    text << mpe->positive();
    spec.mpe = text.str();
  }
}

}  // namespace

std::optional<AcceptanceSpec> parseAcceptanceSpec(const nlohmann::json& plan_document,
                                                  const std::string& source) {
  if (!plan_document.is_object() || !plan_document.contains("acceptance")) return std::nullopt;
  const Node node(plan_document.at("acceptance"), "/acceptance", source);
  node.object();
  AcceptanceSpec spec;
  const Node test = node.at("test");
  spec.test = test.string();
  std::vector<std::string> warnings;
  if (spec.test == "iso10360-2") {
    parseLengthTest(node, spec, warnings);
  } else if (spec.test == "iso9283") {
    parsePoseTest(node, spec, warnings);
  } else {
    test.fail("unknown test \"" + spec.test + "\" (expected \"iso10360-2\" or \"iso9283\")");
  }
  return spec;
}

}  // namespace artcal
