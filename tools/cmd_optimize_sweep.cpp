// artcal optimize SPEC --placements A..B -o DIR/ (optimize_sweep.hpp, docs/optimize.md).

#include <filesystem>
#include <iostream>

#include "artcal/core/error.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/io/output_file.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/planning/placement_sweep.hpp"
#include "artcal/report/report.hpp"
#include "artcal/report/sweep_report.hpp"
#include "commands.hpp"
#include "optimize_sweep.hpp"

namespace artcal::cli {

namespace {

namespace fs = std::filesystem;

/// The output directory: created when missing; anything else in its place is refused (exit 2).
std::string outputDirectory(const std::string& path) {
  if (path == kStandardOutput) {
    throw InputError(path, "", "--placements writes several files: -o must name a directory");
  }
  std::error_code error;
  if (!fs::exists(path, error)) fs::create_directories(path, error);
  if (error || !fs::is_directory(path, error)) {
    throw InputError(path, "", "not a directory: --placements writes one plan per count there");
  }
  return path;
}

/// The plan written for one count: the spec with the designed placements and its `predicted`.
nlohmann::json planDocument(const nlohmann::json& spec_document, const Plan& plan,
                            const nlohmann::json& evaluation, const SweepPoint& point) {
  nlohmann::json document = spec_document;
  document["design"]["placements"] = point.placements;
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
  const std::string directory = outputDirectory(args.directory);
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
  for (const SweepPoint& point : sweep.points) {
    SweepLine line{&point, {}, nullptr};
    if (!point.designed.empty()) {
      Plan plan = spec;
      plan.design->placements = point.placements;
      plan.placements.insert(plan.placements.end(), point.designed.begin(), point.designed.end());
      line.evaluation = evaluationToJson(plan, evaluatePlan(plan));
      const std::string name = (spec.name.empty() ? std::string("plan") : spec.name) + "-" +
                               std::to_string(point.placements) + ".json";
      line.file = (fs::path(directory) / name).string();
      writeOutputFile(line.file,
                      planDocument(document, plan, line.evaluation, point).dump(1) + "\n");
    }
    lines.push_back(std::move(line));
  }
  const nlohmann::json summary = sweepSummaryToJson(spec, sweep, lines, sweep_options.target);
  const std::string table = sweepSummaryTable(summary);
  writeOutputFile((fs::path(directory) / "summary.json").string(), summary.dump(1) + "\n");
  writeOutputFile((fs::path(directory) / "summary.txt").string(), table);
  writeOutputFile((fs::path(directory) / "summary.svg").string(), sweepFigure(summary));
  if (args.json) {
    printJson(summary);
  } else {
    std::cout << table;
  }
  return 0;
}

}  // namespace artcal::cli
