#pragma once
// What `artcal optimize --placements A..B` found (placement_sweep.hpp computes it, report/
// sweep_report.hpp prints it): plain result types, so that the report includes no computation.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "artcal/plan/plan.hpp"

namespace artcal {

struct SweepPoint {
  int placements = 0;
  /// The designed placements (the spec's fixed ones apart); empty when the count cannot be
  /// identifiable (counting condition) or no design was found.
  std::vector<Placement> designed;
  double value = 0.0;     ///< criterion, mm; +infinity without a design
  bool extended = false;  ///< the design for m - 1 plus one placement won
  double fresh = 0.0;     ///< the fresh search's value, mm (+infinity: none)
  double seconds = 0.0;
  std::string message;  ///< why there is no design
};

struct PlacementSweep {
  std::vector<SweepPoint> points;
  /// Index into points of the smallest count reaching SweepOptions::target; nullopt when none
  /// does (or no target was given).
  std::optional<std::size_t> first_reaching;
};

}  // namespace artcal
