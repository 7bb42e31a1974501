// artcal procedure (docs/plan-format.md "artcal procedure"): the plan as the operator's sheet.

#include <iostream>

#include "artcal/planning/procedure.hpp"
#include "artcal/report/procedure.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {

struct ProcedureArguments {
  std::string plan;
  bool json = false;
  bool csv = false;
};

int runProcedure(const ProcedureArguments& args) {
  const Plan plan = loadPlanReporting(args.plan);
  const Procedure procedure = operatorProcedure(plan);
  if (args.json) {
    printJson(procedureToJson(plan, procedure));
  } else if (args.csv) {
    std::cout << procedureCsv(plan, procedure);
  } else {
    std::cout << procedureTable(plan, procedure);
  }
  return 0;
}

void addProcedureCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<ProcedureArguments>();
  CLI::App* cmd = app.add_subcommand(
      "procedure",
      "prints the plan as the operator's procedure: each placement in measuring order with the "
      "artifact's pose, and each reading with its feature, posture and target joint values");
  cmd->add_option("PLAN", args->plan, "plan file with readings (planned or taken)")->required();
  auto* json_flag = cmd->add_flag("--json", args->json, "print one JSON document");
  cmd->add_flag("--csv", args->csv, "print CSV, one row per reading, for a spreadsheet")
      ->excludes(json_flag);
  cmd->callback([&action, args] { action = [args] { return runProcedure(*args); }; });
}

const Registrar procedure_registrar(25, "procedure", addProcedureCommand);

}  // namespace

}  // namespace artcal::cli
