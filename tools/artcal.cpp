// artcal: plan and run the kinematic calibration of measuring mechanisms with artifacts.

#include <algorithm>
#include <iostream>

#include "artcal/core/error.hpp"
#include "artcal/io/output_file.hpp"
#include "artcal/io/plan_io.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {
std::vector<std::pair<int, CommandFactory>>& registry() {
  static std::vector<std::pair<int, CommandFactory>> commands;
  return commands;
}
}  // namespace

Registrar::Registrar(int order, CommandFactory factory) {
  registry().emplace_back(order, factory);
}

std::vector<CommandFactory> registeredCommands() {
  auto sorted = registry();
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<CommandFactory> out;
  for (const auto& entry : sorted) out.push_back(entry.second);
  return out;
}

Plan loadPlanReporting(const std::string& path, bool require_placements) {
  Plan plan = loadPlan(path, require_placements);
  for (const std::string& warning : plan.warnings) std::cerr << "warning: " << warning << "\n";
  return plan;
}

void printJson(const nlohmann::json& document) {
  std::cout << document.dump(2) << std::endl;
}

void writeJsonOutput(const std::string& path, const nlohmann::json& document) {
  writeOutputFile(path,
                  path == kStandardOutput ? document.dump(2) + "\n" : document.dump(1) + "\n");
}

std::ostream& summaryStream(const std::string& output) {
  return output == kStandardOutput ? std::cerr : std::cout;
}

void printPlanSummary(const std::string& command, const std::string& output, const Plan& plan) {
  std::size_t readings = 0;
  for (const Placement& placement : plan.placements) readings += placement.measurements.size();
  summaryStream(output) << command << ": " << plan.placements.size() << " placements, " << readings
                        << " readings\n";
}

}  // namespace artcal::cli

int main(int argc, char** argv) {
  CLI::App app{
      "artcal: plans and runs the kinematic calibration of measuring mechanisms with calibrated "
      "artifacts (ball bars, ball plates, step gauges). Units in files: mm and degrees.",
      "artcal"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "artcal 0.1.0");
  artcal::cli::Action action;
  for (const auto factory : artcal::cli::registeredCommands()) factory(app, action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }
  try {
    return action();
  } catch (const artcal::InputError& e) {
    std::cerr << "error: " << e.describe() << std::endl;
    return 2;
  } catch (const artcal::RunError& e) {
    std::cerr << "error: " << e.describe() << std::endl;
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << std::endl;
    return 2;
  }
}
