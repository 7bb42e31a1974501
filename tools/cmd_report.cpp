// artcal report PLAN -o report.html [--svg DIR]: the self-contained HTML report (html_report.hpp).

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>

#include "artcal/calibration/calibrate_readings.hpp"
#include "artcal/calibration/calibrator.hpp"
#include "artcal/calibration/station_verification.hpp"
#include "artcal/core/error.hpp"
#include "artcal/estimation/error_functions.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/io/output_file.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/plausibility.hpp"
#include "artcal/io/truth_io.hpp"
#include "artcal/planning/procedure.hpp"
#include "artcal/report/acceptance_report.hpp"
#include "artcal/report/calibration_report.hpp"
#include "artcal/report/cartesian_report.hpp"
#include "artcal/report/html_report.hpp"
#include "artcal/report/report.hpp"
#include "artcal/report/station_figures.hpp"
#include "artcal/report/station_report.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {

struct ReportArguments {
  std::string plan;
  std::string output;
  std::string svg_dir;
  bool json = false;
  double rank_tolerance = kDefaultRankTolerance;
  int profile_steps = 21;
  bool calibrate = false;
  double flag_threshold = CalibrationOptions{}.flag_threshold;
  std::string held_out;  ///< an instrument plan's held-out stations (--held-out)
};

/// The readings are calibrated when asked, or when they were simulated (`artcal simulate`
/// records a `simulation` block): nominal planning readings would only give zero residuals.
bool wantsCalibration(const ReportArguments& args, const nlohmann::json& document) {
  return args.calibrate || !args.held_out.empty() || document.contains("simulation");
}

/// The held-out stations of `file` verified with the nominal and with the calibrated machine
/// (calibration/station_verification.hpp), as the report's held_out_json.
nlohmann::json heldOutStations(const std::string& file, const Plan& calibrated_plan,
                               const Calibration& calibration) {
  Plan held = parsePlan(readJsonFile(file), file, true, /*check_plausibility=*/false);
  const Machine& machine = calibrated_plan.machine;
  const auto& mine = held.machine.mechanism->parameters();
  const auto& theirs = machine.mechanism->parameters();
  const bool same = held.machine.mechanism->modelName() == machine.mechanism->modelName() &&
                    mine.size() == theirs.size() &&
                    std::equal(mine.begin(), mine.end(), theirs.begin(),
                               [](const auto& a, const auto& b) { return a.name == b.name; });
  if (!same) {
    throw InputError(file, "/machine",
                     "the held-out plan's machine is not the calibrated plan's (another model or "
                     "other parameters): give held-out readings of the same machine");
  }
  const StationsVerification nominal = verifyStations(held, held.machine.nominal, std::nullopt);
  if (nominal.stations.empty()) {
    throw InputError(file, "/placements",
                     "no instrument station to hold out: --held-out takes an instrument plan's "
                     "stations (for artifact placements, use artcal verify --machine)");
  }
  checkPlausibility(held, calibration.parameters, "the calibrated machine");
  const auto uncertainty = calibration.uncertainty(machine);
  held.noise = withEstimatedProbeNoise(held.noise, uncertainty);
  const StationsVerification calibrated = verifyStations(held, calibration.parameters, uncertainty);
  return {{"plan", file},
          {"nominal", stationsVerificationToJson(held, nominal)},
          {"calibrated", stationsVerificationToJson(held, calibrated)}};
}

/// The HTML and, with --svg, every figure: written as one output (writeOutputFiles), so that a
/// refused or failed file leaves the earlier report and figures as they were.
void writeReportFiles(const ReportArguments& args, const std::string& html,
                      const std::vector<ReportFigure>& figures) {
  std::vector<std::pair<std::string, std::string>> files;
  if (args.output != kStandardOutput) files.emplace_back(args.output, html);
  if (!args.svg_dir.empty()) {
    createOutputDirectory(args.svg_dir);
    for (const ReportFigure& figure : figures) {
      files.emplace_back((std::filesystem::path(args.svg_dir) / (figure.name + ".svg")).string(),
                         "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n" + figure.svg);
    }
  }
  writeOutputFiles(files);
  if (args.output == kStandardOutput) writeOutputFile(args.output, html);
}

/// A Cartesian CMM's error functions along its axes (cartesian_report.hpp): the predicted bands
/// at nominal, or after a calibration the estimate with its band and, for readings simulated by
/// `artcal simulate` (its `simulation` block names the true parameters), against the truth.
void addErrorFunctionFigures(const Plan& plan, const nlohmann::json& document,
                             const std::string& path, const Evaluation& evaluation,
                             const std::optional<Calibration>& calibration,
                             std::vector<ReportFigure>& figures) {
  if (!axisErrorFunctionsOf(plan)) return;
  std::vector<ReportFigure> more;
  if (calibration && calibration->covariance) {
    std::optional<Eigen::VectorXd> truth;
    if (document.contains("simulation") && document["simulation"].contains("parameters")) {
      const nlohmann::json record = {{"parameters", document["simulation"]["parameters"]}};
      truth = parseTruth(record, path, plan);
    }
    more = errorFunctionFigures(
        plan, errorFunctionBands(plan, calibration->covariance->V, calibration->parameters, true,
                                 truth ? &*truth : nullptr));
  } else if (evaluation.covariance) {
    more = errorFunctionFigures(
        plan, errorFunctionBands(plan, evaluation.covariance->V, plan.machine.nominal, false));
  }
  figures.insert(figures.end(), more.begin(), more.end());
}

/// The operator's procedure for the report, or why there is none (no joint values within the
/// limits reach a placed feature: the report says so instead of failing).
std::optional<Procedure> reportProcedure(const Plan& plan, std::string& no_procedure) {
  try {
    return operatorProcedure(plan);
  } catch (const RunError& e) {
    no_procedure = e.describe();
    return std::nullopt;
  }
}

/// What was written: the JSON twin of the table printed.
nlohmann::json summaryJson(const ReportArguments& args, const std::string& html,
                           const std::vector<ReportFigure>& figures, bool identifiable,
                           const std::optional<bool>& converged) {
  nlohmann::json out = {{"report", args.output},
                        {"bytes", html.size()},
                        {"identifiable", identifiable},
                        {"calibration_converged", converged ? nlohmann::json(*converged) : nullptr},
                        {"figures", nlohmann::json::array()}};
  for (const ReportFigure& f : figures) {
    nlohmann::json figure = {{"name", f.name}, {"bytes", f.svg.size()}};
    if (!args.svg_dir.empty()) {
      figure["file"] = (std::filesystem::path(args.svg_dir) / (f.name + ".svg")).string();
    }
    out["figures"].push_back(figure);
  }
  return out;
}

void printSummary(const nlohmann::json& summary, std::ostream& out) {
  out << "Report " << summary["report"].get<std::string>() << " ("
      << summary["bytes"].get<std::size_t>() << " bytes)"
      << (summary["identifiable"].get<bool>() ? "" : "; the plan is NOT identifiable")
      << (summary["calibration_converged"] == false ? "; the calibration did NOT converge" : "")
      << "\n  figure                bytes  file\n";
  for (const auto& f : summary["figures"]) {
    out << "  " << std::left << std::setw(18) << f["name"].get<std::string>() << " " << std::right
        << std::setw(8) << f["bytes"].get<std::size_t>() << "  "
        << (f.contains("file") ? f["file"].get<std::string>() : "(inline only)") << "\n";
  }
}

void addReportCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<ReportArguments>();
  CLI::App* cmd = app.add_subcommand(
      "report",
      "writes a self-contained HTML report (layout, tip uncertainty, parameters, correlation, "
      "identifiability, calibration) with the numbers of `evaluate --json` (exit 0; 1 when not "
      "identifiable or the calibration did not converge)");
  cmd->add_option("PLAN", args->plan, "plan file (artcal-plan/1)")->required();
  cmd->add_option("-o,--output", args->output,
                  "HTML file to write ('-': stdout, the summary then on stderr)")
      ->required();
  cmd->add_option("--svg", args->svg_dir, "also write each figure as DIR/<name>.svg");
  cmd->add_flag("--json", args->json, "print what was written as one JSON document");
  cmd->add_option("--rank-tol", args->rank_tolerance,
                  "relative eigenvalue tolerance of the rank test on the scaled N_red")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--profile-steps", args->profile_steps,
                  "rows of the planar2r tip-uncertainty profile against reach")
      ->check(CLI::Range(2, 10000))
      ->capture_default_str();
  cmd->add_flag("--calibrate", args->calibrate,
                "also calibrate the plan's readings and show the result and the residuals "
                "(automatic for a plan written by `artcal simulate`)");
  cmd->add_option("--flag-threshold", args->flag_threshold,
                  "standardised residual beyond which a reading is flagged (as calibrate)")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--held-out", args->held_out,
                  "an instrument plan of held-out stations of the same machine: the report shows "
                  "their deviations with the nominal and the calibrated machine (implies "
                  "--calibrate)");
  cmd->callback([&action, args] {
    action = [args] {
      checkOutputPath(args->output);
      if (!args->svg_dir.empty()) checkOutputDirectory(args->svg_dir);
      const nlohmann::json document = readJsonFile(args->plan);
      const Plan plan = parsePlan(document, args->plan);
      for (const std::string& warning : plan.warnings) std::cerr << "warning: " << warning << "\n";
      std::optional<nlohmann::json> calibration_json;
      std::optional<bool> converged;
      std::optional<Calibration> calibration;
      // calibrate holds weakly determined parameters at nominal and may estimate the noise: the
      // plan as it decided says with what it calibrated.
      std::optional<Plan> decided;
      if (wantsCalibration(*args, document)) {
        CalibrationOptions options;
        options.flag_threshold = args->flag_threshold;
        CalibrationRun run = calibrateReadings(plan, options);
        decided.emplace(std::move(run.decided));
        calibration.emplace(std::move(run.calibration));
        calibration_json = calibrationToJson(*decided, decided->placements, *calibration);
        converged = calibration->summary.converged();
      }
      const Plan& calibrated = decided ? *decided : plan;
      // The tip map and the predictions with the noise the calibration estimated ("estimate"),
      // or the plan's starting value where its readings cannot tell (predictionNoise).
      Plan predicted = plan;
      if (plan.noise.estimate_probe) {
        const CalibrationRun run{calibration ? *calibration : Calibration{}, calibrated};
        predicted.noise.probe = predictionNoise(plan, calibration ? &run : nullptr).probe;
      }
      const Evaluation evaluation =
          evaluatePlan(predicted, {args->rank_tolerance, args->profile_steps});
      nlohmann::json evaluation_json = evaluationToJson(predicted, evaluation);
      // The tip map with the error the model does not explain, where the calibration told it.
      if (calibration && calibration->unmodelled) {
        if (const auto with_unmodelled = tipWithUnmodelled(
                evaluation, calibration->unmodelled->sigma, predicted.machine.dimension()))
          evaluation_json["tip_with_unmodelled"] =
              tipWithUnmodelledToJson(*with_unmodelled, *calibration->unmodelled);
      }
      std::optional<nlohmann::json> held_out_json;
      if (!args->held_out.empty())
        held_out_json = heldOutStations(args->held_out, calibrated, *calibration);
      // The plan's acceptance test, predicted by src/acceptance; the report reads it.
      const std::optional<PlanAcceptance> acceptance = predictPlanAcceptance(predicted, evaluation);
      std::optional<nlohmann::json> acceptance_json;
      if (acceptance) acceptance_json = planAcceptanceToJson(*acceptance);
      std::string no_procedure;
      const std::optional<Procedure> procedure = reportProcedure(plan, no_procedure);
      const ReportInput input{plan,
                              document,
                              evaluation,
                              evaluation_json,
                              calibration_json ? &*calibration_json : nullptr,
                              args->flag_threshold,
                              acceptance_json ? &*acceptance_json : nullptr,
                              procedure ? &*procedure : nullptr,
                              no_procedure,
                              held_out_json ? &*held_out_json : nullptr};
      std::vector<ReportFigure> figures = reportFigures(input);
      if (calibration_json) {
        for (ReportFigure& f : stationResidualFigures(calibrated, *calibration_json))
          figures.push_back(std::move(f));
      }
      if (held_out_json) {
        for (ReportFigure& f : heldOutDeviationFigures(*held_out_json))
          figures.push_back(std::move(f));
      }
      addErrorFunctionFigures(calibrated, document, args->plan, evaluation, calibration, figures);
      if (acceptance) {
        if (auto figure = acceptanceReportFigure(*acceptance))
          figures.push_back(std::move(*figure));
      }
      const std::string html = htmlReport(input, figures);
      writeReportFiles(*args, html, figures);
      nlohmann::json summary =
          summaryJson(*args, html, figures, evaluation.identifiable(), converged);
      if (acceptance_json) summary["acceptance"] = *acceptance_json;
      if (held_out_json) summary["held_out"] = *held_out_json;
      if (args->json) {
        summaryStream(args->output) << summary.dump(2) << std::endl;
      } else {
        printSummary(summary, summaryStream(args->output));
        if (acceptance) summaryStream(args->output) << "\n" << planAcceptanceTable(*acceptance);
      }
      return evaluation.identifiable() && converged.value_or(true) ? 0 : 1;
    };
  });
}

const Registrar report_registrar(70, "report", addReportCommand);

}  // namespace

}  // namespace artcal::cli
