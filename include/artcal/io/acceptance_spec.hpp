#pragma once
// The plan's optional acceptance test (docs/plan-format.md, "acceptance"; docs/method.md section
// 9):
//   "acceptance": {"test": "iso10360-2", "mpe": "1.5 + L/333"}
//   "acceptance": {"test": "iso9283", "cube": 600, "center": [500, 0, 400], "mpe": 0.1}
//   "acceptance": {"test": "iso9283", "cube": {"center": [500, 0, 400], "edge": 600,
//                  "orientation": [0, 0, 30]}, "seed_posture": [0, -90, 90, -90, -90, 0],
//                  "unmodelled": 0.05}
// (the seed posture, in the machine's joint units, is read by parsePlan, which knows the machine).
// parsePlan keeps it as Plan::acceptance; `artcal acceptance PLAN` takes what the command line
// does not say from it. Faults are InputErrors naming the file and the JSON pointer.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "artcal/plan/plan.hpp"

namespace artcal {

/// The plan document's "acceptance" member; std::nullopt when absent.
std::optional<AcceptanceSpec> parseAcceptanceSpec(const nlohmann::json& plan_document,
                                                  const std::string& source);

}  // namespace artcal
