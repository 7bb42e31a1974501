#pragma once
// What any design of an optimization spec can identify (docs/method.md section 5, "Rank
// policy"; docs/optimize.md).
//
// A design is a few placements from the spec's design space. Each placement adds a positive
// semi-definite term to the information of p (docs/method.md section 3), so the information of a
// design lies below the information of a union of many placements drawn from the same space: a
// parameter combination that the union cannot separate, no design can. The union of enough
// random placements (generic poses, at least twice as many equations as listed parameters) has
// the largest rank the space allows, so its greedy choice (chooseIdentifiableSet, in the listed
// order) is what `optimize` resolves `"calibrate": "identifiable"` to, and what it names as the
// parameters to fix when a listed set cannot be identified by any design.

#include <cstdint>
#include <optional>

#include "artcal/plan/plan.hpp"

namespace artcal {

struct DesignIdentifiability {
  int candidates = 0;                  ///< random placements drawn for the union
  CalibratedSetResolution resolution;  ///< over the spec's listed parameters
};

/// The listed parameters (spec.machine.calibrated, in preferred order) that the spec's fixed
/// placements together with random placements of its design space identify; std::nullopt when
/// the design space yields no feasible placement (the optimizer then says why).
std::optional<DesignIdentifiability> identifiableByDesigns(const Plan& spec, std::uint64_t seed);

}  // namespace artcal
