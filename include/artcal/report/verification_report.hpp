#pragma once
// Results of `verify` (docs/models.md section 6) as JSON (mm; the fields the spec lists, under
// "verify") and as a human table: per placement, each feature's spread beside its predicted
// spread, the length errors beside their predicted u, the residuals of the rigid fit and the
// readings that stand out.

#include <nlohmann/json.hpp>
#include <string>

#include "artcal/calibration/verification.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

nlohmann::json verificationToJson(const Plan& plan, const Verification& verification);
/// `outliers`: how many of the largest deviations from their feature's mean to list.
std::string verificationTable(const Plan& plan, const Verification& verification, int outliers = 5);

}  // namespace artcal
