// artcal verify (docs/models.md section 6): a (calibrated) machine on readings it has not seen.

#include <algorithm>
#include <cctype>
#include <iostream>
#include <string_view>

#include "artcal/calibration/verification.hpp"
#include "artcal/core/error.hpp"
#include "artcal/io/machine_covariance.hpp"
#include "artcal/io/machine_frames.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/plausibility.hpp"
#include "artcal/io/truth_io.hpp"
#include "artcal/report/station_report.hpp"
#include "artcal/report/verification_report.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {

struct VerifyArguments {
  std::string plan, machine;
  std::vector<std::string> frame_of;
  int outliers = 5;
  bool json = false;
};

/// `word` as a shell reads it back as one argument: as it is, or in single quotes (a placement
/// named "table day1").
std::string shellWord(const std::string& word) {
  const bool plain = !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) ||
           std::string_view("_-.,:/=+@%").find(c) != std::string_view::npos;
  });
  if (plain) return word;
  std::string quoted = "'";
  for (const char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

/// A plane placement the calibration's frames do not score, where the machine file holds a frame
/// of the same artifact: a table touched on two days under two names (docs/planes.md) is scored
/// in the calibration's frame only when asked; say how, with an option that is then taken (a
/// name with a space quoted; none where the names cannot be paired, a held name holding '=').
void hintFrameOf(const Plan& plan, const std::vector<CalibratedFrame>& calibrated,
                 const std::vector<std::optional<CalibrationFrame>>& frames,
                 const std::string& machine) {
  for (std::size_t j = 0; j < plan.placements.size() && j < frames.size(); ++j) {
    const Artifact& artifact =
        plan.artifacts[static_cast<std::size_t>(plan.placements[j].artifact)];
    if (frames[j] || !artifact.kind().touches_faces) continue;
    for (const CalibratedFrame& frame : calibrated) {
      if (frame.artifact != artifact.id) continue;
      const std::string pair = placementLabel(plan.placements, j) + "=" + frame.placement;
      try {
        framesForPlacements(plan, calibrated, std::vector<std::string>{pair}, machine);
      } catch (const InputError&) {
        break;
      }
      std::cerr << "note: placement " << placementLabel(plan.placements, j)
                << " is refitted only; if its plane stayed where the calibration's "
                << frame.placement << " was, also score it in that frame: --frame-of "
                << shellWord(pair) << "\n";
      break;
    }
  }
}

int runVerify(const VerifyArguments& args) {
  // The readings are checked against the machine verified or the nominal one
  // (io/plausibility.hpp): held-out readings 12 mm off the nominal machine may fit the calibrated
  // one, and a calibration that extrapolates badly is what verify is there to show.
  const bool calibrated = !args.machine.empty();
  Plan plan = parsePlan(readJsonFile(args.plan), args.plan, true, !calibrated);
  for (const std::string& warning : plan.warnings) std::cerr << "warning: " << warning << "\n";
  Eigen::VectorXd p = plan.machine.nominal;
  std::optional<ParameterUncertainty> uncertainty;
  VerifyOptions options;
  if (calibrated) {
    const nlohmann::json document = readJsonFile(args.machine);
    p = parseTruth(document, args.machine, plan);
    uncertainty = parseMachineCovariance(document, args.machine, plan);
    plan.noise = withEstimatedProbeNoise(plan.noise, uncertainty);
    checkPlausibilityOfVerified(plan, p, "the machine of " + args.machine);
    // The calibration's frames: a placement of the same name (or every placement of --frame-of's
    // artifact) is also scored in the frame the calibration estimated, not refitted.
    const std::vector<CalibratedFrame> calibrated =
        parseMachineFrames(document, args.machine, plan.machine.dimension());
    const auto frames = framesForPlacements(plan, calibrated, args.frame_of, args.machine);
    for (const auto& frame : frames) options.calibration_frames.push_back(frame);
    hintFrameOf(plan, calibrated, frames, args.machine);
  }
  // An instrument's stations (instruments.md): held-out readings against a fitted station.
  const StationsVerification stations =
      verifyStations(plan, p, uncertainty, options.calibration_frames);
  if (onlyStations(plan, stations)) {
    if (args.json) {
      printJson(verifyDocument(plan, stations, nullptr));
    } else {
      std::cout << "Plan " << plan.name << ": " << stations.stations.size()
                << " stations verified, parameters held fixed (mm)\n  predicted RMS from "
                << (uncertainty ? "the calibration's V_p and the reading noise"
                                : "the reading noise alone (no covariance given)")
                << "\n"
                << stationsVerificationTable(plan, stations);
    }
    return 0;
  }
  const Verification verification = verifyMachine(plan, p, uncertainty, options);
  // A calibrated machine is shown beside the plan's nominal one on the same readings.
  const std::optional<Verification> nominal = calibrated ? verifyNominal(plan) : std::nullopt;
  const Verification* beside = nominal ? &*nominal : nullptr;
  if (nominal) {
    for (const std::string& warning : besideNominalWarnings(verification, *nominal))
      std::cerr << "warning: " << warning << "\n";
  }
  if (args.json) {
    printJson(verifyDocument(plan, stations, &verification, beside));
  } else {
    std::cout << verificationTable(plan, verification, args.outliers, beside);
    if (!stations.stations.empty()) std::cout << stationsVerificationTable(plan, stations);
  }
  return 0;
}

void addVerifyCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<VerifyArguments>();
  CLI::App* cmd = app.add_subcommand(
      "verify",
      "tests a (calibrated) machine on the readings of PLAN with its parameters held fixed: per "
      "placement the spread of each feature's postures, the artifact's length errors and the "
      "residuals of the rigid fit, beside what the calibration's uncertainty predicts");
  cmd->add_option("PLAN", args->plan, "plan file with the (held-out) readings")->required();
  cmd->add_option("--machine", args->machine,
                  "machine file as `calibrate --write-machine` writes it (with its covariance); "
                  "default: the plan's own nominal machine");
  cmd->add_option("--frame-of", args->frame_of,
                  "also score every placement of this calibrated placement's artifact in the "
                  "frame the calibration estimated for it (the instrument or the artifact did not "
                  "move since); HELD=CALIBRATED (repeatable): placement HELD in the frame of "
                  "CALIBRATED; without it, a placement named as one of the calibration's is")
      ->needs("--machine")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--outliers", args->outliers,
                  "how many of the readings farthest from their feature's mean to list")
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "print one JSON document instead of the tables");
  cmd->callback([&action, args] { action = [args] { return runVerify(*args); }; });
}

const Registrar verify_registrar(65, "verify", addVerifyCommand);

}  // namespace

}  // namespace artcal::cli
