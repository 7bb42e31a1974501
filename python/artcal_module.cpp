// artcal._native: the Python bindings of the artcal library (docs/python.md). Every result is the
// JSON document the command line prints with --json, built by the same library functions
// (report/, io/), handed to Python as dicts and lists; the package (python/artcal/__init__.py)
// adds the numpy views. Errors become artcal.InputError / artcal.RunError with the command line's
// one-line message ("FILE: POINTER: what to check").

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <string>

#include "artcal/acceptance/length_acceptance.hpp"
#include "artcal/acceptance/pose_acceptance.hpp"
#include "artcal/calibration/calibrate_readings.hpp"
#include "artcal/calibration/confirmation.hpp"
#include "artcal/calibration/simulation.hpp"
#include "artcal/calibration/verification.hpp"
#include "artcal/core/error.hpp"
#include "artcal/core/random.hpp"
#include "artcal/estimation/error_functions.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/io/acceptance_spec.hpp"
#include "artcal/io/calibrated_urdf.hpp"
#include "artcal/io/machine_covariance.hpp"
#include "artcal/io/machine_exports.hpp"
#include "artcal/io/machine_frames.hpp"
#include "artcal/io/output_file.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/plausibility.hpp"
#include "artcal/io/readings_import.hpp"
#include "artcal/io/truth_io.hpp"
#include "artcal/io/urdf.hpp"
#include "artcal/planning/optimizer.hpp"
#include "artcal/report/acceptance_input.hpp"
#include "artcal/report/acceptance_report.hpp"
#include "artcal/report/calibration_report.hpp"
#include "artcal/report/cartesian_report.hpp"
#include "artcal/report/report.hpp"
#include "artcal/report/verification_report.hpp"
#include "optimize_output.hpp"

namespace py = pybind11;
using nlohmann::json;

namespace artcal::python {

namespace {

// ------------------------------------------------------------------------------ JSON <-> Python

py::object toPython(const json& value) {
  switch (value.type()) {
    case json::value_t::null:
      return py::none();
    case json::value_t::boolean:
      return py::bool_(value.get<bool>());
    case json::value_t::number_integer:
      return py::int_(value.get<std::int64_t>());
    case json::value_t::number_unsigned:
      return py::int_(value.get<std::uint64_t>());
    case json::value_t::number_float:
      return py::float_(value.get<double>());
    case json::value_t::string:
      return py::str(value.get_ref<const std::string&>());
    case json::value_t::array: {
      py::list list(value.size());
      for (std::size_t i = 0; i < value.size(); ++i) list[i] = toPython(value[i]);
      return list;
    }
    case json::value_t::object: {
      py::dict dict;
      for (const auto& [key, item] : value.items()) dict[py::str(key)] = toPython(item);
      return dict;
    }
    default:
      return py::none();  // binary, discarded: never in artcal's documents
  }
}

/// A Python dict (the plan file's form) as JSON, through json.dumps: what it cannot encode
/// (a set, an object) raises TypeError naming it.
/// The JSON pointer of the first number of `object` that is not finite (NaN, inf), its text in
/// `value`; "" when every number is finite. JSON has no such numbers (docs/hardening.md).
std::string firstNonFinite(const py::handle& object, const std::string& pointer,
                           std::string& value) {
  if (py::isinstance<py::float_>(object)) {
    const double x = py::cast<double>(object);
    if (std::isfinite(x)) return "";
    value = py::cast<std::string>(py::repr(object));
    return pointer.empty() ? "/" : pointer;
  }
  if (py::isinstance<py::dict>(object)) {
    for (const auto& [key, item] : py::reinterpret_borrow<py::dict>(object)) {
      const std::string at =
          firstNonFinite(item, pointer + "/" + py::cast<std::string>(py::str(key)), value);
      if (!at.empty()) return at;
    }
  } else if (py::isinstance<py::list>(object) || py::isinstance<py::tuple>(object)) {
    std::size_t i = 0;
    for (const py::handle item : object) {
      const std::string at = firstNonFinite(item, pointer + "/" + std::to_string(i++), value);
      if (!at.empty()) return at;
    }
  }
  return "";
}

json fromPython(const py::handle& object, const std::string& source) {
  std::string value;
  if (const std::string at = firstNonFinite(object, "", value); !at.empty())
    throw InputError(source, at, "expected a finite number, got " + value);
  const py::object dumps = py::module_::import("json").attr("dumps");
  const std::string text = py::cast<std::string>(dumps(object, py::arg("allow_nan") = false));
  return parseJsonText(text, source);
}

// ------------------------------------------------------------------------------------- errors

/// The input of the call under way (its plan file, or the URDF): a library's own exception
/// (nlohmann::json, Eigen) is answered "INPUT: message" as the command line names its input.
std::string& currentInput() {
  static std::string input = "artcal";
  return input;
}

void noteInput(const std::string& input) {
  currentInput() = input.empty() ? "artcal" : input;
}

/// The command line's answers (tools/artcal.cpp) for the exceptions that are not LocatedError.
std::string withoutTag(const std::string& message) {
  if (!message.starts_with("[")) return message;
  const auto end = message.find("] ");
  return end == std::string::npos ? message : message.substr(end + 2);
}

// --------------------------------------------------------------------------------- the plan

/// A plan as the command line reads it: the parsed plan and the document it came from (simulate
/// and verify re-read the document as the commands do).
struct PyPlan {
  json document;
  std::string source;
  Plan plan;
};

std::shared_ptr<PyPlan> planFromDocument(json document, const std::string& source,
                                         bool require_placements) {
  auto out = std::make_shared<PyPlan>();
  out->plan = parsePlan(document, source, require_placements);
  out->document = std::move(document);
  out->source = source;
  return out;
}

std::shared_ptr<PyPlan> loadPlanFile(const std::string& path, bool require_placements) {
  noteInput(path);
  return planFromDocument(readJsonFile(path), path, require_placements);
}

std::shared_ptr<PyPlan> planFromDict(const py::handle& dict, const std::string& source,
                                     bool require_placements) {
  noteInput(source);
  return planFromDocument(fromPython(dict, source), source, require_placements);
}

/// Releases the GIL around `work` (a long computation of the library).
template <typename Work>
auto withoutGil(Work&& work) {
  py::gil_scoped_release release;
  return work();
}

/// A Python progress callback called from worker threads: the GIL taken for it, its first
/// exception kept and raised once the computation is over.
class ProgressRelay {
 public:
  explicit ProgressRelay(py::object callback) : callback_(std::move(callback)) {}
  ~ProgressRelay() {
    py::gil_scoped_acquire gil;
    callback_ = py::object();
    error_.reset();
  }
  bool active() const { return !callback_.is_none(); }
  template <typename... Args>
  void operator()(Args&&... args) {
    std::lock_guard<std::mutex> lock(mutex_);
    py::gil_scoped_acquire gil;
    if (error_) return;
    try {
      callback_(std::forward<Args>(args)...);
    } catch (py::error_already_set& e) {
      error_ = std::make_unique<py::error_already_set>(std::move(e));
    }
  }
  void raiseIfFailed() {
    if (error_) {
      py::error_already_set e = std::move(*error_);
      error_.reset();
      throw e;
    }
  }

 private:
  py::object callback_;
  std::mutex mutex_;
  std::unique_ptr<py::error_already_set> error_;
};

// ---------------------------------------------------------------------------- the commands

/// One placement's readings as read (inline or from CSV files): joints in file units (mm, deg)
/// per reading, each reading's feature, and its CSV file and row ("" and 0 when inline).
py::tuple readings(const PyPlan& p, long placement) {
  noteInput(p.source);
  const long count = static_cast<long>(p.plan.placements.size());
  if (placement < 0) placement += count;
  if (placement < 0 || placement >= count) throw py::index_error("placement index out of range");
  py::list joints, features, csv, rows;
  for (const Measurement& m : p.plan.placements[static_cast<std::size_t>(placement)].measurements) {
    joints.append(py::cast(jointsToFile(p.plan.machine, m.joints)));
    features.append(m.feature);
    csv.append(m.csv);
    rows.append(m.csv_row);
  }
  return py::make_tuple(joints, features, csv, rows);
}

json checkDocument(const PyPlan& p, double rank_tolerance) {
  noteInput(p.source);
  const Plan& plan = p.plan;
  const PlanInformation information = verdictInformation(plan, plan.placements);
  const Identifiability id =
      analyseIdentifiability(plan, plan.placements, information, rank_tolerance);
  json out = identifiabilityToJson(id);
  out.update(calibrateSelectionToJson(plan));
  out.update(cartesianAnswersToJson(plan, cartesianAnswers(plan, nullptr)));
  out["plan"] = plan.name;
  return out;
}

/// Values as a numpy array (copied).
py::array_t<double> toArray(const std::vector<double>& v) {
  py::array_t<double> out(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

/// The tip uncertainty S, S_m, S_q (mm) at each configuration of the evaluated workspace, and
/// the configurations (file units): the per-configuration values evaluate's summary is taken
/// from, as the evaluation carries them (not computed again).
py::dict tipPerConfiguration(const Plan& plan, const Evaluation& evaluation) {
  py::dict out;
  if (!evaluation.covariance || evaluation.workspace.empty()) return out;
  out["total"] = toArray(evaluation.workspace_total);
  out["kinematic"] = toArray(evaluation.workspace_kinematic);
  out["encoder"] = toArray(evaluation.workspace_encoder);
  const std::size_t n = evaluation.workspace.size();
  const std::size_t joints = static_cast<std::size_t>(evaluation.workspace.front().size());
  py::array_t<double> q({n, joints});
  auto view = q.mutable_unchecked<2>();
  for (std::size_t i = 0; i < n; ++i) {
    const std::vector<double> row = jointsToFile(plan.machine, evaluation.workspace[i]);
    for (std::size_t k = 0; k < joints; ++k)
      view(static_cast<py::ssize_t>(i), static_cast<py::ssize_t>(k)) = row[k];
  }
  out["joints"] = q;
  return out;
}

py::tuple evaluate(const PyPlan& p, double rank_tolerance, int profile_steps,
                   bool per_configuration) {
  noteInput(p.source);
  if (profile_steps < 2 || profile_steps > 10000)
    throw std::invalid_argument("--profile-steps: expected 2 to 10000");
  // As `artcal evaluate --json`: "estimate" evaluated with the noise the readings tell.
  const auto [noised, document] = withoutGil([&] {
    NoisedEvaluation ev = evaluateWithPredictionNoise(p.plan, {rank_tolerance, profile_steps});
    json out = evaluateCommandToJson(ev, cartesianAnswers(ev.plan, &ev.evaluation));
    return std::make_pair(std::move(ev), std::move(out));
  });
  const Plan& plan = noised.plan;
  const Evaluation& evaluation = noised.evaluation;
  py::object covariance = py::none();
  if (evaluation.covariance)
    covariance = toPython(covarianceToJson(plan.machine, evaluation.covariance->V, 0.0));
  py::object tip = per_configuration ? py::object(tipPerConfiguration(plan, evaluation))
                                     : py::object(py::none());
  return py::make_tuple(toPython(document), covariance, tip);
}

/// The prepared evaluation of a plan's placements (estimation/evaluator.hpp's PlanEvaluator):
/// the cost the optimizer pays per candidate design.
class PyEvaluator {
 public:
  explicit PyEvaluator(std::shared_ptr<PyPlan> plan)
      : plan_(std::move(plan)), evaluator_(plan_->plan) {}
  py::object tip() {
    const std::optional<TipSummary> tip = evaluator_.tip(plan_->plan.placements);
    if (!tip) return py::none();
    return py::make_tuple(tip->worst.total, tip->mean, tip->rms);
  }

 private:
  std::shared_ptr<PyPlan> plan_;
  PlanEvaluator evaluator_;
};

py::tuple calibrate(const PyPlan& p, int max_iterations, double step_tolerance,
                    double flag_threshold, double gross_threshold) {
  noteInput(p.source);
  CalibrationOptions options;
  options.max_iterations = max_iterations;
  options.step_tolerance = step_tolerance;
  options.flag_threshold = flag_threshold;
  options.gross_threshold = gross_threshold;
  std::string error;
  if (!options.isValid(&error)) throw std::invalid_argument("calibrate: " + error);
  const auto [document, machine] = withoutGil([&] {
    // The plan as calibrated (the kept set, the noise used); p.plan itself is not changed.
    const CalibrationRun run = calibrateReadings(p.plan, options);
    const Plan& plan = run.decided;
    const Calibration& calibration = run.calibration;
    if (calibration.dof < 0) {  // fewer equations than unknowns: check's answer, nothing estimated
      json answer = checkDocument(p, kDefaultRankTolerance);
      answer["converged"] = false;
      answer["dof"] = calibration.dof;
      return std::make_pair(std::move(answer), json());
    }
    json result = calibrationToJson(plan, plan.placements, calibration);
    json machine_block;
    if (calibration.summary.converged()) {
      machine_block = machineToJson(plan.machine, calibration.parameters);
      if (const auto uncertainty = calibration.uncertainty(plan.machine))
        machine_block["covariance"] = covarianceToJson(plan.machine, *uncertainty);
      machine_block["frames"] = framesToJson(plan, calibration.poses);  // as --write-machine
    }
    return std::make_pair(std::move(result), std::move(machine_block));
  });
  return py::make_tuple(toPython(document), toPython(machine));
}

/// A machine given as a file's path (str or os.PathLike) or as its dict (`calibrate().machine`):
/// its document and the name errors give it.
std::pair<json, std::string> machineDocument(const py::object& machine,
                                             const std::string& dict_source) {
  if (py::isinstance<py::str>(machine) ||
      py::isinstance(machine, py::module_::import("os").attr("PathLike"))) {
    const std::string path = py::cast<std::string>(py::str(machine));
    return {readJsonFile(path), path};
  }
  return {fromPython(machine, dict_source), dict_source};
}

json verify(const PyPlan& p, const py::object& machine, const std::string& machine_source) {
  noteInput(p.source);
  // As `artcal verify` (tools/cmd_verify.cpp): the readings checked against the machine verified.
  const bool calibrated = !machine.is_none();
  Plan plan = parsePlan(p.document, p.source, true, !calibrated);
  Eigen::VectorXd parameters = plan.machine.nominal;
  std::optional<ParameterUncertainty> uncertainty;
  VerifyOptions options;
  if (calibrated) {
    const auto [document, source] = machineDocument(machine, machine_source);
    parameters = parseTruth(document, source, plan);
    uncertainty = parseMachineCovariance(document, source, plan);
    plan.noise = withEstimatedProbeNoise(plan.noise, uncertainty);
    checkPlausibilityOfVerified(plan, parameters, "the machine of " + source);
    // As the command: placements named as the calibration's are also scored in its frames.
    options.calibration_frames = framesForPlacements(
        plan, parseMachineFrames(document, source, plan.machine.dimension()), "", source);
  }
  // As the command: a plan of instrument stations alone gets the stations' figures only.
  return withoutGil([&] {
    const StationsVerification stations =
        verifyStations(plan, parameters, uncertainty, options.calibration_frames);
    if (onlyStations(plan, stations)) return verifyDocument(plan, stations, nullptr);
    const Verification verification = verifyMachine(plan, parameters, uncertainty, options);
    const std::optional<Verification> nominal =
        calibrated ? verifyNominal(plan) : std::optional<Verification>();
    return verifyDocument(plan, stations, &verification, nominal ? &*nominal : nullptr);
  });
}

json simulate(const PyPlan& p, const py::object& truth, std::uint64_t seed, double noise_scale,
              bool artifact_errors) {
  noteInput(p.source);
  const Plan& plan = p.plan;
  const Eigen::VectorXd true_parameters =
      py::isinstance<py::str>(truth) ? loadTruth(py::cast<std::string>(truth), plan)
                                     : parseTruth(fromPython(truth, "truth"), "truth", plan);
  SimulationOptions options;
  options.noise_scale = noise_scale;
  options.artifact_errors = artifact_errors;
  std::string error;
  if (!options.isValid(&error)) throw std::invalid_argument("simulate: " + error);
  return withoutGil([&] {
    const Simulator simulator(plan, options);
    NormalSource normal(seed);
    const SimulatedRun run = simulator.simulate(true_parameters, normal);
    Plan simulated = plan;
    simulated.placements = run.placements;
    json document = p.document;
    document["placements"] = placementsToJson(simulated);
    json record = truthToJson(plan.machine, true_parameters);
    record["seed"] = seed;
    record["noise_scale"] = noise_scale;
    record["artifact_errors"] =
        std::vector<double>(run.systematic.data(), run.systematic.data() + run.systematic.size());
    document["simulation"] = record;
    return document;
  });
}

json confirm(const PyPlan& p, ConfirmationOptions options, const py::object& progress) {
  noteInput(p.source);
  std::string error;
  if (!options.isValid(&error)) throw std::invalid_argument("confirm: " + error);
  auto relay = std::make_shared<ProgressRelay>(progress);
  if (relay->active()) options.progress = [relay](int done, int total) { (*relay)(done, total); };
  json out = withoutGil([&] {
    const Confirmation confirmation = confirmPlan(p.plan, options);
    return confirmationToJson(p.plan, options, confirmation);
  });
  relay->raiseIfFailed();
  return out;
}

/// The command line's optimize options (`--starts`, `--seed`, ...): unset ones keep the spec's
/// design block.
struct OptimizeKnobs {
  std::optional<int> starts, pool, evaluations, polish, kicks;
  std::optional<std::uint64_t> seed;
  std::optional<double> time_limit;
  std::string algorithm = "sbplx";
  int threads = 0;
};

OptimizerOptions optimizerOptions(const PyPlan& p, const OptimizeKnobs& knobs) {
  if (!p.plan.design)
    throw InputError(p.source, "/design", "missing: an optimization spec needs a design block");
  OptimizerOptions options = OptimizerOptions::fromDesign(*p.plan.design);
  if (knobs.starts) options.starts = *knobs.starts;
  if (knobs.seed) options.seed = *knobs.seed;
  if (knobs.time_limit) options.time_limit = *knobs.time_limit;
  if (knobs.pool && *knobs.pool > 0) options.pool_size = *knobs.pool;
  if (knobs.evaluations && *knobs.evaluations > 0) options.refine_evaluations = *knobs.evaluations;
  if (knobs.polish) options.polish = *knobs.polish;
  if (knobs.kicks) options.kicks = *knobs.kicks;
  const auto algorithm = refineAlgorithmFromName(knobs.algorithm);
  if (!algorithm)
    throw std::invalid_argument("--algorithm: " + knobs.algorithm +
                                " not in {sbplx, bobyqa, neldermead, cobyla, none}");
  options.algorithm = *algorithm;
  options.threads = knobs.threads;
  return options;
}

/// `artcal optimize SPEC -o PLAN`: the plan written (tools/cmd_optimize.cpp, the same library
/// functions: tools/optimize_output.hpp).
json optimize(const PyPlan& p, const OptimizeKnobs& knobs, const py::object& progress) {
  noteInput(p.source);
  OptimizerOptions options = optimizerOptions(p, knobs);
  auto relay = std::make_shared<ProgressRelay>(progress);
  if (relay->active()) {
    options.progress = [relay](const OptimizerProgress& s) {
      (*relay)(s.starts_done, s.starts, s.best, s.elapsed);
    };
  }
  json document = withoutGil([&]() -> json {
    Plan spec = p.plan;
    const int resolved_on = resolveOnDesigns(spec, options.seed);
    const OptimizerSummary summary = optimizePlan(spec, options);
    return optimizedPlan(p.document, spec, p.source, options, summary, resolved_on).document;
  });
  relay->raiseIfFailed();
  return document;
}

/// `artcal optimize SPEC --placements A..B -o DIR`: the plans and the summary written into
/// `directory`; returns the summary document (what --json prints) and the plans' files.
py::tuple optimizeSweep(const PyPlan& p, const OptimizeKnobs& knobs, const std::string& range,
                        std::optional<double> target, const std::string& directory,
                        const py::object& progress) {
  noteInput(p.source);
  const OptimizerOptions options = optimizerOptions(p, knobs);
  if (target && !(*target > 0.0 && std::isfinite(*target)))
    throw std::invalid_argument("--target-tip: expected a positive number (mm)");
  auto relay = std::make_shared<ProgressRelay>(progress);
  std::function<void(int, double)> on_count;
  if (relay->active()) on_count = [relay](int m, double value) { (*relay)(m, value); };
  const PlacementSweepOutput out = withoutGil([&] {
    Plan spec = p.plan;
    resolveOnDesigns(spec, options.seed);
    return placementSweepOutput(p.document, spec, options, range, target, directory, on_count);
  });
  relay->raiseIfFailed();
  createOutputDirectory(directory);
  writeOutputFiles(out.files);
  py::list plans;
  for (std::size_t i = 0; i + 3 < out.files.size(); ++i) plans.append(out.files[i].first);
  return py::make_tuple(toPython(out.summary), plans);
}

/// The prediction's input: the plan's own V_p, or the calibrated `machine` (a file's path or its
/// dict) on this plan (`artcal acceptance MACHINE --plan PLAN [--posterior]`).
AcceptanceInput acceptanceInput(const PyPlan& p, const py::object& machine, bool posterior) {
  if (machine.is_none()) {
    if (posterior)
      throw InputError(p.source, "", "--posterior goes with a calibrated machine file");
    return evaluatedAcceptanceInput(p.plan, p.source);
  }
  const auto [document, source] = machineDocument(machine, "machine");
  return acceptanceInputFromMachineFile(document, source, p.plan, posterior);
}

json acceptanceLength(const PyPlan& p, const std::string& mpe, const MonteCarloOptions& mc,
                      const py::object& machine, bool posterior, double stylus_offset) {
  noteInput(p.source);
  LengthTestOptions options;
  std::string error;
  const auto parsed = parseMpe(mpe, &error);
  if (!parsed) throw InputError("--mpe", "", error);
  options.mpe = *parsed;
  options.stylus_offset = stylus_offset;  // checked by the prediction (finite, >= 0)
  options.monte_carlo = mc;
  std::optional<AcceptanceInput> input;  // a machine's: read with the GIL (Python objects)
  if (!machine.is_none() || posterior) input = acceptanceInput(p, machine, posterior);
  return withoutGil([&] {
    if (!input) input = evaluatedAcceptanceInput(p.plan, p.source);
    return lengthTestToJson(*input, predictLengthTest(*input, options), mc);
  });
}

json acceptancePose(const PyPlan& p, double cube, const std::array<double, 3>& center,
                    std::optional<double> mpe, const MonteCarloOptions& mc,
                    const py::object& machine, bool posterior) {
  noteInput(p.source);
  if (!(cube > 0.0) || !std::isfinite(cube))
    throw InputError("--cube", "", "the pose test needs --cube E (mm, > 0, finite)");
  PoseTestOptions options;
  options.cube = cube;
  options.center = Eigen::Vector3d(center[0], center[1], center[2]);
  if (!options.center.allFinite())
    throw InputError("--center", "", "expected X,Y,Z in mm, e.g. 500,0,400");
  if (mpe && !(*mpe > 0.0 && std::isfinite(*mpe)))
    throw InputError("--mpe", "", "the pose test's MPE is one number in mm (> 0)");
  options.mpe = mpe;
  options.monte_carlo = mc;
  std::optional<AcceptanceInput> input;  // a machine's: read with the GIL (Python objects)
  if (!machine.is_none() || posterior) input = acceptanceInput(p, machine, posterior);
  return withoutGil([&] {
    if (!input) input = evaluatedAcceptanceInput(p.plan, p.source);
    return poseTestToJson(*input, predictPoseTest(*input, options), options);
  });
}

MonteCarloOptions monteCarlo(long trials, std::uint64_t seed, int threads) {
  MonteCarloOptions mc;
  if (trials < 0) throw std::invalid_argument("--trials: expected 0 (adaptive) or more");
  mc.trials = trials;
  mc.seed = seed;
  mc.threads = threads;
  return mc;
}

/// `artcal import-readings DIR ...`: the plan document and its source name, with the warnings
/// of the import and of reading the plan (the command's checks, tools/cmd_import_readings.cpp).
std::shared_ptr<PyPlan> importReadingsPlan(ReadingsImport import, const py::object& probe) {
  noteInput(import.inputs.empty() ? import.folder : import.inputs.front());
  if (import.machine_file.empty() && import.urdf.empty())
    throw std::invalid_argument("import-readings: needs --machine or --urdf");
  if (!import.machine_file.empty() && !import.urdf.empty())
    throw std::invalid_argument("import-readings: --machine excludes --urdf");
  if (!import.urdf.empty() && (import.base.empty() || (import.tip.empty() && import.tips.empty())))
    throw std::invalid_argument("import-readings: --urdf needs --base and --tip");
  if (!import.ball_bar && import.artifact_file.empty() && !import.instrument)
    throw std::invalid_argument("import-readings: needs --ball-bar, --artifact or --instrument");
  if (import.instrument && (import.ball_bar || !import.artifact_file.empty()))
    throw std::invalid_argument("import-readings: --instrument excludes --ball-bar and --artifact");
  if (import.instrument && !(*import.instrument > 0.0 && std::isfinite(*import.instrument)))
    throw std::invalid_argument("import-readings: --instrument: expected a noise > 0 (mm)");
  if (!import.point_unit.empty() && import.point_unit != "mm" && import.point_unit != "m")
    throw std::invalid_argument("import-readings: --point-unit: expected mm or m");
  if (import.instrument_angle && !import.instrument)
    throw std::invalid_argument("import-readings: --instrument-angle requires --instrument");
  if (import.instrument_angle &&
      !(*import.instrument_angle > 0.0 && std::isfinite(*import.instrument_angle)))
    throw std::invalid_argument("import-readings: --instrument-angle: expected a noise > 0 (deg)");
  if (!import.orientation_unit.empty() && import.orientation_unit != "deg" &&
      import.orientation_unit != "rad")
    throw std::invalid_argument("import-readings: --orientation-unit: expected deg or rad");
  if (!import.orientation.empty() && import.orientation != "rotation_vector" &&
      import.orientation != "rpy" && import.orientation != "quaternion")
    throw std::invalid_argument(
        "import-readings: --orientation: expected rotation_vector, rpy or quaternion");
  for (const auto& [joint, value] : import.holds) {
    if (!std::isfinite(value))
      throw std::invalid_argument("import-readings: --hold " + joint + ": expected a finite value");
  }
  if (import.ball_bar && !import.artifact_file.empty())
    throw std::invalid_argument("import-readings: --ball-bar excludes --artifact");
  if (import.ball_bar && !(*import.ball_bar > 0.0 && std::isfinite(*import.ball_bar)))
    throw std::invalid_argument("import-readings: --ball-bar: expected a length > 0 (mm)");
  if (!(import.u_length >= 0.0) || !(import.encoder >= 0.0))
    throw std::invalid_argument("import-readings: --u-length and --encoder: expected >= 0");
  if (!import.output.empty()) checkOutputPath(import.output);
  import.probe = fromPython(probe, "--probe");
  const ImportedPlan imported = withoutGil([&] { return importReadings(import); });
  auto out = std::make_shared<PyPlan>();
  out->plan = parsePlan(imported.plan, imported.source, true, /*check_plausibility=*/false);
  out->plan.warnings.insert(out->plan.warnings.begin(), imported.warnings.begin(),
                            imported.warnings.end());
  out->document = imported.plan;
  out->source = imported.source;
  if (!import.output.empty()) writeOutputFile(import.output, out->document.dump(1) + "\n");
  return out;
}

/// `artcal export-urdf --machine M --urdf U [-o OUT]`: the URDF text and the warnings.
py::tuple exportCalibratedUrdf(const py::object& machine, const std::string& urdf,
                               const std::string& output) {
  noteInput(urdf);
  if (!output.empty()) checkOutputPath(output);
  const auto [document, source] = machineDocument(machine, "machine");
  const CalibratedUrdf exported = calibratedUrdf(document, source, urdf);
  if (!output.empty()) writeOutputFile(output, exported.text);
  return py::make_tuple(exported.text, exported.warnings);
}

/// `artcal export-xacro` ("xacro", `urdf`), `export-ur` ("ur"), `export-linuxcnc` ("linuxcnc",
/// `pivot`) [-o OUT] (docs/exports.md): the file's text, its summary and its warnings.
py::tuple exportMachine(const std::string& format, const py::object& machine,
                        const std::string& urdf, const std::vector<double>& pivot,
                        const std::string& output) {
  if (!urdf.empty()) noteInput(urdf);
  if (!output.empty()) checkOutputPath(output);
  const auto [document, source] = machineDocument(machine, "machine");
  std::string text;
  json summary;
  std::vector<std::string> warnings;
  if (format == "xacro") {
    const XacroProperties x = calibratedXacro(document, source, urdf);
    text = x.text;
    summary = x.summary;
    warnings = x.warnings;
  } else {
    const MachineFile file = readMachineFile(document, source);
    if (format == "linuxcnc" && pivot.size() != 3)
      throw InputError("pivot", "", "expected 3 numbers (mm)");
    const MachineExport e = format == "ur" ? urKinematicsExport(file)
                                           : linuxcncExport(file, Eigen::Vector3d(pivot.data()));
    text = e.text;
    summary = e.summary;
  }
  if (!output.empty()) writeOutputFile(output, text);
  return py::make_tuple(text, toPython(summary), warnings);
}

// ------------------------------------------------------------------------------ the module

void registerExceptions(py::module_& m) {
  static py::exception<LocatedError> base(m, "Error", PyExc_ValueError);
  static py::exception<InputError> input(m, "InputError", base.ptr());
  static py::exception<RunError> run(m, "RunError", base.ptr());
  // The command line's one line (tools/artcal.cpp), without "error: ".
  py::register_exception_translator([](std::exception_ptr thrown) {
    try {
      if (thrown) std::rethrow_exception(thrown);
    } catch (const InputError& e) {
      input(e.describe().c_str());
    } catch (const RunError& e) {
      run(e.describe().c_str());
    } catch (const std::bad_alloc&) {
      PyErr_SetString(PyExc_MemoryError,
                      "not enough memory for this input (make it smaller, or run on a machine "
                      "with more memory)");
    } catch (const std::filesystem::filesystem_error& e) {
      const std::string file = e.path1().empty() ? currentInput() : e.path1().string();
      input((file + ": " + e.code().message()).c_str());
    } catch (const std::invalid_argument& e) {
      input(e.what());
    } catch (const py::builtin_exception&) {
      throw;
    } catch (const py::error_already_set&) {
      throw;
    } catch (const std::exception& e) {  // a library's (nlohmann::json, Eigen, ...)
      input((currentInput() + ": " + withoutTag(e.what())).c_str());
    }
  });
}

ConfirmationOptions confirmationOptions(int trials, std::uint64_t seed, int threads,
                                        double noise_scale, double perturbation, double level,
                                        double allowance) {
  ConfirmationOptions options;
  options.trials = trials;
  options.seed = seed;
  options.threads = threads;
  options.noise_scale = noise_scale;
  options.perturbation = perturbation;
  options.level = level;
  options.allowance = allowance;
  return options;
}

void definePlan(py::module_& m) {
  py::class_<PyPlan, std::shared_ptr<PyPlan>>(m, "_Plan")
      .def_property_readonly("name", [](const PyPlan& p) { return p.plan.name; })
      .def_property_readonly("source", [](const PyPlan& p) { return p.source; })
      .def_property_readonly("warnings", [](const PyPlan& p) { return p.plan.warnings; })
      .def("document", [](const PyPlan& p) { return toPython(p.document); })
      .def("placement_count", [](const PyPlan& p) { return p.plan.placements.size(); })
      .def("readings", &readings, py::arg("placement"))
      .def(
          "check", [](const PyPlan& p, double tol) { return toPython(checkDocument(p, tol)); },
          py::arg("rank_tol") = kDefaultRankTolerance)
      .def("evaluate", &evaluate, py::arg("rank_tol") = kDefaultRankTolerance,
           py::arg("profile_steps") = 21, py::arg("per_configuration") = true)
      .def("calibrate", &calibrate, py::arg("max_iterations"), py::arg("step_tol"),
           py::arg("flag_threshold"), py::arg("gross_threshold"))
      .def(
          "verify",
          [](const PyPlan& p, const py::object& machine) {
            return toPython(verify(p, machine, "machine"));
          },
          py::arg("machine") = py::none())
      .def(
          "simulate",
          [](const PyPlan& p, const py::object& truth, std::uint64_t seed, double noise_scale,
             bool artifact_errors) {
            return toPython(simulate(p, truth, seed, noise_scale, artifact_errors));
          },
          py::arg("truth"), py::arg("seed"), py::arg("noise_scale"), py::arg("artifact_errors"))
      .def(
          "confirm",
          [](const PyPlan& p, int trials, std::uint64_t seed, int threads, double noise_scale,
             double perturbation, double level, double allowance, const py::object& progress) {
            return toPython(confirm(p,
                                    confirmationOptions(trials, seed, threads, noise_scale,
                                                        perturbation, level, allowance),
                                    progress));
          },
          py::arg("trials"), py::arg("seed"), py::arg("threads"), py::arg("noise_scale"),
          py::arg("perturbation"), py::arg("level"), py::arg("allowance"),
          py::arg("progress") = py::none())
      .def(
          "optimize",
          [](const PyPlan& p, const OptimizeKnobs& knobs, const py::object& progress) {
            return toPython(optimize(p, knobs, progress));
          },
          py::arg("knobs"), py::arg("progress") = py::none())
      .def(
          "optimize_sweep",
          [](const PyPlan& p, const OptimizeKnobs& knobs, const std::string& range,
             std::optional<double> target, const std::string& directory,
             const py::object& progress) {
            return optimizeSweep(p, knobs, range, target, directory, progress);
          },
          py::arg("knobs"), py::arg("range"), py::arg("target"), py::arg("directory"),
          py::arg("progress") = py::none())
      .def(
          "acceptance_length",
          [](const PyPlan& p, const std::string& mpe, long trials, std::uint64_t seed, int threads,
             const py::object& machine, bool posterior, double stylus_offset) {
            return toPython(acceptanceLength(p, mpe, monteCarlo(trials, seed, threads), machine,
                                             posterior, stylus_offset));
          },
          py::arg("mpe"), py::arg("trials"), py::arg("seed"), py::arg("threads"),
          py::arg("machine"), py::arg("posterior"), py::arg("stylus_offset"))
      .def(
          "acceptance_pose",
          [](const PyPlan& p, double cube, const std::array<double, 3>& center,
             std::optional<double> mpe, long trials, std::uint64_t seed, int threads,
             const py::object& machine, bool posterior) {
            return toPython(acceptancePose(p, cube, center, mpe, monteCarlo(trials, seed, threads),
                                           machine, posterior));
          },
          py::arg("cube"), py::arg("center"), py::arg("mpe"), py::arg("trials"), py::arg("seed"),
          py::arg("threads"), py::arg("machine"), py::arg("posterior"));
}

}  // namespace

}  // namespace artcal::python

PYBIND11_MODULE(_native, m) {
  using namespace artcal::python;
  m.doc() = "artcal's C++ core; use the artcal package (docs/python.md)";
  registerExceptions(m);
  definePlan(m);
  m.def("load_plan", &loadPlanFile, py::arg("path"), py::arg("require_placements") = true);
  m.def("plan_from_dict", &planFromDict, py::arg("document"), py::arg("source"),
        py::arg("require_placements") = true);
  m.def(
      "import_urdf",
      [](const std::string& path, const std::string& base, const std::vector<std::string>& tips) {
        artcal::python::noteInput(path);
        return toPython(artcal::importUrdf(path, base, tips));
      },
      py::arg("path"), py::arg("base"), py::arg("tip"));
  py::class_<OptimizeKnobs>(m, "_OptimizeKnobs")
      .def(py::init<>())
      .def_readwrite("starts", &OptimizeKnobs::starts)
      .def_readwrite("seed", &OptimizeKnobs::seed)
      .def_readwrite("time_limit", &OptimizeKnobs::time_limit)
      .def_readwrite("threads", &OptimizeKnobs::threads)
      .def_readwrite("pool", &OptimizeKnobs::pool)
      .def_readwrite("evaluations", &OptimizeKnobs::evaluations)
      .def_readwrite("polish", &OptimizeKnobs::polish)
      .def_readwrite("kicks", &OptimizeKnobs::kicks)
      .def_readwrite("algorithm", &OptimizeKnobs::algorithm);
  m.def(
      "import_readings",
      [](const std::string& folder, const std::string& machine, const std::string& urdf,
         const std::string& base, const std::string& tip, std::optional<double> ball_bar,
         double u_length, const std::string& artifact, const py::object& probe, double encoder,
         const std::string& unit, bool keep_calibrate, bool keep_limits, const std::string& output,
         std::optional<double> instrument, const std::string& point_unit,
         std::optional<double> instrument_angle, const std::string& orientation_unit,
         const std::vector<std::string>& marker, const std::string& orientation,
         const std::map<std::string, double>& hold, const std::vector<std::string>& files,
         const std::vector<std::string>& tips, const std::map<std::string, std::string>& tip_of,
         std::optional<std::pair<double, double>> prior) {
        artcal::ReadingsImport import;
        import.folder = folder;
        import.inputs = files;
        if (tips.size() > 1) import.tips = tips;
        for (const auto& [placement, name] : tip_of) import.tip_of.emplace_back(placement, name);
        if (prior) {  // checked with the command line's (importReadings)
          import.prior_length = prior->first;
          import.prior_angle = prior->second;
        }
        import.machine_file = machine;
        import.urdf = urdf;
        import.base = base;
        import.tip = tip;
        import.ball_bar = ball_bar;
        import.u_length = u_length;
        import.artifact_file = artifact;
        import.encoder = encoder;
        import.unit = unit;
        import.keep_calibrate = keep_calibrate;
        import.keep_limits = keep_limits;
        import.output = output;
        import.instrument = instrument;
        import.point_unit = point_unit;
        import.instrument_angle = instrument_angle;
        import.orientation_unit = orientation_unit;
        import.markers = marker;
        import.orientation = orientation;
        for (const auto& [joint, value] : hold) import.holds.emplace_back(joint, value);
        return importReadingsPlan(std::move(import), probe);
      },
      py::arg("folder"), py::arg("machine"), py::arg("urdf"), py::arg("base"), py::arg("tip"),
      py::arg("ball_bar"), py::arg("u_length"), py::arg("artifact"), py::arg("probe"),
      py::arg("encoder"), py::arg("unit"), py::arg("keep_calibrate"), py::arg("keep_limits"),
      py::arg("output"), py::arg("instrument"), py::arg("point_unit"), py::arg("instrument_angle"),
      py::arg("orientation_unit"), py::arg("marker"), py::arg("orientation"), py::arg("hold"),
      py::arg("files"), py::arg("tips"), py::arg("tip_of"), py::arg("prior"));
  m.def("export_urdf", &exportCalibratedUrdf, py::arg("machine"), py::arg("urdf"),
        py::arg("output"));
  m.def("export_machine", &exportMachine, py::arg("format"), py::arg("machine"), py::arg("urdf"),
        py::arg("pivot"), py::arg("output"));
  py::class_<PyEvaluator>(m, "_Evaluator")
      .def(py::init<std::shared_ptr<PyPlan>>(), py::keep_alive<1, 2>())
      .def("tip", &PyEvaluator::tip);
}
