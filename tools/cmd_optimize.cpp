// artcal optimize SPEC -o PLAN (docs/plan-format.md, optimization spec; docs/method.md section 7).

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "artcal/core/error.hpp"
#include "artcal/core/parallel.hpp"
#include "artcal/io/output_file.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/planning/optimizer.hpp"
#include "artcal/planning/reading_pool.hpp"
#include "artcal/report/report.hpp"
#include "commands.hpp"
#include "optimize_output.hpp"

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
  std::string sweep_range;           ///< --placements A..B: every count, -o is a directory
  std::optional<double> target_tip;  ///< with --placements: overrides design.target_tip
  std::optional<int> choose;         ///< --choose N: SPEC is a pool of readings
  std::string criterion = "worst-tip";
  double prior_tolerance = 1.0;
  std::string workspace = "plan";
  int slot_candidates = 1024;
};

double toMicrometres(double mm) {
  return mm * 1000.0;
}

/// How a criterion value is shown: um for the lengths; for "pass" the quantity it stands for
/// (1 - P(pass), or the 95 % quantile of max |E|/MPE where P(pass) saturates: PassObjective).
struct CriterionDisplay {
  double value;
  std::string unit;
};

CriterionDisplay displayOf(Criterion criterion, double value) {
  if (criterion != Criterion::Pass) return {value * 1000.0, "um"};
  const PassObjective objective = passObjectiveOf(value);
  return {objective.value, objective.name()};
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
    const Criterion criterion = plan.design->criterion;
    options.progress = [criterion](const OptimizerProgress& p) {
      const CriterionDisplay display = displayOf(criterion, p.best);
      std::fprintf(stderr, "\roptimize: %d/%d starts, best %.3f %s, %.1f s   ", p.starts_done,
                   p.starts, display.value, display.unit.c_str(), p.elapsed);
      std::fflush(stderr);
    };
  }
  return options;
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
  const Criterion criterion = plan.design->criterion;
  if (criterion == Criterion::Pass) {
    out << "  stage                    criterion\n";
  } else {
    out << "  stage                    criterion (um)\n";
  }
  for (const auto& [stage, value] :
       {std::pair<const char*, double>{"random initial design", best.initial},
        {"after exchange", best.exchanged},
        {"after refinement", best.refined}}) {
    const CriterionDisplay display = displayOf(criterion, value);
    out << "  " << std::left << std::setw(25) << stage << std::right << std::setw(12)
        << display.value;
    if (criterion == Criterion::Pass) out << "  " << display.unit;
    out << "\n";
  }
  out << "\n";
  if (summary.pass) {
    const PassEstimate& pass = *summary.pass;
    const std::string saturation = pass.saturated
                                       ? std::string("saturated: within its standard error of ") +
                                             (pass.p_pass > 0.5 ? "1" : "0")
                                       : "not saturated";
    out << "  optimised " << passObjectiveOf(summary.value).name() << " (P(pass) " << saturation
        << "); P(pass) " << std::setprecision(4) << pass.p_pass
        << " (standard error <= " << pass.standard_error << ")"
        << ", q95 of max |E|/MPE " << pass.q95 << " (" << kPassDraws << " fixed draws)\n"
        << std::setprecision(3);
  }
  if (evaluation.tip) {
    out << "  tip worst " << toMicrometres(evaluation.tip->worst.total) << " um, mean "
        << toMicrometres(evaluation.tip->mean) << " um\n";
  }
  out << "  " << summary.briefReport() << "\n";
  return out.str();
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

/// `--placements A..B`: every count optimized, the plans and the summary written into -o DIR/.
int runPlacementSweep(const nlohmann::json& spec_document, const Plan& spec,
                      const OptimizerOptions& options, const OptimizeArguments& args) {
  std::function<void(int, double)> progress;
  if (options.progress) {
    progress = [](int m, double value) {
      std::cerr << "optimize --placements: m = " << m << ", G " << value * 1e3 << " um\n";
    };
  }
  const PlacementSweepOutput out = placementSweepOutput(
      spec_document, spec, options, args.sweep_range, args.target_tip, args.output, progress);
  createOutputDirectory(args.output);
  writeOutputFiles(out.files);
  if (args.json) {
    printJson(out.summary);
  } else {
    std::cout << out.table;
  }
  return 0;
}

/// `--choose N`: N readings of the readings plan SPEC (its readings are the candidates, docs/
/// optimize.md "Choosing readings from a pool"); -o gets the plan of the chosen readings.
int runChoose(const OptimizeArguments& args) {
  checkOutputPath(args.output);
  nlohmann::json document = readJsonFile(args.spec);
  const Plan pool_plan = parsePlan(document, args.spec);
  for (const std::string& warning : pool_plan.warnings) std::cerr << "warning: " << warning << "\n";
  const ReadingPool pool(pool_plan, args.prior_tolerance,
                         args.workspace == "pool" ? PoolWorkspace::Pool : PoolWorkspace::Plan);
  PoolOptions options;
  options.criterion = *criterionFromName(args.criterion);
  if (args.starts) options.starts = *args.starts;
  if (args.time_limit) options.time_limit = *args.time_limit;
  if (args.seed) options.seed = static_cast<std::uint64_t>(*args.seed);
  options.threads = args.threads;
  options.slot_candidates = args.slot_candidates;
  if (!args.quiet && isatty(STDERR_FILENO)) {
    options.progress = [](const OptimizerProgress& p) {
      std::fprintf(stderr, "\roptimize --choose: %d/%d starts, best %.3f um, %.1f s   ",
                   p.starts_done, p.starts, p.best * 1000.0, p.elapsed);
      std::fflush(stderr);
    };
  }
  const PoolChoice choice = chooseReadings(pool, *args.choose, options);
  if (options.progress) std::fprintf(stderr, "\n");
  const Plan chosen = pool.subsetPlan(choice.chosen);
  document["placements"] = placementsToJson(chosen);
  writeJsonOutput(args.output, document);
  nlohmann::json rows = nlohmann::json::array();
  for (int i : choice.chosen) {
    const PoolReading& r = pool.readings()[static_cast<std::size_t>(i)];
    rows.push_back(
        {{"placement", placementLabel(pool_plan.placements, static_cast<std::size_t>(r.placement))},
         {"reading", r.measurement}});
  }
  const nlohmann::json summary = {{"plan", args.output},
                                  {"criterion", criterionName(choice.criterion)},
                                  {"value_mm", choice.value},
                                  {"pool", pool.size()},
                                  {"chosen", rows},
                                  {"starts_done", choice.starts_done},
                                  {"starts", choice.starts},
                                  {"best_start", choice.best_start},
                                  {"termination", choice.timed_out ? "time_limit" : "completed"},
                                  {"seconds", choice.seconds}};
  std::ostream& out = summaryStream(args.output);
  if (args.json) {
    out << summary.dump(2) << std::endl;
  } else {
    out << "artcal optimize --choose: " << choice.chosen.size() << " of " << pool.size()
        << " readings of " << args.spec << " -> " << args.output << "\n  criterion "
        << criterionName(choice.criterion) << " " << std::fixed << std::setprecision(3)
        << choice.value * 1000.0 << " um (prior tolerance " << args.prior_tolerance << " mm)\n  "
        << (choice.timed_out ? "time limit reached" : "completed") << ": " << choice.starts_done
        << "/" << choice.starts << " starts, best start " << choice.best_start << ", "
        << choice.seconds << " s\n";
  }
  return 0;
}

int runOptimize(const OptimizeArguments& args) {
  if (args.choose) return runChoose(args);
  const bool sweep = !args.sweep_range.empty();
  if (!sweep) checkOutputPath(args.output);  // refused before the search, not after it
  const nlohmann::json spec_document = readJsonFile(args.spec);
  Plan spec = parsePlan(spec_document, args.spec, /*require_placements=*/false);
  for (const std::string& warning : spec.warnings) std::cerr << "warning: " << warning << "\n";
  if (!spec.design) {
    throw InputError(args.spec, "/design", "missing: an optimization spec needs a design block");
  }
  const OptimizerOptions options = optionsFrom(spec, args);
  const int resolved_on = resolveOnDesigns(spec, options.seed);
  if (sweep) return runPlacementSweep(spec_document, spec, options, args);
  const OptimizerSummary summary = optimizePlan(spec, options);
  if (options.progress) std::fprintf(stderr, "\n");
  const OptimizedPlan optimized =
      optimizedPlan(spec_document, spec, args.spec, options, summary, resolved_on);
  const Plan& plan = optimized.plan;
  const nlohmann::json& predicted = optimized.document["predicted"];
  writeJsonOutput(args.output, optimized.document);
  std::ostream& summary_out = summaryStream(args.output);
  if (args.json) {
    nlohmann::json out = predicted;
    out["plan"] = args.output;
    out["seconds"] = summary.seconds;
    summary_out << out.dump(2) << std::endl;
  } else {
    summary_out << summaryTable(spec, summary, optimized.evaluation, args.output)
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
  cmd->add_option("--seed", args->seed, "seed (overrides design.seed)")->check(nonNegativeNumber());
  cmd->add_option("--time-limit", args->time_limit, "seconds (overrides design.time_limit)")
      ->check(positiveNumber());
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
  cmd->add_option("--placements", args->sweep_range,
                  "A..B: optimize every count from A to B placements (seeding each count with "
                  "the design for the one before); -o is then a directory for the plans and "
                  "the summary");
  cmd->add_option("--target-tip", args->target_tip,
                  "with --placements: the criterion to reach, mm (overrides design.target_tip)")
      ->check(positiveNumber());
  cmd->add_option("--choose", args->choose,
                  "N: SPEC is a readings plan (an earlier session's, or imported readings); "
                  "choose N of its readings by exchange and write their plan to -o")
      ->check(CLI::Range(1, 100000000));
  cmd->add_option("--criterion", args->criterion, "with --choose: the criterion")
      ->check(CLI::IsMember({"worst-tip", "mean-tip", "D", "A"}))
      ->capture_default_str();
  cmd->add_option(
         "--workspace", args->workspace,
         "with --choose: the configurations G and I look at: the plan's workspace, or the pool's "
         "own readings")
      ->check(CLI::IsMember({"plan", "pool"}))
      ->capture_default_str();
  cmd->add_option("--prior-tolerance", args->prior_tolerance,
                  "with --choose: mm, the standard deviation of nominal parameters the machine "
                  "states no prior for (angles: at the reach)")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--slot-candidates", args->slot_candidates,
                  "with --choose: candidates tried per slot of the exchange (a fresh random subset "
                  "of this many "
                  "when the pool is larger); 0: all")
      ->check(CLI::Range(0, 100000000))
      ->capture_default_str();
  cmd->add_option("--algorithm", args->algorithm, "continuous refinement (NLopt)")
      ->check(CLI::IsMember({"sbplx", "bobyqa", "neldermead", "cobyla", "none"}))
      ->capture_default_str();
  cmd->callback([&action, args] { action = [args] { return runOptimize(*args); }; });
}

const Registrar optimize_registrar(30, "optimize", addOptimizeCommand);

}  // namespace

}  // namespace artcal::cli
