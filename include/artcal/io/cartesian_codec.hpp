#pragma once
// The plan-file form of the `cartesian` model (docs/models.md section 4):
//   "axes": [{"name", "direction", "range"}, ...] from the base to the probe, "degree",
//   "styli": [[x, y, z], ...], optional "parameters": {"y.tx.1": mm, "z.rx.2": um/m, ...}
//   (nominal error coefficients; default 0, a calibrated machine writes its estimates here).
// The axis ranges are the joint limits unless the machine gives `joint_limits`.

#include <Eigen/Core>
#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "artcal/io/json_node.hpp"
#include "artcal/io/model_registry.hpp"
#include "artcal/model/cartesian.hpp"

namespace artcal {

/// The registry's codec of "cartesian" (model_registry.hpp).
ModelCodec cartesianCodec();

/// The mechanism, its nominal parameters (internal units) and its axis ranges as joint limits.
MechanismPtr parseCartesian(const Node& machine, Eigen::VectorXd& nominal,
                            std::vector<std::array<double, 2>>& axis_ranges,
                            std::vector<std::string>& warnings);
/// A parameter's value in file units (mm, or um/m for a rotation) and back.
double cartesianFileValue(const Cartesian& cmm, int parameter, double internal);
double cartesianInternalValue(const Cartesian& cmm, int parameter, double file_value);
/// The model's fields of the machine block (axes, degree, styli, non-zero parameters).
void cartesianToJson(const Cartesian& cmm, const Eigen::VectorXd& parameters, nlohmann::json& out);

}  // namespace artcal
