#pragma once
// The plan's own acceptance test (its "acceptance" block, docs/plan-format.md;
// docs/method.md section 9) predicted from the plan's V_p: what `artcal report` shows. The figures
// are those of `artcal acceptance PLAN` with the block's test and the default Monte-Carlo options
// (the same seed and adaptive trials), computed here once; the report only formats them.

#include <optional>
#include <string>

#include "artcal/acceptance/acceptance.hpp"
#include "artcal/acceptance/length_acceptance.hpp"
#include "artcal/acceptance/pose_acceptance.hpp"
#include "artcal/estimation/evaluation_result.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

struct PlanAcceptance {
  AcceptanceInput input;  ///< points into the plan: valid while the plan is
  std::string test;       ///< "iso10360-2" or "iso9283"
  LengthTestOptions length_options;
  std::optional<LengthTestPrediction> length;  ///< iso10360-2
  PoseTestOptions pose_options;
  std::optional<PoseTestPrediction> pose;  ///< iso9283
};

/// The ISO 10360-2 options of an "acceptance" block (its MPE; the default layout and
/// Monte-Carlo).
LengthTestOptions lengthTestOptionsFrom(const AcceptanceSpec& spec);
/// The ISO 9283 options of an "acceptance" block (cube, centre, orientation, seed posture,
/// unmodelled error, the MPE when it has one).
PoseTestOptions poseTestOptionsFrom(const AcceptanceSpec& spec);

/// The plan's acceptance test predicted from its V_p; std::nullopt when the plan names no test
/// or does not identify its calibrated parameters. InputError when the machine does not suit
/// the test; RunError when an ISO 9283 point cannot be reached (as `artcal acceptance`).
std::optional<PlanAcceptance> predictPlanAcceptance(const Plan& plan, const Evaluation& evaluation);

}  // namespace artcal
