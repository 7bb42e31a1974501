#pragma once
// The calibrated parameters' covariance V_p carried in a machine file (`calibrate
// --write-machine` writes it beside the machine block; `verify --machine` reads it for the
// predicted figures, docs/models.md section 6):
//   "covariance": {"parameters": [names], "matrix": [[...], ...], "birge_ratio": 1.21,
//                  "probe_noise": 0.0093}
// in file units: entry (i, j) in the units of parameter i times those of parameter j (mm, deg);
// "birge_ratio" (optional) is sqrt(chi2/dof) of the fit that produced the matrix; "probe_noise"
// (optional, mm) the probe noise that fit estimated (`"probe": "estimate"`), which a plan saying
// "estimate" then verifies with; "unmodelled" (optional, mm per coordinate) the error the model
// does not explain, estimated by cross-validation (unmodelled_error.hpp), which verify's
// predictions add apart from the noise.

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "artcal/calibration/verification.hpp"
#include "artcal/model/machine.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// The "covariance" member for V (internal units) over the machine's calibrated parameters;
/// `birge_ratio` <= 0 (no redundancy) is left out.
nlohmann::json covarianceToJson(const Machine& machine, const Eigen::MatrixXd& V,
                                double birge_ratio);
/// The same for a calibration's uncertainty (Calibration::uncertainty), with the probe noise it
/// estimated as "probe_noise" (mm) when it estimated one.
nlohmann::json covarianceToJson(const Machine& machine, const ParameterUncertainty& uncertainty);

/// The "covariance" member of a machine file for `plan`'s model (internal units); std::nullopt
/// when there is none. InputError naming `source` and the pointer when malformed, when a name is
/// not a parameter of the model, or when the matrix is not symmetric positive semi-definite.
std::optional<ParameterUncertainty> parseMachineCovariance(const nlohmann::json& document,
                                                           const std::string& source,
                                                           const Plan& plan);

}  // namespace artcal
