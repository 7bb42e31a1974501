#include "artcal/acceptance/plan_acceptance.hpp"

#include <string>

namespace artcal {

LengthTestOptions lengthTestOptionsFrom(const AcceptanceSpec& spec) {
  LengthTestOptions options;
  options.mpe = *parseMpe(spec.mpe);  // checked when the plan was read
  return options;
}

PoseTestOptions poseTestOptionsFrom(const AcceptanceSpec& spec) {
  PoseTestOptions options;
  options.cube = spec.cube.value_or(0.0);
  options.center = spec.center.value_or(Eigen::Vector3d::Zero());
  options.orientation = spec.orientation.value_or(Eigen::Vector3d::Zero());
  options.seed_posture = spec.seed_posture;
  options.unmodelled = spec.unmodelled.value_or(0.0);
  if (!spec.mpe.empty()) options.mpe = std::stod(spec.mpe);  // checked when the plan was read
  return options;
}

std::optional<PlanAcceptance> predictPlanAcceptance(const Plan& plan,
                                                    const Evaluation& evaluation) {
  if (!plan.acceptance) return std::nullopt;
  auto input = acceptanceInputFromPlan(plan, evaluation);
  if (!input) return std::nullopt;
  PlanAcceptance acceptance;
  acceptance.input = std::move(*input);
  acceptance.test = plan.acceptance->test;
  if (acceptance.test == "iso10360-2") {
    acceptance.length_options = lengthTestOptionsFrom(*plan.acceptance);
    acceptance.length = predictLengthTest(acceptance.input, acceptance.length_options);
  } else {
    acceptance.pose_options = poseTestOptionsFrom(*plan.acceptance);
    acceptance.pose = predictPoseTest(acceptance.input, acceptance.pose_options);
  }
  return acceptance;
}

}  // namespace artcal
