// libFuzzer harness of the design-spec parser (artcal optimize SPEC: a plan with a design block
// and possibly no placements) and of what an optimizer does first with it: plan one placement of
// the design artifact inside the region by inverse kinematics, then evaluate the fixed
// placements with it through the prepared PlanEvaluator.

#include <random>

#include "fuzz_common.hpp"

namespace {

using namespace artcal;

/// A point inside the design region: the box centre, else the middle of the reach along x.
Eigen::VectorXd regionCentre(const Plan& plan) {
  const DesignSpec& design = *plan.design;
  const int d = plan.machine.dimension();
  if (design.region.box) return 0.5 * ((*design.region.box)[0] + (*design.region.box)[1]);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(d);
  x[0] = 0.5 * ((*design.region.reach)[0] + (*design.region.reach)[1]);
  return x;
}

/// One placement of the design artifact at the region centre, readings by inverse kinematics;
/// std::nullopt when a feature cannot be reached.
std::optional<Placement> plannedPlacement(const Plan& plan) {
  const DesignSpec& design = *plan.design;
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(design.artifact)];
  const int d = plan.machine.dimension();
  const Eigen::VectorXd centre = regionCentre(plan);
  const RigidTransform W = d == 2 ? placePlanar(centre.head<2>(), 0.3)
                                  : placeSpatial(centre.head<3>(), Eigen::Vector3d::UnitX(), 0.0);
  const RigidTransform to_machine = W.inverse();
  std::mt19937_64 rng(design.seed);
  Placement placement;
  placement.artifact = design.artifact;
  const int postures = std::min(design.postures, 2);
  for (int f = 0; f < std::min(artifact.featureCount(), 8); ++f) {
    const Eigen::VectorXd target = to_machine.apply(artifact.features.col(f));
    const auto qs = diversePostures(plan.machine, plan.machine.nominal, target, postures, rng, 4);
    if (qs.empty()) return std::nullopt;
    for (const Eigen::VectorXd& q : qs) placement.measurements.push_back({f, q});
  }
  return placement;
}

/// What an optimizer does first with a parsed spec: its fixed placements and one planned one,
/// evaluated through the prepared PlanEvaluator; every figure must be finite.
void evaluateSpec(Plan plan) {
  if (!plan.design || plan.machine.jointCount() > 8 ||
      fuzz::readingCount(plan) > fuzz::kMaxReadings) {
    return;
  }
  fuzz::boundWorkspace(plan);
  std::vector<Placement> placements;
  for (const Placement& p : plan.placements) {
    if (!p.measurements.empty()) placements.push_back(p);
  }
  if (auto planned = plannedPlacement(plan)) placements.push_back(std::move(*planned));
  PlanEvaluator evaluator(plan);
  const Eigen::MatrixXd& information = evaluator.information(placements);
  if (information.hasNaN()) fuzz::finding("NaN in the information matrix");
  if (const auto tip = evaluator.tip(placements)) {
    if (!std::isfinite(tip->worst.total) || !std::isfinite(tip->mean)) {
      fuzz::finding("non-finite tip uncertainty");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > fuzz::kMaxInputBytes) return -1;
  const std::string text(reinterpret_cast<const char*>(data), size);
  // An InputError is the proper answer of the parser, or of the evaluator to a spec it cannot
  // evaluate (no usable workspace configuration): the command line's exit status 2.
  try {
    evaluateSpec(parsePlan(parseJsonText(text, "spec.json"), "spec.json", false));
  } catch (const InputError& e) {
    if (std::string(e.what()).empty()) fuzz::finding("an InputError without a message");
  }
  return 0;
}
