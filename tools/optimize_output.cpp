// The outputs of `artcal optimize` (optimize_output.hpp), shared by the command line and the
// Python module so that both build the same documents.

#include "optimize_output.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "artcal/io/output_file.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/planning/design_identifiability.hpp"
#include "artcal/planning/instrument_design.hpp"
#include "artcal/planning/placement_sweep.hpp"
#include "artcal/report/report.hpp"
#include "artcal/report/sweep_report.hpp"

namespace artcal {

namespace {

namespace fs = std::filesystem;

double median(std::vector<double> values) {
  if (values.empty()) return NAN;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// The quantity a pass criterion value stands for ("1 - P(pass)" or "q95 of max |E|/MPE").
nlohmann::json passQuantity(double value) {
  return std::isfinite(value) ? nlohmann::json(passObjectiveOf(value).name()) : nullptr;
}

/// Criterion "pass": the optimum's P(pass), its standard error, q95 and whether P(pass)
/// saturated (optimizer.hpp, PassObjective), and which quantity each stage's value is.
nlohmann::json passJson(const OptimizerSummary& summary, double best_initial,
                        double median_initial) {
  const PassEstimate& pass = *summary.pass;
  const StartResult& best = summary.starts[static_cast<std::size_t>(summary.best_start)];
  return {{"draws", kPassDraws},
          {"p_pass", finiteOrNull(pass.p_pass)},
          {"p_pass_standard_error", finiteOrNull(pass.standard_error)},
          {"q95", finiteOrNull(pass.q95)},
          {"saturated", pass.saturated},
          {"objective", passObjectiveOf(summary.value).name()},
          {"stage_objectives",
           {{"random_initial_best", passQuantity(best_initial)},
            {"random_initial_median", passQuantity(median_initial)},
            {"best_start_initial", passQuantity(best.initial)},
            {"best_start_exchanged", passQuantity(best.exchanged)},
            {"best_start_refined", passQuantity(best.refined)}}}};
}

/// The file of the sweep's plan for `placements` placements.
std::string sweepPlanFile(const std::string& directory, const Plan& spec, int placements) {
  const std::string name = (spec.name.empty() ? std::string("plan") : spec.name) + "-" +
                           std::to_string(placements) + ".json";
  return (fs::path(directory) / name).string();
}

/// The plan written for one count: the spec with the designed placements and its `predicted`.
nlohmann::json sweepPlanDocument(const nlohmann::json& spec_document, const Plan& plan,
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

int resolveOnDesigns(Plan& spec, std::uint64_t seed) {
  if (!spec.machine.calibrate_identifiable) return 0;
  if (spec.calibrate_resolution) spec.machine.calibrated = spec.calibrate_resolution->listed;
  spec.calibrate_resolution.reset();
  const std::optional<DesignIdentifiability> by_designs = identifiableByDesigns(spec, seed);
  if (!by_designs) return 0;  // no feasible placement: the search says why
  if (by_designs->resolution.kept.empty()) {
    // Nothing to calibrate is not a plan: every reading is absorbed by its placement's pose.
    throw InputError(spec.source, "/design/postures",
                     std::to_string(by_designs->candidates) +
                         " random placements of the design space together identify none of the " +
                         std::to_string(by_designs->resolution.listed.size()) +
                         " listed parameters: each placement's pose absorbs what its " +
                         std::to_string(spec.design->postures) +
                         " reading(s) see; give more postures per placement");
  }
  spec.machine.calibrated = by_designs->resolution.kept;
  spec.calibrate_resolution = by_designs->resolution;
  return by_designs->candidates;
}

RunError unidentifiableDesignError(const Plan& spec, std::uint64_t seed, const std::string& source,
                                   const std::string& why) {
  const std::optional<DesignIdentifiability> by_designs = identifiableByDesigns(spec, seed);
  std::ostringstream message;
  if (by_designs && !by_designs->resolution.dropped.empty()) {
    message << why << "; no design of this space can identify "
            << by_designs->resolution.dropped.size() << " of the " << spec.machine.calibratedCount()
            << " calibrated parameters (" << by_designs->candidates
            << " random placements together cannot, docs/method.md section 5): "
            << calibrateFixText(spec, by_designs->resolution);
    return {source, "/machine/calibrate", message.str()};
  }
  message << why;
  if (by_designs) {
    message << "; " << by_designs->candidates
            << " random placements together identify every calibrated parameter: more "
               "placements or postures may";
  }
  return {source, "/design/placements", message.str()};
}

nlohmann::json criterionJson(Criterion criterion, double value) {
  if (criterion != Criterion::Pass || !std::isfinite(value)) return finiteOrNull(value);
  return passObjectiveOf(value).value;
}

nlohmann::json optimizationToJson(const Plan& spec, const OptimizerOptions& options,
                                  const OptimizerSummary& summary) {
  std::vector<double> initial;
  for (const StartResult& s : summary.starts) {
    if (s.done) initial.push_back(s.initial);
  }
  const StartResult& best = summary.starts[static_cast<std::size_t>(summary.best_start)];
  const Criterion criterion = spec.design->criterion;
  auto value = [criterion](double v) { return criterionJson(criterion, v); };
  nlohmann::json out;
  out["criterion"] = criterionName(criterion);
  out["value"] = value(summary.value);
  out["unit"] = criterion == Criterion::Pass ? passObjectiveOf(summary.value).name() : "mm";
  out["seed"] = options.seed;
  out["starts"] = options.starts;
  out["starts_done"] = summary.startsDone();
  out["pool"] = summary.pool_size;
  out["algorithm"] = refineAlgorithmName(options.algorithm);
  out["best_start"] = {{"index", summary.best_start},
                       {"initial", value(best.initial)},
                       {"exchanged", value(best.exchanged)},
                       {"refined", value(best.refined)}};
  const double best_initial =
      initial.empty() ? NAN : *std::min_element(initial.begin(), initial.end());
  out["random_initial"] = {{"best", value(best_initial)}, {"median", value(median(initial))}};
  if (summary.pass) out["pass"] = passJson(summary, best_initial, median(initial));
  out["termination"] =
      summary.termination == OptimizerSummary::Termination::Completed ? "completed" : "time_limit";
  return out;
}

OptimizedPlan optimizedPlan(const nlohmann::json& spec_document, const Plan& spec,
                            const std::string& source, const OptimizerOptions& options,
                            const OptimizerSummary& summary, int resolved_on) {
  if (summary.best_start < 0)
    throw unidentifiableDesignError(spec, options.seed, source, summary.message);
  OptimizedPlan out{spec, {}, {}};
  appendDesignedPlacements(out.plan, summary.placements);
  out.evaluation = evaluatePlan(out.plan);
  // The rank policy re-checks the optimizer's pick (a finite criterion is not a full rank).
  if (!out.evaluation.identifiability.identifiable())
    throw unidentifiableDesignError(spec, options.seed, source,
                                    "the optimized design is not identifiable");
  out.document = spec_document;
  out.document["placements"] = placementsToJson(out.plan);
  nlohmann::json predicted = evaluationToJson(out.plan, out.evaluation);
  predicted.erase("plan");
  predicted["optimization"] = optimizationToJson(spec, options, summary);
  if (out.plan.calibrate_resolution) {
    predicted["calibrate_resolved_on"] = {{"random_placements", resolved_on},
                                          {"seed", options.seed}};
  }
  out.document["predicted"] = predicted;
  return out;
}

PlacementSweepOutput placementSweepOutput(const nlohmann::json& spec_document, const Plan& spec,
                                          const OptimizerOptions& options, const std::string& range,
                                          std::optional<double> target,
                                          const std::string& directory,
                                          std::function<void(int, double)> progress) {
  const auto counts = parseCountRange(range);
  if (!counts) throw InputError(range, "", "--placements: expected A..B with 1 <= A <= B <= 1000");
  checkOutputDirectory(directory);
  // Every file the sweep may write is checked before the search, not after it.
  for (int m = counts->first; m <= counts->second; ++m)
    checkOutputPath(sweepPlanFile(directory, spec, m));
  for (const char* name : {"summary.json", "summary.txt", "summary.svg"})
    checkOutputPath((fs::path(directory) / name).string());
  SweepOptions sweep_options;
  sweep_options.first = counts->first;
  sweep_options.last = counts->second;
  sweep_options.optimizer = options;
  sweep_options.optimizer.progress = nullptr;
  sweep_options.target = target ? target : spec.design->target_tip;
  sweep_options.progress = std::move(progress);
  const PlacementSweep sweep = sweepPlacements(spec, sweep_options);
  PlacementSweepOutput out;
  std::vector<SweepLine> lines;
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
      line.file = sweepPlanFile(directory, spec, point.placements);
      out.files.emplace_back(
          line.file, sweepPlanDocument(spec_document, plan, line.evaluation, point).dump(1) + "\n");
    }
    lines.push_back(std::move(line));
  }
  out.summary = sweepSummaryToJson(spec, sweep, lines, sweep_options.target);
  out.table = sweepSummaryTable(out.summary);
  out.files.emplace_back((fs::path(directory) / "summary.json").string(),
                         out.summary.dump(1) + "\n");
  out.files.emplace_back((fs::path(directory) / "summary.txt").string(), out.table);
  out.files.emplace_back((fs::path(directory) / "summary.svg").string(), sweepFigure(out.summary));
  return out;
}

}  // namespace artcal
