#pragma once
// Results of `calibrate` and `confirm` as JSON (file units, the fields docs/plan-format.md
// promises: calibrate {converged, iterations, chi2_per_dof, parameters [{name, estimate, u,
// unit}]}, confirm {confirmed, trials, parameters [{name, predicted_u, empirical_u, ratio}]}) and
// as human tables. Non-finite numbers never reach the JSON (finiteOrNull).

#include <nlohmann/json.hpp>
#include <string>

#include "artcal/calibration/calibrator.hpp"
#include "artcal/calibration/confirmation.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// `u_posterior_caveat`: null with 30 or more degrees of freedom; otherwise why u_posterior (u
/// scaled by sqrt(chi2/dof)) is not to be read as a figure: no redundancy at all (dof <= 0), or so
/// few degrees of freedom that sqrt(chi2/dof) is uncertain by 1/sqrt(2 dof) (13 % at 30).
nlohmann::json posteriorCaveat(int dof);

nlohmann::json calibrationToJson(const Plan& plan, const std::vector<Placement>& placements,
                                 const Calibration& calibration);
std::string calibrationTable(const Plan& plan, const std::vector<Placement>& placements,
                             const Calibration& calibration);

nlohmann::json confirmationToJson(const Plan& plan, const ConfirmationOptions& options,
                                  const Confirmation& confirmation);
std::string confirmationTable(const Plan& plan, const ConfirmationOptions& options,
                              const Confirmation& confirmation);

}  // namespace artcal
