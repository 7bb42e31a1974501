#pragma once
// Results of `calibrate` and `confirm` as JSON (file units, the fields plan-format.md promises:
// calibrate {converged, iterations, chi2_per_dof, parameters [{name, estimate, u, unit}]},
// confirm {confirmed, trials, parameters [{name, predicted_u, empirical_u, ratio}]}) and as
// human tables. Non-finite numbers never reach the JSON (finiteOrNull).

#include <nlohmann/json.hpp>
#include <string>

#include "artcal/calibration/calibrator.hpp"
#include "artcal/calibration/confirmation.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

nlohmann::json calibrationToJson(const Plan& plan, const std::vector<Placement>& placements,
                                 const Calibration& calibration);
std::string calibrationTable(const Plan& plan, const std::vector<Placement>& placements,
                             const Calibration& calibration);

nlohmann::json confirmationToJson(const Plan& plan, const ConfirmationOptions& options,
                                  const Confirmation& confirmation);
std::string confirmationTable(const Plan& plan, const ConfirmationOptions& options,
                              const Confirmation& confirmation);

}  // namespace artcal
