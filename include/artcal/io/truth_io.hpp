#pragma once
// The TRUTH file of `artcal simulate`: the parameters of the simulated ("true") machine, in file
// units (mm, deg). Three forms are accepted:
//   1. a machine block, as `artcal calibrate --write-machine` writes it (it has "model");
//   2. {"parameters": {"l1": 150.02, "dt2": 0.004}}: named values on top of the plan's nominal
//      parameters (any parameter of the model, calibrated or not);
//   3. {"machine": {...machine block...}, "parameters": {...}}: the block, then the named values.
// The machine block must be of the plan's model with the same joints. Unknown names, non-finite
// values and anything else malformed are InputErrors naming the file and JSON pointer.

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

#include "artcal/plan/plan.hpp"

namespace artcal {

/// The full true parameter vector (internal units) the document describes for `plan`'s model.
Eigen::VectorXd parseTruth(const nlohmann::json& document, const std::string& source,
                           const Plan& plan);

/// readJsonFile + parseTruth.
Eigen::VectorXd loadTruth(const std::string& path, const Plan& plan);

/// {"parameters": {name: value}} in file units for a full parameter vector (form 2 above).
nlohmann::json truthToJson(const Machine& machine, const Eigen::VectorXd& parameters);

}  // namespace artcal
