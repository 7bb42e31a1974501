#pragma once
// calibrate's held-out model choice (calibration/model_choice.hpp) as JSON and as a table: one
// row per candidate kept set, the held-out error predicted and observed side by side, and which
// rule chose the set. Reads the result only.

#include <nlohmann/json.hpp>
#include <string>

#include "artcal/calibration/model_choice_result.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// {"decided_by", "rule", "folds", "rank_rule_size", "reason", "unit", "candidates": [{"size",
/// "held_at_nominal", "surviving_fraction", "converged", "chi2_per_dof", "predicted",
/// "observed", "observed_per_fold", "predicted_rms_mm", "observed_rms_mm", "chosen"}]}
/// (docs/plan-format.md).
nlohmann::json modelChoiceToJson(const Plan& plan, const ModelChoice& choice);

/// The table, and the parameters the choice holds at nominal beyond the rank rule's.
std::string modelChoiceTable(const Plan& plan, const ModelChoice& choice);

}  // namespace artcal
