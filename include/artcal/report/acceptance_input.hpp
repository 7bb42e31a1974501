#pragma once
// What `artcal acceptance` predicts from (docs/method.md section 9): a plan's own predicted V_p, or
// a calibrated machine file's parameters and covariance with the noise and workspace of the plan it
// was calibrated from. The command line and the Python module take their input here, with the
// same errors.

#include <nlohmann/json.hpp>
#include <string>

#include "artcal/acceptance/acceptance.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// The plan's prediction (acceptanceInputFromPlan on evaluatePlan); InputError naming `source`
/// when the plan does not identify its calibrated parameters.
AcceptanceInput acceptanceInputOfPlan(const Plan& plan, const std::string& source);

/// A machine file as `calibrate --write-machine` writes it (`machine`, read from
/// `machine_source`), on the plan it was calibrated from; `posterior` scales the covariance by
/// its Birge ratio squared. InputError naming the machine file when it has no covariance, or no
/// Birge ratio for `posterior`.
AcceptanceInput acceptanceInputOfMachine(const nlohmann::json& machine,
                                         const std::string& machine_source, const Plan& plan,
                                         bool posterior);

}  // namespace artcal
