// artcal compare-designs RECORDED HELD_OUT (docs/optimize.md, "Does the choice win on a real
// machine?"; planning/design_comparison.hpp): subsets of the recorded readings chosen by each
// criterion, by random draws and by the spread heuristic, each calibrated alone and scored on the
// held-out readings.

#include <unistd.h>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "artcal/core/error.hpp"
#include "artcal/core/parallel.hpp"
#include "artcal/io/plan_file.hpp"
#include "artcal/planning/design_comparison.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {

struct CompareArguments {
  std::string recorded, held_out;
  std::vector<int> sizes{8, 12, 16, 25, 50};
  std::vector<std::string> criteria{"worst-tip", "mean-tip", "D", "A"};
  int draws = 12;
  long seed = 1;
  int starts = 8;
  int threads = 0;
  double time_limit = 60.0;
  double prior_tolerance = 1.0;
  std::string workspace = "plan";
  std::string calibrated_set = "pool";
  bool json = false;
  bool quiet = false;
};

nlohmann::json subsetToJson(const SubsetScore& s) {
  nlohmann::json out = {
      {"readings", s.readings}, {"worst_tip_mm", s.criterion}, {"calibrated", s.calibrated}};
  if (s.calibrated) {
    out["held_out_mean_mm"] = s.held_out_mean;
    out["held_out_rms_mm"] = s.held_out_rms;
  } else {
    out["failure"] = s.failure;
  }
  return out;
}

nlohmann::json comparisonToJson(const DesignComparison& c) {
  nlohmann::json sizes = nlohmann::json::array();
  for (const SizeComparison& size : c.sizes) {
    nlohmann::json methods = nlohmann::json::object();
    for (const MethodScore& m : size.methods) {
      nlohmann::json subsets = nlohmann::json::array();
      for (const SubsetScore& s : m.subsets) subsets.push_back(subsetToJson(s));
      const auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; };
      methods[m.method] = {
          {"held_out_mean_mm",
           {{"median", number(m.median)}, {"min", number(m.min)}, {"max", number(m.max)}}},
          {"failed", m.failed},
          {"choice_seconds", m.seconds},
          {"subsets", subsets}};
    }
    sizes.push_back({{"n", size.size}, {"methods", methods}});
  }
  return {{"pool", c.pool},
          {"held_out_readings", c.held_out},
          {"unit", "mm"},
          {"all_readings", subsetToJson(c.all)},
          {"sizes", sizes}};
}

std::string comparisonTable(const DesignComparison& c) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(3);
  out << "held-out error (mean 3-D deviation in the calibration's station, mm) of subsets of N of "
      << c.pool << " recorded readings, " << c.held_out << " held-out readings\n";
  out << "all " << c.pool << " readings: "
      << (c.all.calibrated ? std::to_string(c.all.held_out_mean) : "failed: " + c.all.failure)
      << "\n\n";
  if (c.sizes.empty()) return out.str();
  out << "     N";
  for (const MethodScore& m : c.sizes.front().methods)
    out << std::setw(m.method == "random" ? 30 : 11) << m.method;
  out << "\n";
  for (const SizeComparison& size : c.sizes) {
    out << std::setw(6) << size.size;
    for (const MethodScore& m : size.methods) {
      if (m.method == "random") {
        std::ostringstream cell;
        cell << std::fixed << std::setprecision(3) << m.median << " [" << m.min << " .. " << m.max
             << "]";
        out << std::setw(30) << cell.str();
      } else {
        out << std::setw(11) << m.median;
      }
    }
    out << "\n";
  }
  out << "\nrandom: median [min .. max] over the draws; failed calibrations are left out (JSON: "
         "failed).\nworst-tip G of each subset (mm), the criterion every row is also ranked by:\n";
  for (const SizeComparison& size : c.sizes) {
    out << std::setw(6) << size.size;
    for (const MethodScore& m : size.methods) {
      double g = 0.0;
      for (const SubsetScore& s : m.subsets)
        g += s.criterion / static_cast<double>(m.subsets.size());
      out << std::setw(m.method == "random" ? 30 : 11) << g;
    }
    out << "\n";
  }
  return out.str();
}

int runCompare(const CompareArguments& args) {
  const Plan recorded = loadPlanReporting(args.recorded);
  const Plan held_out = loadPlanReporting(args.held_out);
  ComparisonOptions options;
  options.sizes = args.sizes;
  options.draws = args.draws;
  options.seed = static_cast<std::uint64_t>(args.seed);
  options.prior_tolerance = args.prior_tolerance;
  options.calibrated_set = args.calibrated_set == "pool" ? ReadingPool::CalibratedSet::Pool
                                                         : ReadingPool::CalibratedSet::Subset;
  options.workspace = args.workspace == "pool" ? PoolWorkspace::Pool : PoolWorkspace::Plan;
  options.criteria.clear();
  for (const std::string& name : args.criteria)
    options.criteria.push_back(*criterionFromName(name));
  options.pool.seed = static_cast<std::uint64_t>(args.seed);
  options.pool.starts = args.starts;
  options.pool.slot_candidates = 1024;  // optimize --choose's default
  options.pool.threads = args.threads;
  options.pool.time_limit = args.time_limit;
  if (!args.quiet) options.progress = [](const std::string& line) { std::cerr << line << "\n"; };
  const DesignComparison comparison = compareDesigns(recorded, held_out, options);
  if (args.json) {
    printJson(comparisonToJson(comparison));
  } else {
    std::cout << comparisonTable(comparison);
  }
  return 0;
}

void addCompareCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<CompareArguments>();
  CLI::App* cmd = app.add_subcommand(
      "compare-designs",
      "chooses N of the RECORDED readings by each criterion, by random draws and by farthest "
      "points in joint space, calibrates each subset alone and scores it on the HELD_OUT "
      "readings in the station the calibration estimated (exit 0)");
  cmd->add_option("RECORDED", args->recorded, "readings plan: the candidate readings")->required();
  cmd->add_option("HELD_OUT", args->held_out, "readings plan of the same instrument: the score")
      ->required();
  cmd->add_option("--sizes", args->sizes, "subset sizes N")
      ->delimiter(',')
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--criteria", args->criteria, "criteria compared")
      ->delimiter(',')
      ->check(CLI::IsMember({"worst-tip", "mean-tip", "D", "A"}))
      ->capture_default_str();
  cmd->add_option("--draws", args->draws, "random subsets per size")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "seed of the draws and the exchange's starts")
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--starts", args->starts, "exchange starts per choice")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "worker threads; 0: all cores")
      ->check(CLI::Range(0, kMaxThreads))
      ->capture_default_str();
  cmd->add_option("--time-limit", args->time_limit, "seconds per choice")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--calibrated-set", args->calibrated_set,
                  "with \"calibrate\": \"identifiable\": the set resolved on every recorded "
                  "reading (pool), or on each subset's own readings (subset)")
      ->check(CLI::IsMember({"pool", "subset"}))
      ->capture_default_str();
  cmd->add_option("--workspace", args->workspace,
                  "the configurations G and I look at: the plan's workspace, or the pool's "
                  "own readings")
      ->check(CLI::IsMember({"plan", "pool"}))
      ->capture_default_str();
  cmd->add_option("--prior-tolerance", args->prior_tolerance,
                  "mm: the standard deviation of the nominal parameters the machine states no "
                  "prior for (angles: at the reach), what a subset too small to identify them "
                  "leaves them at")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "print one JSON document instead of the table");
  cmd->add_flag("--quiet", args->quiet, "no progress lines on stderr");
  cmd->callback([&action, args] { action = [args] { return runCompare(*args); }; });
}

const Registrar compare_registrar(32, "compare-designs", addCompareCommand);

}  // namespace

}  // namespace artcal::cli
