// What a plan of a model with axis error functions (a Cartesian CMM) answers
// (cartesian_answers.hpp), computed once here for check, evaluate and report, which print it.
#include <algorithm>
#include <map>
#include <string>

#include "artcal/estimation/cartesian_answers.hpp"
#include "artcal/estimation/error_functions.hpp"
#include "artcal/estimation/evaluator.hpp"

namespace artcal {

namespace {

// The information of every model parameter as the rank test sees it (the frame-rotation test
// needs them all): N_red without the prior and the unreduced diagonal.
PlanInformation fullInformation(const Plan& plan) {
  Plan all = plan;
  all.machine.calibrated.clear();
  for (int i = 0; i < plan.machine.mechanism->parameterCount(); ++i) {
    all.machine.calibrated.push_back(i);
  }
  return planInformation(all, all.placements, all.machine.nominal, false);
}

// Model parameters not calibrated: the dropped ones of "identifiable", or those the plan fixed.
std::vector<int> notCalibrated(const Plan& plan) {
  if (plan.calibrate_resolution) return plan.calibrate_resolution->dropped;
  std::vector<int> out;
  const auto& calibrated = plan.machine.calibrated;
  for (int i = 0; i < plan.machine.mechanism->parameterCount(); ++i) {
    if (std::find(calibrated.begin(), calibrated.end(), i) == calibrated.end()) out.push_back(i);
  }
  return out;
}

}  // namespace

const AxisErrorFunctions* axisErrorFunctionsOf(const Plan& plan) {
  return plan.machine.mechanism->axisErrorFunctions();
}

CartesianAnswers cartesianAnswers(const Plan& plan, const Evaluation* evaluation,
                                  int profile_steps) {
  CartesianAnswers answers;
  const AxisErrorFunctions* cmm = axisErrorFunctionsOf(plan);
  if (!cmm) return answers;
  const Mechanism& model = *plan.machine.mechanism;
  answers.absorbed = frameRotationsAbsorbed(model, fullInformation(plan));
  std::vector<int> dropped = notCalibrated(plan);
  // Each absorbed rotation holds one of the parameters it moves at its nominal value: the
  // squareness the frame defines. The rest of the dropped ones the plan cannot separate.
  for (const AbsorbedRotation& rotation : answers.absorbed) {
    std::string held;
    for (auto it = dropped.begin(); it != dropped.end(); ++it) {
      const std::string& name = model.parameters()[static_cast<std::size_t>(*it)].name;
      if (std::find(rotation.involves.begin(), rotation.involves.end(), name) !=
          rotation.involves.end()) {
        held = name;
        dropped.erase(it);
        break;
      }
    }
    answers.held_by_frame.push_back(held);
  }
  std::map<std::pair<int, int>, std::vector<int>> functions;  // (axis, error) -> degrees
  const int per_axis = cmm->degree() * kAxisErrorCount;
  for (const int i : dropped) {
    const int axis = i / per_axis;
    const int degree = (i % per_axis) / kAxisErrorCount + 1;
    functions[{axis, i % kAxisErrorCount}].push_back(degree);
  }
  for (const auto& [key, degrees] : functions) {
    const CartesianAxis& axis = cmm->axes()[static_cast<std::size_t>(key.first)];
    const auto error = static_cast<AxisError>(key.second);
    answers.unseparated.push_back(
        {axis.name + "." + axisErrorName(error), axisErrorMeaning(axis.direction, error), degrees});
  }
  if (evaluation && evaluation->covariance) {
    answers.profiles = errorFunctionProfiles(plan.machine, evaluation->covariance->V,
                                             plan.machine.nominal, profile_steps);
  }
  return answers;
}

ErrorFunctionBands errorFunctionBands(const Plan& plan, const Eigen::MatrixXd& V,
                                      const Eigen::VectorXd& p, bool calibrated,
                                      const Eigen::VectorXd* truth, int steps) {
  ErrorFunctionBands bands;
  bands.calibrated = calibrated;
  if (!axisErrorFunctionsOf(plan)) return bands;
  bands.profiles = errorFunctionProfiles(plan.machine, V, p, steps);
  if (truth) bands.truth = errorFunctionProfiles(plan.machine, V, *truth, steps);
  return bands;
}

}  // namespace artcal
