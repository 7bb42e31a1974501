// artcal acceptance (docs/method.md section 9): will the calibrated machine pass its acceptance
// test? ISO 10360-2 (Cartesian CMMs) and ISO 9283 (arms, robots) predicted from a plan's V_p or a
// calibrated machine file's covariance.

#include <cmath>
#include <iostream>
#include <sstream>

#include "artcal/acceptance/length_acceptance.hpp"
#include "artcal/acceptance/plan_acceptance.hpp"
#include "artcal/acceptance/pose_acceptance.hpp"
#include "artcal/core/units.hpp"
#include "artcal/io/acceptance_spec.hpp"
#include "artcal/io/output_file.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/report/acceptance_input.hpp"
#include "artcal/report/acceptance_report.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {

struct AcceptanceArguments {
  std::string file, plan, test, mpe, lines, center, svg, orientation, seed_posture;
  double cube = 0.0, stylus_offset = 0.0;
  std::optional<double> unmodelled;
  bool posterior = false;
  bool json = false;
  MonteCarloOptions monte_carlo;
};

/// What FILE and --plan give: the plan (noise, workspace) and the prediction's input.
struct LoadedInput {
  Plan plan;
  AcceptanceInput input;
  std::optional<AcceptanceSpec> spec;  ///< the plan's "acceptance" block
};

bool isPlanDocument(const nlohmann::json& document) {
  return document.is_object() && document.contains("format");
}

LoadedInput loadFromPlan(const std::string& path) {
  LoadedInput loaded{loadPlanReporting(path), {}, {}};
  loaded.spec = loaded.plan.acceptance;
  loaded.input = evaluatedAcceptanceInput(loaded.plan, path);
  return loaded;
}

LoadedInput loadFromMachine(const AcceptanceArguments& args, const nlohmann::json& document) {
  if (args.plan.empty())
    throw InputError(args.file, "",
                     "a machine file needs --plan PLAN, the plan it was calibrated from (its "
                     "noise and workspace)");
  LoadedInput loaded{loadPlanReporting(args.plan), {}, {}};
  loaded.spec = loaded.plan.acceptance;
  loaded.input = acceptanceInputFromMachineFile(document, args.file, loaded.plan, args.posterior);
  return loaded;
}

LoadedInput loadInput(const AcceptanceArguments& args) {
  const nlohmann::json document = readJsonFile(args.file);
  if (isPlanDocument(document)) {
    if (!args.plan.empty())
      throw InputError(args.file, "", "--plan goes with a machine file, not with a plan");
    if (args.posterior)
      throw InputError(args.file, "", "--posterior goes with a calibrated machine file");
    return loadFromPlan(args.file);
  }
  return loadFromMachine(args, document);
}

/// `--lines FILE`: a JSON list of unit directions.
std::vector<Eigen::Vector3d> loadLines(const std::string& path) {
  const nlohmann::json document = readJsonFile(path);
  if (!document.is_array() || document.empty())
    throw InputError(path, "", "expected a non-empty list of unit directions [x, y, z]");
  if (document.size() > kMaxTestLines)  // refused before the entries are read
    throw InputError(path, "",
                     std::to_string(document.size()) + " lines, more than " +
                         std::to_string(kMaxTestLines) +
                         ": the length test's work grows as the square of its lines; give at "
                         "most that many directions");
  std::vector<Eigen::Vector3d> lines;
  for (std::size_t i = 0; i < document.size(); ++i) {
    const nlohmann::json& entry = document[i];
    const std::string pointer = "/" + std::to_string(i);
    if (!entry.is_array() || entry.size() != 3)
      throw InputError(path, pointer, "expected 3 numbers (a unit direction)");
    Eigen::Vector3d u;
    for (int k = 0; k < 3; ++k) {
      if (!entry[static_cast<std::size_t>(k)].is_number())
        throw InputError(path, pointer + "/" + std::to_string(k), "expected a number");
      u[k] = entry[static_cast<std::size_t>(k)].get<double>();
    }
    if (!u.allFinite() || std::abs(u.norm() - 1.0) > 1e-6)
      throw InputError(path, pointer, "a line direction must be a unit vector (|u| = 1)");
    lines.push_back(u);
  }
  return lines;
}

Mpe parseMpeOption(const std::string& text) {
  std::string error;
  const auto mpe = parseMpe(text, &error);
  if (!mpe) throw InputError("--mpe", "", error);
  return *mpe;
}

/// "a,b,c,...": exactly `count` finite numbers separated by commas; InputError naming `option`
/// with `expected` (what to give) otherwise.
Eigen::VectorXd parseNumberList(const std::string& option, const std::string& text, int count,
                                const std::string& expected) {
  std::istringstream in(text);
  Eigen::VectorXd values(count);
  char comma = ',';
  for (int k = 0; k < count; ++k) {
    if ((k > 0 && !(in >> comma)) || comma != ',' || !(in >> values[k]))
      throw InputError(option, "", expected);
  }
  std::string rest;
  if (in >> rest || !values.allFinite()) throw InputError(option, "", expected);
  return values;
}

Eigen::Vector3d parseCenter(const std::string& text) {
  return parseNumberList("--center", text, 3, "expected X,Y,Z in mm, e.g. 500,0,400");
}

/// The ISO 9283 options the command line gives over the plan's block (`spec`, when its test is
/// iso9283): orientation, seed posture, unmodelled error (by default the one the calibration
/// estimated, carried in the machine file).
void takePoseSetUp(const AcceptanceArguments& args, const Machine& machine,
                   const std::optional<AcceptanceSpec>& spec, double calibration_unmodelled,
                   PoseTestOptions& options) {
  const bool from_plan = spec && spec->test == "iso9283";
  if (from_plan) options = poseTestOptionsFrom(*spec);
  if (!args.orientation.empty())
    options.orientation =
        parseNumberList("--orientation", args.orientation, 3,
                        "expected ROLL,PITCH,YAW in deg (the cube's axes), e.g. 0,0,30") *
        kDegree;
  if (!args.seed_posture.empty()) {
    const int n = machine.jointCount();
    options.seed_posture = jointsFromFile(
        *machine.mechanism,
        parseNumberList("--seed-posture", args.seed_posture, n,
                        "expected " + std::to_string(n) +
                            " joint values separated by commas (deg, mm), the arm's posture"));
    // As a reading of the plan: beyond the joint_limits it states, refused (docs/hardening.md).
    if (machine.limits_stated && !machine.withinLimits(*options.seed_posture))
      throw InputError("--seed-posture", "",
                       "the posture is outside the plan's joint_limits: check its values and "
                       "units (deg, mm)");
  }
  if (args.unmodelled) options.unmodelled = *args.unmodelled;
  // Neither the option nor the plan's block states it: the calibration's own estimate, by
  // cross-validation, from the machine file's covariance (unmodelled_error.hpp).
  else if (options.unmodelled == 0.0)
    options.unmodelled = calibration_unmodelled;
}

int runLengthTest(const AcceptanceArguments& args, const LoadedInput& loaded) {
  if (args.mpe.empty()) throw InputError("--mpe", "", "the length test needs --mpe \"A + L/K\"");
  LengthTestOptions options;
  options.mpe = parseMpeOption(args.mpe);
  if (!args.lines.empty()) options.lines = loadLines(args.lines);
  options.stylus_offset = args.stylus_offset;
  options.monte_carlo = args.monte_carlo;
  if (!args.svg.empty()) checkOutputPath(args.svg);
  const LengthTestPrediction prediction = predictLengthTest(loaded.input, options);
  if (!args.svg.empty()) writeOutputFile(args.svg, lengthTestSvg(prediction));
  for (const std::string& w : unseenParameterWarnings(loaded.input, prediction))
    std::cerr << "warning: " << w << "\n";  // table or JSON: stdout is the result alone
  if (args.json) {
    printJson(lengthTestToJson(loaded.input, prediction, args.monte_carlo));
  } else {
    std::cout << lengthTestTable(loaded.input, prediction, args.monte_carlo);
  }
  return 0;
}

int runPoseTest(const AcceptanceArguments& args, const LoadedInput& loaded) {
  if (!(args.cube > 0.0)) throw InputError("--cube", "", "the pose test needs --cube E (mm, > 0)");
  if (args.center.empty()) throw InputError("--center", "", "the pose test needs --center X,Y,Z");
  if (!args.svg.empty())
    throw InputError("--svg", "", "the E-against-L figure belongs to the length test");
  if (args.stylus_offset != 0.0)
    throw InputError("--stylus-offset", "", "the stylus offset (E150) belongs to the length test");
  PoseTestOptions options;
  takePoseSetUp(args, *loaded.input.machine, loaded.spec, loaded.input.uncertainty.unmodelled,
                options);
  options.cube = args.cube;
  options.center = parseCenter(args.center);
  if (!args.mpe.empty()) {
    std::istringstream in(args.mpe);
    double mpe = 0.0;
    std::string rest;
    if (!(in >> mpe) || (in >> rest) || !(mpe > 0.0) || !std::isfinite(mpe))
      throw InputError("--mpe", "", "the pose test's MPE is one number in mm (> 0)");
    options.mpe = mpe;
  }
  options.monte_carlo = args.monte_carlo;
  const PoseTestPrediction prediction = predictPoseTest(loaded.input, options);
  if (args.json) {
    printJson(poseTestToJson(loaded.input, prediction, options));
  } else {
    std::cout << poseTestTable(loaded.input, prediction, options);
  }
  return 0;
}

/// The command line's choices over the plan's "acceptance" block.
AcceptanceArguments withPlanDefaults(AcceptanceArguments args, const LoadedInput& loaded) {
  if (!loaded.spec) {
    if (args.test.empty())
      throw InputError(args.plan.empty() ? args.file : args.plan, "/acceptance",
                       "no test: give --test iso10360-2 or iso9283 (or an \"acceptance\" block "
                       "in the plan)");
    return args;
  }
  const AcceptanceSpec& spec = *loaded.spec;
  if (args.test.empty()) args.test = spec.test;
  if (args.test != spec.test) return args;  // another test than the plan's: nothing to take
  if (args.mpe.empty()) args.mpe = spec.mpe;
  if (!(args.cube > 0.0) && spec.cube) args.cube = *spec.cube;
  if (args.center.empty() && spec.center) {
    std::ostringstream center;
    center.precision(17);
    center << spec.center->x() << "," << spec.center->y() << "," << spec.center->z();
    args.center = center.str();
  }
  return args;
}

int runAcceptance(const AcceptanceArguments& given) {
  const LoadedInput loaded = loadInput(given);
  const AcceptanceArguments args = withPlanDefaults(given, loaded);
  if (args.test == "iso10360-2") return runLengthTest(args, loaded);
  return runPoseTest(args, loaded);
}

void addAcceptanceCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<AcceptanceArguments>();
  CLI::App* cmd = app.add_subcommand(
      "acceptance",
      "predicts the acceptance test of the calibrated machine: ISO 10360-2 (Cartesian CMMs: E0 "
      "against its MPE, P(pass)) or ISO 9283 (arms, robots: pose accuracy AP at the 5 points of "
      "the cube), from a plan's predicted V_p or a calibrated machine file's covariance");
  MonteCarloOptions& mc = args->monte_carlo;
  cmd->add_option("FILE", args->file,
                  "plan file, or a machine file as `calibrate --write-machine` writes it (then "
                  "--plan)")
      ->required();
  cmd->add_option("--plan", args->plan,
                  "with a machine file: the plan it was calibrated from (noise, workspace)");
  cmd->add_option("--test", args->test,
                  "iso10360-2 or iso9283 (default: the plan's \"acceptance\" block)")
      ->check(CLI::IsMember({"iso10360-2", "iso9283"}));
  cmd->add_option("--mpe", args->mpe,
                  "iso10360-2: \"A + L/K\" (A in um, L in mm); iso9283: X in mm (optional)");
  cmd->add_option("--lines", args->lines,
                  "iso10360-2: JSON file with a list of unit directions replacing the 7 lines");
  cmd->add_option("--stylus-offset", args->stylus_offset,
                  "iso10360-2: E150, the test with a stylus tip offset across the ram (mm, "
                  "e.g. 150): two positions instead of the 7 lines; --mpe is then E150's")
      ->check(nonNegativeNumber());
  cmd->add_option("--cube", args->cube, "iso9283: the cube's edge, mm");
  cmd->add_option("--center", args->center, "iso9283: the cube's centre X,Y,Z, mm (base frame)");
  cmd->add_option("--orientation", args->orientation,
                  "iso9283: the cube's orientation ROLL,PITCH,YAW, deg (R = Rz(yaw) Ry(pitch) "
                  "Rx(roll), its columns the cube's axes; default 0,0,0: along the base frame)");
  cmd->add_option("--seed-posture", args->seed_posture,
                  "iso9283: the arm's posture Q1,...,Qn (deg, mm) the inverse kinematics stays "
                  "near (default: the workspace sample nearest each point)");
  cmd->add_option("--unmodelled", args->unmodelled,
                  "iso9283: the error the model does not explain, standard deviation per "
                  "coordinate, mm (default 0)")
      ->check(nonNegativeNumber());
  cmd->add_option("--trials", mc.trials, "Monte-Carlo trials (0: adaptive, GUM S1 7.9)")
      ->check(CLI::Range(0L, 10000000L))
      ->capture_default_str();
  cmd->add_option("--seed", mc.seed, "random seed (same seed, same result, any thread count)")
      ->capture_default_str();
  cmd->add_option("--threads", mc.threads, "worker threads (0: all cores)")
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_flag("--posterior", args->posterior,
                "with a machine file: scale its covariance by its Birge ratio squared");
  cmd->add_option("--svg", args->svg, "iso10360-2: write the E-against-L figure (SVG) here");
  cmd->add_flag("--json", args->json, "print one JSON document instead of the tables");
  cmd->callback([&action, args] { action = [args] { return runAcceptance(*args); }; });
}

const Registrar acceptance_registrar(67, "acceptance", addAcceptanceCommand);

}  // namespace

}  // namespace artcal::cli
