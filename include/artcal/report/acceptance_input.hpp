#pragma once
// What `artcal acceptance --machine` predicts from (docs/method.md section 9): a calibrated
// machine file's parameters and covariance with the noise and workspace of the plan it was
// calibrated from, read here (no computation; a plan's own prediction is
// evaluatedAcceptanceInput, acceptance/acceptance.hpp). The command line and the Python module
// take their input here, with the same errors.

#include <nlohmann/json.hpp>
#include <string>

#include "artcal/acceptance/acceptance.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// A machine file as `calibrate --write-machine` writes it (`machine`, read from
/// `machine_source`), on the plan it was calibrated from; `posterior` scales the covariance by
/// its Birge ratio squared. InputError naming the machine file when it has no covariance, or no
/// Birge ratio for `posterior`.
AcceptanceInput acceptanceInputFromMachineFile(const nlohmann::json& machine,
                                               const std::string& machine_source, const Plan& plan,
                                               bool posterior);

}  // namespace artcal
