#include "artcal/io/cartesian_codec.hpp"

#include <Eigen/LU>
#include <cmath>

namespace artcal {

namespace {

constexpr std::size_t kMaxAxes = 6;
constexpr long kMaxDegree = 12;
constexpr std::size_t kMaxStyli = 64;

CartesianAxis parseAxis(const Node& node, std::vector<std::string>& names,
                        std::vector<std::string>& warnings) {
  node.object();
  node.warnUnknown({"name", "direction", "range"}, warnings);
  CartesianAxis axis;
  const Node name = node.at("name");
  axis.name = name.string();
  if (axis.name.empty() || axis.name.find('.') != std::string::npos) {
    name.fail("expected a non-empty axis name without '.'");
  }
  for (const std::string& other : names) {
    if (other == axis.name) name.fail("axis \"" + axis.name + "\" named twice");
  }
  names.push_back(axis.name);
  const Node direction = node.at("direction");
  const Eigen::Vector3d d = direction.numbers(3);
  if (!(d.norm() > 0.0)) direction.fail("direction must not be zero");
  axis.direction = d.normalized();
  const Node range = node.at("range");
  const Eigen::VectorXd r = range.numbers(2);
  if (!(r[0] < r[1])) range.fail("expected [lower, upper] with lower < upper");
  axis.range = {r[0], r[1]};
  return axis;
}

}  // namespace

MechanismPtr parseCartesian(const Node& machine, Eigen::VectorXd& nominal,
                            std::vector<std::array<double, 2>>& axis_ranges,
                            std::vector<std::string>& warnings) {
  const Node axes_node = machine.at("axes");
  const std::size_t n = axes_node.arraySize(3, 3);
  std::vector<CartesianAxis> axes;
  std::vector<std::string> names;
  Eigen::Matrix3d directions;
  for (std::size_t k = 0; k < n; ++k) {
    axes.push_back(parseAxis(axes_node[k], names, warnings));
    directions.col(static_cast<int>(k)) = axes.back().direction;
  }
  // The readings must resolve every point (docs/models.md section 4, inverse kinematics).
  if (std::abs(directions.determinant()) < 1e-6) {
    axes_node.fail("axis directions must span space (they are nearly coplanar)");
  }
  const int degree = static_cast<int>(machine.at("degree").integer(1, kMaxDegree));
  const Node styli_node = machine.at("styli");
  const std::size_t m = styli_node.arraySize(1, kMaxStyli);
  std::vector<Eigen::Vector3d> styli;
  for (std::size_t s = 0; s < m; ++s) styli.push_back(styli_node[s].numbers(3));
  auto cmm = std::make_shared<Cartesian>(std::move(axes), degree, std::move(styli));
  nominal = Eigen::VectorXd::Zero(cmm->parameterCount());
  if (const auto parameters = machine.find("parameters")) {
    for (const auto& [key, value] : parameters->object().items()) {
      const int index = cmm->parameterIndex(key);
      const Node entry = parameters->at(key);
      if (index < 0) {
        entry.fail("unknown parameter of cartesian (expected AXIS.tx.N ... AXIS.rz.N, N = 1.." +
                   std::to_string(degree) + ")");
      }
      nominal[index] = cartesianInternalValue(*cmm, index, entry.number());
    }
  }
  axis_ranges.clear();
  for (const CartesianAxis& axis : cmm->axes()) axis_ranges.push_back(axis.range);
  return cmm;
}

double cartesianFileValue(const Cartesian& cmm, int parameter, double internal) {
  return toFileUnit(cmm.parameters()[static_cast<std::size_t>(parameter)].quantity, internal);
}

double cartesianInternalValue(const Cartesian& cmm, int parameter, double file_value) {
  return fromFileUnit(cmm.parameters()[static_cast<std::size_t>(parameter)].quantity, file_value);
}

void cartesianToJson(const Cartesian& cmm, const Eigen::VectorXd& parameters, nlohmann::json& out) {
  nlohmann::json axes = nlohmann::json::array();
  for (const CartesianAxis& axis : cmm.axes()) {
    axes.push_back({{"name", axis.name},
                    {"direction", {axis.direction.x(), axis.direction.y(), axis.direction.z()}},
                    {"range", {axis.range[0], axis.range[1]}}});
  }
  out["axes"] = axes;
  out["degree"] = cmm.degree();
  nlohmann::json styli = nlohmann::json::array();
  for (const Eigen::Vector3d& s : cmm.styli()) styli.push_back({s.x(), s.y(), s.z()});
  out["styli"] = styli;
  nlohmann::json values = nlohmann::json::object();
  for (int i = 0; i < cmm.parameterCount(); ++i) {
    if (parameters[i] != 0.0) {
      values[cmm.parameters()[i].name] = cartesianFileValue(cmm, i, parameters[i]);
    }
  }
  out["parameters"] = values;
}

ModelCodec cartesianCodec() {
  return {"cartesian",
          [](const Node& node, std::vector<std::string>& warnings) {
            node.warnUnknown({"axes", "degree", "styli", "parameters"}, warnings);
            MachineBlock block;
            block.mechanism = parseCartesian(node, block.nominal, block.default_limits, warnings);
            return block;
          },
          [](const Mechanism& mechanism, const Eigen::VectorXd& parameters, nlohmann::json& out) {
            cartesianToJson(dynamic_cast<const Cartesian&>(mechanism), parameters, out);
          }};
}

}  // namespace artcal
