// artcal optimize SPEC -o PLAN (docs/plan-format.md, optimization spec; docs/method.md section 7).

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "artcal/core/error.hpp"
#include "artcal/core/parallel.hpp"
#include "artcal/io/output_file.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/planning/design_identifiability.hpp"
#include "artcal/planning/instrument_design.hpp"
#include "artcal/planning/optimizer.hpp"
#include "artcal/report/report.hpp"
#include "commands.hpp"
#include "optimize_sweep.hpp"

namespace artcal::cli {

namespace {

struct OptimizeArguments {
  std::string spec;
  std::string output;
  bool json = false;
  bool quiet = false;
  int threads = 0;
  int pool = 0;
  int evaluations = 0;
  std::string algorithm = "sbplx";
  std::optional<int> starts;
  std::optional<double> time_limit;
  std::optional<long> seed;
  std::optional<int> polish, kicks;
  SweepArguments sweep;  ///< --placements A..B: every count, -o is a directory
};

double toMicrometres(double mm) {
  return mm * 1000.0;
}

/// How a criterion value is shown: um for the lengths, as is for "pass" (1 - P(pass)).
struct CriterionDisplay {
  double factor;
  const char* unit;
};

CriterionDisplay displayOf(Criterion criterion) {
  if (criterion == Criterion::Pass) return {1.0, "1 - P(pass)"};
  return {1000.0, "um"};
}

OptimizerOptions optionsFrom(const Plan& plan, const OptimizeArguments& args) {
  OptimizerOptions options = OptimizerOptions::fromDesign(*plan.design);
  if (args.starts) options.starts = *args.starts;
  if (args.time_limit) options.time_limit = *args.time_limit;
  if (args.seed) options.seed = static_cast<std::uint64_t>(*args.seed);
  options.threads = args.threads;
  if (args.pool > 0) options.pool_size = args.pool;
  if (args.evaluations > 0) options.refine_evaluations = args.evaluations;
  if (args.polish) options.polish = *args.polish;
  if (args.kicks) options.kicks = *args.kicks;
  options.algorithm = *refineAlgorithmFromName(args.algorithm);
  if (!args.quiet && isatty(STDERR_FILENO)) {
    const CriterionDisplay display = displayOf(plan.design->criterion);
    options.progress = [display](const OptimizerProgress& p) {
      std::fprintf(stderr, "\roptimize: %d/%d starts, best %.3f %s, %.1f s   ", p.starts_done,
                   p.starts, p.best * display.factor, display.unit, p.elapsed);
      std::fflush(stderr);
    };
  }
  return options;
}

double median(std::vector<double> values) {
  if (values.empty()) return NAN;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// How the optimum compares with its starting designs (criterion values, mm).
nlohmann::json optimizationToJson(const Plan& plan, const OptimizerOptions& options,
                                  const OptimizerSummary& summary) {
  std::vector<double> initial;
  for (const StartResult& s : summary.starts) {
    if (s.done) initial.push_back(s.initial);
  }
  const StartResult& best = summary.starts[static_cast<std::size_t>(summary.best_start)];
  nlohmann::json out;
  out["criterion"] = criterionName(plan.design->criterion);
  out["value"] = finiteOrNull(summary.value);
  out["unit"] = plan.design->criterion == Criterion::Pass ? "1 - P(pass)" : "mm";
  out["seed"] = options.seed;
  out["starts"] = options.starts;
  out["starts_done"] = summary.startsDone();
  out["pool"] = summary.pool_size;
  out["algorithm"] = refineAlgorithmName(options.algorithm);
  out["best_start"] = {{"index", summary.best_start},
                       {"initial", finiteOrNull(best.initial)},
                       {"exchanged", finiteOrNull(best.exchanged)},
                       {"refined", finiteOrNull(best.refined)}};
  out["random_initial"] = {
      {"best",
       finiteOrNull(initial.empty() ? NAN : *std::min_element(initial.begin(), initial.end()))},
      {"median", finiteOrNull(median(initial))}};
  out["termination"] =
      summary.termination == OptimizerSummary::Termination::Completed ? "completed" : "time_limit";
  return out;
}

std::string summaryTable(const Plan& plan, const OptimizerSummary& summary,
                         const Evaluation& evaluation, const std::string& output) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(3);
  const StartResult& best = summary.starts[static_cast<std::size_t>(summary.best_start)];
  out << "artcal optimize: " << plan.name << " -> " << output << "\n";
  out << "criterion " << criterionName(plan.design->criterion) << ", " << plan.design->placements;
  if (plan.design->instrument) {
    out << " station(s) x " << plan.design->instrument->readings << " readings from "
        << summary.pool_size << " candidate configurations\n\n";
  } else {
    out << " placements x " << plan.design->postures << " posture(s)\n\n";
  }
  const CriterionDisplay display = displayOf(plan.design->criterion);
  out << "  stage                    criterion (" << display.unit << ")\n";
  out << "  random initial design    " << std::setw(12) << best.initial * display.factor << "\n";
  out << "  after exchange           " << std::setw(12) << best.exchanged * display.factor << "\n";
  out << "  after refinement         " << std::setw(12) << best.refined * display.factor << "\n\n";
  if (evaluation.tip) {
    out << "  tip worst " << toMicrometres(evaluation.tip->worst.total) << " um, mean "
        << toMicrometres(evaluation.tip->mean) << " um\n";
  }
  out << "  " << summary.briefReport() << "\n";
  return out.str();
}

// `"calibrate": "identifiable"` in a spec: resolved on random placements of the design space
// (planning/design_identifiability.hpp), from the listed candidates, not from the spec's fixed
// placements alone (which parsePlan resolved on). Returns how many placements decided.
int resolveOnDesigns(Plan& spec, std::uint64_t seed) {
  if (!spec.machine.calibrate_identifiable) return 0;
  if (spec.calibrate_resolution) spec.machine.calibrated = spec.calibrate_resolution->listed;
  spec.calibrate_resolution.reset();
  const std::optional<DesignIdentifiability> by_designs = identifiableByDesigns(spec, seed);
  if (!by_designs) return 0;  // no feasible placement: the search says why
  spec.machine.calibrated = by_designs->resolution.kept;
  spec.calibrate_resolution = by_designs->resolution;
  return by_designs->candidates;
}

// No design identifies the calibrated set (docs/plan-format.md: exit 1, one line). The advice
// comes from the union of random placements of the design space: the parameters to fix when
// even the union cannot separate them, otherwise more placements or postures.
int refuseUnidentifiable(const Plan& spec, std::uint64_t seed, const std::string& source,
                         const std::string& why) {
  const std::optional<DesignIdentifiability> by_designs = identifiableByDesigns(spec, seed);
  std::cerr << "error: " << source;
  if (by_designs && !by_designs->resolution.dropped.empty()) {
    std::cerr << ": /machine/calibrate: " << why << "; no design of this space can identify "
              << by_designs->resolution.dropped.size() << " of the "
              << spec.machine.calibratedCount() << " calibrated parameters ("
              << by_designs->candidates
              << " random placements together cannot, docs/method.md section 5): "
              << calibrateFixText(spec, by_designs->resolution) << std::endl;
  } else {
    std::cerr << ": /design/placements: " << why;
    if (by_designs) {
      std::cerr << "; " << by_designs->candidates
                << " random placements together identify every calibrated parameter: more "
                   "placements or postures may";
    }
    std::cerr << std::endl;
  }
  return 1;
}

std::string resolutionLine(const Plan& plan, int candidates) {
  if (!plan.calibrate_resolution) return {};
  const auto& params = plan.machine.mechanism->parameters();
  std::ostringstream out;
  out << "  calibrate \"identifiable\" resolved on " << candidates
      << " random placements of the design space: " << plan.calibrate_resolution->kept.size()
      << " kept";
  if (!plan.calibrate_resolution->dropped.empty()) out << ", fixed at nominal:";
  for (int k : plan.calibrate_resolution->dropped) {
    out << " " << params[static_cast<std::size_t>(k)].name;
  }
  out << "\n";
  return out.str();
}

int runOptimize(const OptimizeArguments& args) {
  const bool sweep = !args.sweep.range.empty();
  if (!sweep) checkOutputPath(args.output);  // refused before the search, not after it
  const nlohmann::json spec_document = readJsonFile(args.spec);
  Plan spec = parsePlan(spec_document, args.spec, /*require_placements=*/false);
  for (const std::string& warning : spec.warnings) std::cerr << "warning: " << warning << "\n";
  if (!spec.design) {
    throw InputError(args.spec, "/design", "missing: an optimization spec needs a design block");
  }
  const OptimizerOptions options = optionsFrom(spec, args);
  const int resolved_on = resolveOnDesigns(spec, options.seed);
  if (sweep) {
    SweepArguments sweep_args = args.sweep;
    sweep_args.directory = args.output;
    sweep_args.json = args.json;
    return runPlacementSweep(spec_document, spec, options, sweep_args);
  }
  const OptimizerSummary summary = optimizePlan(spec, options);
  if (options.progress) std::fprintf(stderr, "\n");
  if (summary.best_start < 0) {
    return refuseUnidentifiable(spec, options.seed, args.spec, summary.message);
  }
  Plan plan = spec;
  appendDesignedPlacements(plan, summary.placements);
  const Evaluation evaluation = evaluatePlan(plan);
  // The rank policy re-checks the optimizer's pick (a finite criterion is not a full rank).
  if (!evaluation.identifiability.identifiable()) {
    return refuseUnidentifiable(spec, options.seed, args.spec,
                                "the optimized design is not identifiable");
  }
  nlohmann::json document = spec_document;
  document["placements"] = placementsToJson(plan);
  nlohmann::json predicted = evaluationToJson(plan, evaluation);
  predicted.erase("plan");
  predicted["optimization"] = optimizationToJson(spec, options, summary);
  if (plan.calibrate_resolution) {
    predicted["calibrate_resolved_on"] = {{"random_placements", resolved_on},
                                          {"seed", options.seed}};
  }
  document["predicted"] = predicted;
  writeJsonOutput(args.output, document);
  std::ostream& summary_out = summaryStream(args.output);
  if (args.json) {
    nlohmann::json out = predicted;
    out["plan"] = args.output;
    out["seconds"] = summary.seconds;
    summary_out << out.dump(2) << std::endl;
  } else {
    summary_out << summaryTable(spec, summary, evaluation, args.output)
                << resolutionLine(plan, resolved_on);
  }
  return 0;
}

void addOptimizeCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<OptimizeArguments>();
  CLI::App* cmd = app.add_subcommand(
      "optimize",
      "searches placements and postures minimising the design criterion; writes the complete "
      "plan with its predicted figures (exit 0)");
  cmd->add_option("SPEC", args->spec, "optimization spec: a plan with a design block")->required();
  cmd->add_option("-o,--output", args->output,
                  "the plan to write ('-': stdout, the summary then on stderr)")
      ->required();
  cmd->add_flag("--json", args->json, "print one JSON document instead of the table");
  cmd->add_flag("--quiet", args->quiet, "no progress line on stderr");
  cmd->add_option("--starts", args->starts, "starts (overrides design.starts)")
      ->check(CLI::Range(1, 10000));
  cmd->add_option("--seed", args->seed, "seed (overrides design.seed)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--time-limit", args->time_limit, "seconds (overrides design.time_limit)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--threads", args->threads, "worker threads; 0: all cores")
      ->check(CLI::Range(0, kMaxThreads))
      ->capture_default_str();
  cmd->add_option("--pool", args->pool,
                  "candidate placements (overrides design.pool); 0: design.pool or automatic")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  cmd->add_option("--evaluations", args->evaluations,
                  "refinement evaluations per start (overrides design.evaluations); 0: "
                  "design.evaluations or automatic")
      ->check(CLI::Range(0, 10000000))
      ->capture_default_str();
  cmd->add_option("--polish", args->polish,
                  "the best designs polished at the end (overrides design.polish)")
      ->check(CLI::Range(0, 10000));
  cmd->add_option("--kicks", args->kicks,
                  "iterated-local-search kicks per polished design (overrides design.kicks)")
      ->check(CLI::Range(0, 10000));
  cmd->add_option("--placements", args->sweep.range,
                  "A..B: optimize every count from A to B placements (seeding each count with "
                  "the design for the one before); -o is then a directory for the plans and "
                  "the summary");
  cmd->add_option("--target-tip", args->sweep.target,
                  "with --placements: the criterion to reach, mm (overrides design.target_tip)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--algorithm", args->algorithm, "continuous refinement (NLopt)")
      ->check(CLI::IsMember({"sbplx", "bobyqa", "neldermead", "cobyla", "none"}))
      ->capture_default_str();
  cmd->callback([&action, args] { action = [args] { return runOptimize(*args); }; });
}

const Registrar optimize_registrar(30, addOptimizeCommand);

}  // namespace

}  // namespace artcal::cli
