#pragma once
// The plan's optional acceptance test (docs/plan-format.md, "acceptance"; spec acceptance.md):
//   "acceptance": {"test": "iso10360-2", "mpe": "1.5 + L/333"}
//   "acceptance": {"test": "iso9283", "cube": 600, "center": [500, 0, 400], "mpe": 0.1}
// `artcal acceptance PLAN` takes what the command line does not say from it. Faults are
// InputErrors naming the file and the JSON pointer; parsePlan checks the block when present.

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace artcal {

struct AcceptanceSpec {
  std::string test;                       ///< "iso10360-2" or "iso9283"
  std::string mpe;                        ///< "A + L/K" (um, mm) or, for iso9283, mm as text
  std::optional<double> cube;             ///< iso9283, mm
  std::optional<Eigen::Vector3d> center;  ///< iso9283, mm
};

/// The plan document's "acceptance" member; std::nullopt when absent.
std::optional<AcceptanceSpec> parseAcceptanceSpec(const nlohmann::json& plan_document,
                                                  const std::string& source);

}  // namespace artcal
