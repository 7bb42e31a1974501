// artcal plan --complete PLAN -o OUT: the nominal readings of a layout written into the plan
// (docs/plan-format.md, "Readings planned from a layout").

#include <filesystem>
#include <iostream>

#include "artcal/io/plan_io.hpp"
#include "artcal/planning/plan_completion.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {

using nlohmann::json;

struct PlanArguments {
  std::string plan, output;
  std::uint64_t seed = 1;
};

/// A planned reading as a plan-file measurement entry (file units).
json measurementEntry(const Machine& machine, const Measurement& m) {
  std::vector<double> joints;
  for (int i = 0; i < m.joints.size(); ++i)
    joints.push_back(toFileUnit(jointQuantity(machine.mechanism->jointKind(i)), m.joints[i]));
  json entry = {{"feature", m.feature}, {"joints", joints}};
  // As a plan file names it: a chain's tip by its name (docs/urdf.md), a stylus by its index.
  if (const std::vector<std::string> tips = machine.mechanism->stylusNames(); !tips.empty()) {
    entry["tip"] = tips[static_cast<std::size_t>(m.stylus)];
  } else if (m.stylus != 0) {
    entry["stylus"] = m.stylus;
  }
  return entry;
}

/// The plan document with each posture request replaced, in place, by its planned readings;
/// everything else as it was.
json completedDocument(json document, const Plan& plan,
                       const std::vector<std::vector<std::vector<Measurement>>>& planned) {
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    if (planned[j].empty()) continue;
    json& entries = document.at("placements").at(j).at("measurements");
    json completed = json::array();
    std::size_t request = 0;
    for (const json& entry : entries) {
      if (!entry.contains("postures")) {
        completed.push_back(entry);
        continue;
      }
      for (const Measurement& m : planned[j][request])
        completed.push_back(measurementEntry(plan.machine, m));
      ++request;
    }
    entries = completed;
  }
  return document;
}

void addPlanCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<PlanArguments>();
  CLI::App* cmd = app.add_subcommand(
      "plan",
      "--complete: nominal readings for a layout (placements with a pose and {\"feature\": k, "
      "\"postures\": N}), written into the plan");
  cmd->add_option("--complete", args->plan, "plan whose posture requests to plan")->required();
  cmd->add_option("-o,--output", args->output, "completed plan to write (- for stdout)")
      ->required();
  cmd->add_option("--seed", args->seed, "seed of the postures' search (default: design.seed or 1)");
  cmd->callback([&action, args, cmd] {
    const bool seeded = cmd->count("--seed") > 0;
    action = [args, seeded] {
      checkOutputPath(args->output);
      std::error_code ec;
      if (std::filesystem::equivalent(args->plan, args->output, ec)) {
        throw InputError(args->output, "", "is the input plan: write the completed plan elsewhere");
      }
      const json document = readJsonFile(args->plan);
      const Plan plan = parsePlan(document, args->plan, /*require_placements=*/false);
      // A spec without placements (an instrument's design of stations and readings, an
      // optimizer's spec) has nothing to complete: say what plans it, not "/placements: missing
      // field" of the completed copy (issue 44).
      if (plan.placements.empty()) {
        throw InputError(
            args->plan, "",
            std::string("no placements: nothing to complete (plan --complete plans the readings "
                        "of placements that ask for them, {\"feature\": k, \"postures\": N})") +
                (plan.design ? "; this plan's \"design\" is planned by `artcal optimize " +
                                   args->plan + " -o PLAN`"
                             : ""));
      }
      for (const std::string& warning : plan.warnings) std::cerr << "warning: " << warning << "\n";
      const std::uint64_t seed = seeded ? args->seed : plan.design ? plan.design->seed : 1;
      const json completed = completedDocument(document, plan, plannedReadings(plan, seed));
      // The completed plan is checked like any plan before it is written.
      const Plan checked = parsePlan(completed, args->plan);
      writeJsonOutput(args->output, completed);
      printPlanSummary("plan --complete", args->output, checked);
      return 0;
    };
  });
}

}  // namespace

const Registrar plan_registrar(35, "plan", addPlanCommand);

}  // namespace artcal::cli
