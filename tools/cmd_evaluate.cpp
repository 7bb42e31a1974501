// artcal check PLAN / artcal evaluate PLAN (docs/plan-format.md, command line).

#include <iostream>

#include "artcal/calibration/calibrate_readings.hpp"
#include "artcal/estimation/error_functions.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/report/cartesian_report.hpp"
#include "artcal/report/report.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {

struct EvaluateArguments {
  std::string plan;
  bool json = false;
  double rank_tolerance = kDefaultRankTolerance;
  int profile_steps = 21;
};

void addCommonOptions(CLI::App* cmd, EvaluateArguments& args) {
  cmd->add_option("PLAN", args.plan, "plan file (artcal-plan/1)")->required();
  cmd->add_flag("--json", args.json, "print one JSON document instead of the table");
  cmd->add_option("--rank-tol", args.rank_tolerance,
                  "relative eigenvalue tolerance of the rank test on the scaled N_red")
      ->check(positiveNumber())
      ->capture_default_str();
}

}  // namespace

int printCheck(const Plan& plan, bool json, double rank_tolerance) {
  const PlanInformation information = verdictInformation(plan, plan.placements);
  const Identifiability id =
      analyseIdentifiability(plan, plan.placements, information, rank_tolerance);
  const CartesianAnswers cmm = cartesianAnswers(plan, nullptr);
  if (json) {
    nlohmann::json out = identifiabilityToJson(id);
    out.update(calibrateSelectionToJson(plan));
    out.update(cartesianAnswersToJson(plan, cmm));
    out["plan"] = plan.name;
    printJson(out);
  } else {
    std::cout << identifiabilityTable(plan, id) << cartesianAnswersTable(plan, cmm);
  }
  return id.identifiable() ? 0 : 1;
}

namespace {

void addCheckCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<EvaluateArguments>();
  CLI::App* cmd =
      app.add_subcommand("check",
                         "counting condition and rank: can this plan identify every parameter? "
                         "(exit 0 identifiable, 1 not)");
  addCommonOptions(cmd, *args);
  cmd->callback([&action, args] {
    action = [args] {
      return printCheck(loadPlanReporting(args->plan), args->json, args->rank_tolerance);
    };
  });
}

void addEvaluateCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<EvaluateArguments>();
  CLI::App* cmd = app.add_subcommand(
      "evaluate",
      "parameter uncertainties and tip uncertainty over the workspace, before any "
      "measurement (exit 0; 1 when the plan is not identifiable)");
  addCommonOptions(cmd, *args);
  cmd->add_option("--profile-steps", args->profile_steps,
                  "rows of the planar2r tip-uncertainty profile against reach")
      ->check(CLI::Range(2, 10000))
      ->capture_default_str();
  cmd->callback([&action, args] {
    action = [args] {
      // "estimate": the noise the readings tell where they are measured (predictionNoise).
      const NoisedEvaluation noised = evaluateWithPredictionNoise(
          loadPlanReporting(args->plan), {args->rank_tolerance, args->profile_steps});
      const Plan& plan = noised.plan;
      const Evaluation& evaluation = noised.evaluation;
      const PredictionNoise& noise = noised.noise;
      const CartesianAnswers cmm = cartesianAnswers(plan, &evaluation);
      if (args->json) {
        printJson(evaluateCommandToJson(noised, cmm));
      } else {
        std::cout << evaluationTable(plan, evaluation) << cartesianAnswersTable(plan, cmm);
        if (noised.tip_with_unmodelled)
          std::cout << tipWithUnmodelledTable(*noised.tip_with_unmodelled, *noise.unmodelled);
        if (plan.noise.estimate_probe)
          std::cout << "probe noise \"estimate\": " << noise.probe << " mm, " << noise.source
                    << "\n";
      }
      return evaluation.identifiable() ? 0 : 1;
    };
  });
}

const Registrar check_registrar(10, "check", addCheckCommand);
const Registrar evaluate_registrar(20, "evaluate", addEvaluateCommand);

}  // namespace

}  // namespace artcal::cli
