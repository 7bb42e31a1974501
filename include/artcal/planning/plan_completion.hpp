#pragma once
// Nominal readings for a layout (`artcal plan --complete`, docs/plan-format.md): a placement with
// a `pose` and, per feature, `{"feature": k, "postures": N}` gets N readings of feature k by the
// planner's own rule (featureReadings, design_space.hpp): the feature placed at the pose, N
// postures reaching it within the joint limits narrowed by the design's joint margin (default
// 2 deg / 1 mm), spread in joint space.

#include <cstdint>
#include <vector>

#include "artcal/plan/plan.hpp"

namespace artcal {

/// For every placement of `plan`, for each of its posture requests in order, the planned
/// readings (internal units). The same plan and seed give the same readings. InputError naming
/// the request when not that many postures reach the feature.
std::vector<std::vector<std::vector<Measurement>>> plannedReadings(const Plan& plan,
                                                                   std::uint64_t seed);

}  // namespace artcal
