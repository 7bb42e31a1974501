#include "artcal/planning/plan_completion.hpp"

#include <random>

#include "artcal/core/error.hpp"
#include "artcal/planning/design_space.hpp"
#include "artcal/planning/plane_touches.hpp"

namespace artcal {

std::vector<std::vector<std::vector<Measurement>>> plannedReadings(const Plan& plan,
                                                                   std::uint64_t seed) {
  const Machine& machine = plan.machine;
  const Eigen::VectorXd margin =
      plan.design && plan.design->joint_margin.size() == machine.jointCount()
          ? plan.design->joint_margin
          : defaultJointMargin(*machine.mechanism);
  const Machine reading_machine = withJointMargin(machine, margin);
  std::mt19937_64 rng(seed);
  std::vector<std::vector<std::vector<Measurement>>> out(plan.placements.size());
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const Placement& placement = plan.placements[j];
    if (placement.posture_requests.empty()) continue;
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    const Eigen::MatrixXd features = placedFeatures(artifact, *placement.pose);
    for (const PostureRequest& request : placement.posture_requests) {
      std::vector<Measurement> readings =
          artifact.kind().touches_faces
              ? planeTouches(reading_machine, artifact,
                             poseTransform(machine.dimension(), *placement.pose), request.feature,
                             request.postures, rng, request.stylus)
              : featureReadings(reading_machine, request.feature, features.col(request.feature),
                                request.postures, rng, request.stylus);
      if (static_cast<int>(readings.size()) < request.postures) {
        throw InputError(plan.source, request.pointer,
                         "only " + std::to_string(readings.size()) + " of " +
                             std::to_string(request.postures) + " postures reach feature " +
                             std::to_string(request.feature) +
                             " at the placement's pose within the joint limits (less the joint "
                             "margin): move the pose or ask fewer postures");
      }
      out[j].push_back(std::move(readings));
    }
  }
  return out;
}

}  // namespace artcal
