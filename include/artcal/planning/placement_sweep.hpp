#pragma once
// "How many placements?" (`artcal optimize SPEC --placements A..B`, docs/optimize.md): the
// planner run for every count m of the design's artifact from A to B, so that a lab sees the
// criterion G against m, how fast the return diminishes and the smallest count that reaches a
// target tip uncertainty.
//
// Each count m after the first is searched twice with the optimizer's options: afresh (m
// placements), and as the best design for m - 1 kept fixed with one placement added (the
// placements found for m - 1 seed the search for m). The better of the two is kept. Information
// only adds (docs/method.md section 3: N_red is a sum of positive semi-definite placement terms),
// so the extension is never worse than m - 1: the curve is monotone by construction.

#include <functional>
#include <optional>
#include <vector>

#include "artcal/plan/plan.hpp"
#include "artcal/planning/optimizer.hpp"
#include "artcal/planning/placement_sweep_result.hpp"

namespace artcal {

struct SweepOptions {
  int first = 1, last = 1;       ///< the counts m, first <= last
  OptimizerOptions optimizer;    ///< per search (each count runs one or two searches)
  std::optional<double> target;  ///< criterion value to reach, mm (design.target_tip)
  std::function<void(int placements, double value)> progress;  ///< after each count
};

/// Parses "A..B" (1 <= A <= B <= 1000) or a single count; nullopt when malformed.
std::optional<std::pair<int, int>> parseCountRange(const std::string& text);

/// Runs the sweep on the spec (its `design` block: artifact, postures, region, criterion).
PlacementSweep sweepPlacements(const Plan& spec, const SweepOptions& options);

}  // namespace artcal
