// artcal simulate / calibrate / confirm (docs/plan-format.md, command line; docs/method.md section
// 6).

#include <unistd.h>

#include <iostream>
#include <utility>

#include "artcal/calibration/calibrate_readings.hpp"
#include "artcal/calibration/calibrator.hpp"
#include "artcal/calibration/confirmation.hpp"
#include "artcal/calibration/simulation.hpp"
#include "artcal/core/parallel.hpp"
#include "artcal/estimation/identifiability.hpp"
#include "artcal/io/machine_covariance.hpp"
#include "artcal/io/machine_frames.hpp"
#include "artcal/io/output_file.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/truth_io.hpp"
#include "artcal/report/calibration_report.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {

void checkOptions(bool valid, const std::string& what, const std::string& error) {
  if (!valid) throw std::invalid_argument(what + ": " + error);
}

// ---------------------------------------------------------------------------------- simulate

struct SimulateArguments {
  std::string plan, truth, output;
  std::uint64_t seed = 1;
  double noise_scale = 1.0;
  bool no_artifact_errors = false;
  bool json = false;
};

constexpr const char* kTruthHelp =
    "TRUTH file: the true machine, file units (mm, deg). Either a machine block as "
    "`calibrate --write-machine` writes it, or {\"parameters\": {\"l1\": 150.02, ...}} (named "
    "values over the plan's nominal ones), or {\"machine\": {...}, \"parameters\": {...}}.";

int runSimulate(const SimulateArguments& args) {
  checkOutputPath(args.output);
  const Plan plan = loadPlanReporting(args.plan);
  nlohmann::json document = readJsonFile(args.plan);
  const Eigen::VectorXd truth = loadTruth(args.truth, plan);
  SimulationOptions options;
  options.noise_scale = args.noise_scale;
  options.artifact_errors = !args.no_artifact_errors;
  std::string error;
  checkOptions(options.isValid(&error), "simulate", error);
  const Simulator simulator(plan, options);
  NormalSource normal(args.seed);
  const SimulatedRun run = simulator.simulate(truth, normal);
  Plan simulated = plan;
  simulated.placements = run.placements;
  document["placements"] = placementsToJson(simulated);
  nlohmann::json record = truthToJson(plan.machine, truth);
  record["seed"] = args.seed;
  record["noise_scale"] = args.noise_scale;
  record["artifact_errors"] =
      std::vector<double>(run.systematic.data(), run.systematic.data() + run.systematic.size());
  document["simulation"] = record;
  writeJsonOutput(args.output, document);
  if (args.output != "-") {
    if (args.json) {
      printJson({{"output", args.output}, {"seed", args.seed}, {"simulation", record}});
    } else {
      std::cout << "simulated readings of " << run.placements.size() << " placements (seed "
                << args.seed << ") written to " << args.output << "\n";
    }
  }
  return 0;
}

void addSimulateCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<SimulateArguments>();
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "the readings a machine with the TRUTH parameters would report for the plan (inverse "
      "kinematics, probe and encoder noise, one draw of each artifact's calibration error); "
      "writes the plan with those readings");
  cmd->footer(kTruthHelp);
  cmd->add_option("PLAN", args->plan, "plan file (artcal-plan/1)")->required();
  cmd->add_option("--truth", args->truth, "the true machine (see below)")->required();
  cmd->add_option("--seed", args->seed, "random seed (same seed, same readings)")
      ->capture_default_str();
  cmd->add_option("-o,--output", args->output, "output plan with simulated readings ('-': stdout)")
      ->required();
  cmd->add_option("--noise-scale", args->noise_scale, "simulate K times the declared noise")
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_flag("--no-artifact-errors", args->no_artifact_errors,
                "do not draw the artifacts' systematic errors (c = 0)");
  cmd->add_flag("--json", args->json, "print one JSON document instead of the summary line");
  cmd->callback([&action, args] { action = [args] { return runSimulate(*args); }; });
}

// --------------------------------------------------------------------------------- calibrate

struct CalibrateArguments {
  std::string plan, write_machine;
  std::string repeats = "count";
  bool json = false;
  CalibrationOptions options;
  std::string model_choice = "held-out";
};

int runCalibrate(CalibrateArguments args) {
  std::string error;
  checkOptions(args.options.isValid(&error), "calibrate", error);
  args.options.model_choice = *fromName(kModelChoiceModeNames, args.model_choice);
  if (!args.write_machine.empty()) checkOutputPath(args.write_machine);
  Plan given = loadPlanReporting(args.plan);
  // Copies of a reading counted once: the figures as if each were read once.
  const std::vector<std::string> once =
      args.repeats == "once" ? countRepeatsOnce(given.placements) : std::vector<std::string>{};
  for (const std::string& line : once) std::cerr << "note: " << line << "\n";
  // The plan as calibrated: its kept set and the noise used (given itself is not changed).
  const CalibrationRun run = calibrateReadings(given, args.options);
  const Plan& plan = run.decided;
  const Calibration& calibration = run.calibration;
  if (calibration.dof < 0) {
    // Fewer equations than unknowns: nothing is estimated, the answer is check's.
    std::cerr << "calibrate: " << args.plan << ": " << -calibration.dof
              << " more unknowns than equations (degrees of freedom " << calibration.dof
              << "): nothing can be estimated; check's answer follows\n";
    if (!args.write_machine.empty())
      std::cerr << "warning: nothing estimated: " << args.write_machine << " not written\n";
    return printCheck(given, args.json, kDefaultRankTolerance);
  }
  if (!args.write_machine.empty()) {
    // Only a converged estimate may become the next plan's machine.
    if (calibration.summary.converged()) {
      nlohmann::json machine = machineToJson(plan.machine, calibration.parameters);
      // V_p travels with the estimate: `verify --machine` predicts the spread from it.
      if (const auto uncertainty = calibration.uncertainty(plan.machine))
        machine["covariance"] = covarianceToJson(plan.machine, *uncertainty);
      // The placements' (stations') estimated frames: `verify` scores held-out readings in them.
      machine["frames"] = framesToJson(plan, calibration.poses);
      writeJsonOutput(args.write_machine, machine);
    } else {
      std::cerr << "warning: not converged: " << args.write_machine << " not written\n";
    }
  }
  std::ostream& out = summaryStream(args.write_machine);
  if (args.json) {
    out << calibrationToJson(plan, plan.placements, calibration).dump(2) << std::endl;
  } else {
    out << calibrationTable(plan, plan.placements, calibration);
  }
  return calibration.summary.converged() ? 0 : 1;
}

void addCalibrateCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<CalibrateArguments>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "estimates the parameters from the readings in PLAN (Levenberg-Marquardt on the "
      "Schur-reduced block structure): estimates, u, u_posterior, chi2/dof, residuals (exit 0 "
      "converged, 1 not)");
  cmd->add_option("PLAN", args->plan, "plan file with the readings taken")->required();
  cmd->add_flag("--json", args->json, "print one JSON document instead of the tables");
  cmd->add_option("--write-machine", args->write_machine,
                  "write the machine block with the estimated parameters (the next plan's "
                  "machine) to this file, when converged ('-': stdout, the tables then on "
                  "stderr)");
  cmd->add_option("--repeats", args->repeats,
                  "readings repeated bit for bit: count (each copy a measurement, with a warning) "
                  "or once (the copies removed, the figures as if each were read once)")
      ->check(CLI::IsMember({"count", "once"}))
      ->capture_default_str();
  cmd->add_option("--model-choice", args->model_choice,
                  "how \"calibrate\": \"identifiable\" settles the kept set: held-out (the rank "
                  "rule's set, or a smaller one of its order when the readings left out in turn "
                  "hold clearly better with it) or rank (information alone)")
      ->check(CLI::IsMember({"held-out", "rank"}))
      ->capture_default_str();
  cmd->add_option("--max-iterations", args->options.max_iterations, "iteration limit")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--step-tol", args->options.step_tolerance,
                  "converged when every step is below this many standard uncertainties")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--flag-threshold", args->options.flag_threshold,
                  "flag normalised residuals larger than this")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--gross-threshold", args->options.gross_threshold,
                  "call a reading a gross error when its normalised residual exceeds this many "
                  "times max(1, Birge ratio)")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->callback([&action, args] { action = [args] { return runCalibrate(*args); }; });
}

// ----------------------------------------------------------------------------------- confirm

struct ConfirmArguments {
  std::string plan;
  bool json = false;
  bool quiet = false;
  ConfirmationOptions options;
};

int runConfirm(ConfirmArguments args) {
  std::string error;
  checkOptions(args.options.isValid(&error), "confirm", error);
  const Plan plan = loadPlanReporting(args.plan);
  if (!args.quiet && isatty(STDERR_FILENO)) {
    args.options.progress = [](int done, int total) {
      if (done == total || done % 10 == 0) {
        std::cerr << "\rtrials " << done << "/" << total << (done == total ? "\n" : "")
                  << std::flush;
      }
    };
  }
  const Confirmation confirmation = confirmPlan(plan, args.options);
  if (args.json) {
    printJson(confirmationToJson(plan, args.options, confirmation));
  } else {
    std::cout << confirmationTable(plan, args.options, confirmation);
  }
  return confirmation.confirmed ? 0 : 1;
}

void addConfirmCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<ConfirmArguments>();
  CLI::App* cmd = app.add_subcommand(
      "confirm",
      "Monte-Carlo confirmation: T simulated calibrations of PLAN against the predicted "
      "uncertainties; prints the band the trial count allows (exit 0 confirmed, 1 not)");
  ConfirmationOptions& o = args->options;
  cmd->add_option("PLAN", args->plan, "plan file (artcal-plan/1)")->required();
  cmd->add_option("--trials", o.trials, "number of simulated calibrations")
      ->check(CLI::Range(2, 10000000))
      ->capture_default_str();
  cmd->add_option("--seed", o.seed, "random seed (same seed, same result, any thread count)")
      ->capture_default_str();
  cmd->add_option("--threads", o.threads, "worker threads (0: all cores)")
      ->check(CLI::Range(0, kMaxThreads))
      ->capture_default_str();
  cmd->add_option("--noise-scale", o.noise_scale,
                  "simulate K times the declared noise (K = 2 must not confirm)")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--perturbation", o.perturbation,
                  "true parameters = nominal + this many predicted u times N(0, 1)")
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--allowance", o.allowance, "relative non-linearity allowance of the band")
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--level", o.level, "family-wise false-alarm probability of the band")
      ->check(CLI::Range(1e-12, 0.5))
      ->capture_default_str();
  cmd->add_flag("--quiet", args->quiet, "no progress on stderr");
  cmd->add_flag("--json", args->json, "print one JSON document instead of the table");
  cmd->callback([&action, args] { action = [args] { return runConfirm(*args); }; });
}

const Registrar simulate_registrar(40, "simulate", addSimulateCommand);
const Registrar calibrate_registrar(50, "calibrate", addCalibrateCommand);
const Registrar confirm_registrar(60, "confirm", addConfirmCommand);

}  // namespace

}  // namespace artcal::cli
