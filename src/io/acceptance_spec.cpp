#include "artcal/io/acceptance_spec.hpp"

#include <sstream>

#include "artcal/acceptance/acceptance.hpp"
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

void parsePoseTest(const Node& node, AcceptanceSpec& spec, std::vector<std::string>& warnings) {
  node.warnUnknown({"test", "mpe", "cube", "center"}, warnings);
  spec.cube = node.at("cube").positive();
  spec.center = Eigen::Vector3d(node.at("center").numbers(3));
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
