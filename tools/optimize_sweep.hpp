#pragma once
// `artcal optimize SPEC --placements A..B -o DIR/` (docs/optimize.md "How many placements?"):
// the optimizer for every count, each plan and the summary written into DIR.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "artcal/plan/plan.hpp"
#include "artcal/planning/optimizer.hpp"

namespace artcal::cli {

struct SweepArguments {
  std::string range;             ///< "A..B"
  std::optional<double> target;  ///< G to reach, mm (overrides design.target_tip)
  std::string directory;         ///< -o DIR
  bool json = false;
};

/// Runs the sweep on a parsed spec (`document` as read, for the plans written); exit status.
int runPlacementSweep(const nlohmann::json& document, const Plan& spec,
                      const OptimizerOptions& options, const SweepArguments& args);

}  // namespace artcal::cli
