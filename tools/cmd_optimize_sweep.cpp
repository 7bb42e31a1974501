// artcal optimize SPEC --placements A..B -o DIR/ (optimize_sweep.hpp, docs/optimize.md).

#include <filesystem>
#include <iostream>

#include "artcal/core/error.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/io/output_file.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/planning/instrument_design.hpp"
#include "artcal/planning/placement_sweep.hpp"
#include "artcal/report/report.hpp"
#include "artcal/report/sweep_report.hpp"
#include "commands.hpp"
#include "optimize_sweep.hpp"

namespace artcal::cli {

namespace {

namespace fs = std::filesystem;

/// The file of the plan for `placements` placements.
std::string planFile(const std::string& directory, const Plan& spec, int placements) {
  const std::string name = (spec.name.empty() ? std::string("plan") : spec.name) + "-" +
                           std::to_string(placements) + ".json";
  return (fs::path(directory) / name).string();
}

/// The plan written for one count: the spec with the designed placements and its `predicted`.
nlohmann::json planDocument(const nlohmann::json& spec_document, const Plan& plan,
                            const nlohmann::json& evaluation, const SweepPoint& point) {
  nlohmann::json document = spec_document;
  document["design"][plan.design->instrument ? "readings" : "placements"] = point.placements;
  document["placements"] = placementsToJson(plan);
  nlohmann::json predicted = evaluation;
  predicted.erase("plan");
  predicted["optimization"] = {
      {"criterion", criterionName(plan.design->criterion)},
      {"value", finiteOrNull(point.value)},
      {"unit", "mm"},
      {"sweep", point.extended ? "design for m - 1 plus one placement" : "fresh search"}};
  document["predicted"] = predicted;
  return document;
}

}  // namespace

int runPlacementSweep(const nlohmann::json& document, const Plan& spec,
                      const OptimizerOptions& options, const SweepArguments& args) {
  const auto range = parseCountRange(args.range);
  if (!range) {
    throw InputError(args.range, "", "--placements: expected A..B with 1 <= A <= B <= 1000");
  }
  checkOutputDirectory(args.directory);
  const std::string& directory = args.directory;
  // Every file the sweep may write is checked before the search, not after it.
  for (int m = range->first; m <= range->second; ++m) checkOutputPath(planFile(directory, spec, m));
  for (const char* name : {"summary.json", "summary.txt", "summary.svg"})
    checkOutputPath((fs::path(directory) / name).string());
  SweepOptions sweep_options;
  sweep_options.first = range->first;
  sweep_options.last = range->second;
  sweep_options.optimizer = options;
  sweep_options.optimizer.progress = nullptr;
  if (args.target) sweep_options.target = *args.target;
  if (!sweep_options.target) sweep_options.target = spec.design->target_tip;
  if (options.progress) {
    sweep_options.progress = [](int m, double value) {
      std::cerr << "optimize --placements: m = " << m << ", G " << value * 1e3 << " um\n";
    };
  }
  const PlacementSweep sweep = sweepPlacements(spec, sweep_options);
  std::vector<SweepLine> lines;
  std::vector<std::pair<std::string, std::string>> files;  // written together at the end
  for (const SweepPoint& point : sweep.points) {
    SweepLine line{&point, {}, nullptr};
    if (!point.designed.empty()) {
      Plan plan = spec;
      if (plan.design->instrument) {
        plan.design->instrument->readings = point.placements;
      } else {
        plan.design->placements = point.placements;
      }
      appendDesignedPlacements(plan, point.designed);
      line.evaluation = evaluationToJson(plan, evaluatePlan(plan));
      line.file = planFile(directory, spec, point.placements);
      files.emplace_back(line.file,
                         planDocument(document, plan, line.evaluation, point).dump(1) + "\n");
    }
    lines.push_back(std::move(line));
  }
  const nlohmann::json summary = sweepSummaryToJson(spec, sweep, lines, sweep_options.target);
  const std::string table = sweepSummaryTable(summary);
  files.emplace_back((fs::path(directory) / "summary.json").string(), summary.dump(1) + "\n");
  files.emplace_back((fs::path(directory) / "summary.txt").string(), table);
  files.emplace_back((fs::path(directory) / "summary.svg").string(), sweepFigure(summary));
  createOutputDirectory(directory);
  writeOutputFiles(files);
  if (args.json) {
    printJson(summary);
  } else {
    std::cout << table;
  }
  return 0;
}

}  // namespace artcal::cli
