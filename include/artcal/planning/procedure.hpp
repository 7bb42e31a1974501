#pragma once
// The operator's procedure (`artcal procedure`, docs/plan-format.md "artcal procedure"): the plan
// as the sheet a person follows at the machine. For each placement, in the plan's order (the
// measuring order), the artifact and its pose (centre, direction, roll); for each reading the
// feature, its posture (the k-th reading of that feature in the placement) and the target joint
// values that put the probe on the feature at that pose on the nominal machine.
//
// The pose is the plan's `pose`, or, when the plan gives none, the rigid fit of the artifact to
// the nominal forward kinematics of the readings (the fit the evaluator uses, docs/method.md
// section 1). The targets are the inverse kinematics of each placed feature started from the
// plan's reading, so that each reading keeps its posture (elbow branch, arm configuration); for a
// planned plan they are its readings, for a plan of real readings the nominal joints nearest them.

#include "artcal/plan/plan.hpp"
#include "artcal/planning/procedure_result.hpp"

namespace artcal {

/// The procedure of a plan with readings. Throws RunError naming the reading when no joint values
/// within the limits put the probe on a placed feature.
Procedure operatorProcedure(const Plan& plan);

}  // namespace artcal
