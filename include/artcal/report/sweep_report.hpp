#pragma once
// The summary of `artcal optimize SPEC --placements A..B` (planning/placement_sweep.hpp): per
// count m the criterion G, the tip figures and each parameter's u of the plan written for m, as
// a JSON document (the twin of the table), a table, and a figure of G and mean S against m.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "artcal/plan/plan.hpp"
#include "artcal/planning/placement_sweep_result.hpp"

namespace artcal {

/// One count's line: the sweep point, the plan file written for it (empty: none) and
/// evaluationToJson of that plan (null: none).
struct SweepLine {
  const SweepPoint* point = nullptr;
  std::string file;
  nlohmann::json evaluation;
};

/// summary.json: lengths in mm, angles in deg (each parameter's unit in `parameters`).
nlohmann::json sweepSummaryToJson(const Plan& spec, const PlacementSweep& sweep,
                                  const std::vector<SweepLine>& lines,
                                  std::optional<double> target);
/// The table of a summary document: G and S in um, u in um (lengths) or the parameter's unit.
std::string sweepSummaryTable(const nlohmann::json& summary);
/// An SVG figure of G and mean S against m (and the target, dotted) from a summary document.
std::string sweepFigure(const nlohmann::json& summary);

}  // namespace artcal
