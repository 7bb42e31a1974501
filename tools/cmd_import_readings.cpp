// artcal import-readings DIR: a plan from a folder of CSV readings and a machine
// (docs/plan-format.md, "A plan from a folder of CSV files"; docs/calibrate-your-robot.md).

#include <cmath>
#include <iostream>

#include "artcal/core/assignment.hpp"
#include "artcal/core/error.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/readings_import.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {

struct ImportReadingsArguments {
  ReadingsImport import;
  std::vector<std::string> holds;   ///< JOINT=VALUE
  std::vector<std::string> tip_of;  ///< PLACEMENT=TIP
  std::string prior;                ///< LENGTH,ANGLE
  std::string probe = "0.1";
  std::string output = kStandardOutput;
};

/// --probe: a decimal number (mm), or a word the plan format knows ("estimate") passed on as it
/// is; hexadecimal, inf and nan are refused (numbers in options are decimal numbers only).
nlohmann::json probeValue(const std::string& text) {
  if (const auto value = decimalNumber(text)) return *value;
  const std::string number_like = "0123456789+-.";
  if (text.empty() || number_like.find(text.front()) != std::string::npos || text == "inf" ||
      text == "nan" || text == "infinity") {
    throw InputError("--probe", text, "expected a decimal number (mm) or \"estimate\"");
  }
  return text;
}

void addImportReadingsCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<ImportReadingsArguments>();
  ReadingsImport& in = args->import;
  CLI::App* cmd = app.add_subcommand(
      "import-readings",
      "a plan from a folder of CSV readings (one sub-folder per placement, one file per feature) "
      "and a machine or URDF");
  cmd->add_option("DIR", in.inputs,
                  "folder of placement sub-folders (hole_<k>.csv, feature_<k>.csv), or CSV files "
                  "of one placement each (a plane's touches, named after the file)")
      ->required();
  auto* machine = cmd->add_option("--machine", in.machine_file, "machine file (import-urdf -o)");
  auto* urdf =
      cmd->add_option("--urdf", in.urdf, "robot description (URDF), with --base and --tip");
  machine->excludes(urdf);
  cmd->add_option("--base", in.base, "URDF link the chain starts from")->needs(urdf);
  cmd->add_option("--tip", in.tips,
                  "URDF link whose origin is the probe centre; repeated: one machine with several "
                  "tips (then --tip-of says which touched in each placement)")
      ->needs(urdf)
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--tip-of", args->tip_of,
                  "PLACEMENT=TIP: the tip that touched in this placement (a folder's or a file's "
                  "name), for a machine with several tips; repeat for each placement")
      ->type_name("PLACEMENT=TIP");
  auto* bar =
      cmd->add_option("--ball-bar", in.ball_bar, "the artifact: a ball bar of this length, mm")
          ->check(positiveNumber());
  cmd->add_option("--u-length", in.u_length, "standard uncertainty of the bar's length, mm")
      ->check(nonNegativeNumber())
      ->needs(bar);
  auto* artifact =
      cmd->add_option("--artifact", in.artifact_file,
                      "the artifact: a file with an artifacts block {\"id\": {\"type\": ...}}");
  bar->excludes(artifact);
  auto* instrument =
      cmd->add_option("--instrument", in.instrument,
                      "the artifact: a laser tracker or total station of this noise, mm per "
                      "coordinate; DIR holds one CSV per station (joints, then x, y, z)")
          ->check(positiveNumber());
  instrument->excludes(bar);
  instrument->excludes(artifact);
  cmd->add_option("--instrument-angle", in.instrument_angle,
                  "the instrument measures poses (a 6-DOF tracker) of this orientation noise, deg "
                  "per rotation-vector coordinate; each row the joints, then x, y, z, rx, ry, rz")
      ->check(positiveNumber())
      ->needs(instrument);
  cmd->add_option("--point-unit", in.point_unit,
                  "unit of the measured points of an instrument (mm or m), for a header that names "
                  "none (a header naming another is refused)")
      ->check(CLI::IsMember({"mm", "m"}));
  cmd->add_option(
         "--orientation-unit", in.orientation_unit,
         "unit of a pose instrument's measured orientations (deg or rad), for a header that "
         "names none (a header naming another is refused)")
      ->check(CLI::IsMember({"deg", "rad"}));
  auto* probe = cmd->add_option("--probe", args->probe,
                                "noise.probe: mm per coordinate, or \"estimate\" (the default with "
                                "--instrument: the robot's own scatter, estimated by calibrate)")
                    ->capture_default_str();
  cmd->add_option("--encoder", in.encoder, "noise.encoder: deg (mm for prismatic joints)")
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--unit", in.unit,
                  "unit of every file's readings (deg, rad, mm, m), instead of "
                  "the layout's (hole_<k>.csv: rad; feature_<k>.csv: header)");
  cmd->add_option("--marker", in.markers,
                  "files whose header names the columns: the marker whose <marker>_x, <marker>_y, "
                  "<marker>_z are the tip's measured point (default: the header's only marker); "
                  "repeated: each row is one reading of each marker, each marker a tip of its "
                  "own whose offset is calibrated")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--orientation", in.orientation,
                  "a pose's orientation columns: rotation_vector, rpy (roll, pitch, yaw: the "
                  "URDF's fixed-axis x-y-z, R = Rz(yaw) Ry(pitch) Rx(roll)) or quaternion (w, x, "
                  "y, z); default: what the header names, rotation_vector without names")
      ->check(CLI::IsMember({"rotation_vector", "rpy", "quaternion"}));
  cmd->add_option("--hold", args->holds,
                  "JOINT=VALUE: a joint no file reads (a tool mount), held at VALUE (deg, or mm "
                  "for a prismatic joint) in every reading; repeat for several")
      ->type_name("JOINT=VALUE");
  cmd->add_option("--prior", args->prior,
                  "LENGTH,ANGLE: the machine's tolerances as built, mm and deg, a prior on every "
                  "parameter (plan-format.md \"prior\"): for readings too few for the parameters "
                  "they identify (a humanoid's touches)")
      ->type_name("MM,DEG");
  cmd->add_flag("--keep-calibrate", in.keep_calibrate,
                "keep the machine file's \"calibrate\" (default: \"identifiable\")");
  cmd->add_flag(
      "--keep-limits", in.keep_limits,
      "keep the machine's joint_limits where the readings pass them (they are then "
      "refused); default: widen a revolute joint's limits to its readings, with a warning");
  cmd->add_option("-o,--output", args->output, "plan file to write (- for stdout)")
      ->capture_default_str();
  cmd->callback([&action, args, probe] {
    ReadingsImport& given = args->import;
    given.tips = distinctEntries(given.tips);
    given.markers = distinctEntries(given.markers);
    given.tip = given.tips.size() == 1 ? given.tips.front() : std::string();
    if (given.tips.size() == 1) given.tips.clear();
    if (given.machine_file.empty() && given.urdf.empty())
      throw CLI::ValidationError("import-readings", "needs --machine or --urdf");
    if (!given.urdf.empty() && (given.base.empty() || (given.tip.empty() && given.tips.empty())))
      throw CLI::ValidationError("import-readings", "--urdf needs --base and --tip");
    if (!given.ball_bar && given.artifact_file.empty() && !given.instrument)
      throw CLI::ValidationError("import-readings", "needs --ball-bar, --artifact or --instrument");
    // Beside an instrument of stated noise, the robot's own scatter is what the readings state.
    if (given.instrument && probe->count() == 0) args->probe = "estimate";
    action = [args] {
      ReadingsImport& import = args->import;
      checkOutputPath(args->output);
      import.holds.clear();
      for (const std::string& hold : args->holds) {
        const auto assignment = splitAssignment(hold);
        const auto value = assignment ? decimalNumber(assignment->second) : std::nullopt;
        if (!value) {
          throw InputError("--hold", hold,
                           "expected JOINT=VALUE, VALUE a decimal number (deg, or mm), e.g. "
                           "tool_joint=0");
        }
        import.holds.emplace_back(assignment->first, *value);
      }
      import.tip_of.clear();
      for (const std::string& pair : args->tip_of) {
        auto assignment = splitAssignment(pair);
        if (!assignment)
          throw InputError("--tip-of", pair, "expected PLACEMENT=TIP, e.g. left=gripper_left_link");
        import.tip_of.push_back(std::move(*assignment));
      }
      if (!args->prior.empty()) {
        const auto comma = args->prior.find(',');
        const auto length =
            comma == std::string::npos ? std::nullopt : decimalNumber(args->prior.substr(0, comma));
        const auto angle = comma == std::string::npos
                               ? std::nullopt
                               : decimalNumber(args->prior.substr(comma + 1));
        if (!length || !angle || !(*length > 0.0) || !(*angle > 0.0))
          throw InputError("--prior", args->prior,
                           "expected LENGTH,ANGLE, decimal numbers (mm, deg; > 0), e.g. 5,0.5");
        import.prior_length = *length;
        import.prior_angle = *angle;
      }
      import.probe = probeValue(args->probe);
      import.output = args->output;
      const ImportedPlan imported = importReadings(import);
      for (const std::string& warning : imported.warnings)
        std::cerr << "warning: " << warning << "\n";
      const nlohmann::json& plan = imported.plan;
      // Checked like any plan (CSV rows, joint limits) before anything is written; whether the
      // nominal machine is plausible for the readings is check's and calibrate's to say.
      const Plan parsed = parsePlan(plan, imported.source, true, /*check_plausibility=*/false);
      for (const std::string& warning : parsed.warnings)
        std::cerr << "warning: " << warning << "\n";
      writeJsonOutput(args->output, plan);
      printPlanSummary("import-readings", args->output, parsed);
      return 0;
    };
  });
}

}  // namespace

const Registrar import_readings_registrar(79, "import-readings", addImportReadingsCommand);

}  // namespace artcal::cli
