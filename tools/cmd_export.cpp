// artcal export-linuxcnc / export-ur / export-xacro: a calibrated machine file as a controller or
// a robot description loads it (docs/exports.md). The file goes to -o; what was written and what
// the format cannot carry go to stdout (stderr when -o is -), as a table or with --json.

#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "artcal/io/calibrated_urdf.hpp"
#include "artcal/io/machine_exports.hpp"
#include "artcal/io/output_file.hpp"
#include "artcal/io/plan_io.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {

struct ExportArguments {
  std::string machine, urdf, output;
  std::vector<double> pivot;
  bool json = false;
};

// Writes the export and its summary (table or JSON).
int finish(const ExportArguments& args, const std::string& text, const nlohmann::json& summary) {
  writeOutputFile(args.output, text);
  std::ostream& out = summaryStream(args.output);
  if (args.json)
    out << summary.dump(2) << "\n";
  else
    out << exportSummaryTable(summary);
  return 0;
}

CLI::App* addCommon(CLI::App& app, const char* name, const char* what, ExportArguments& args) {
  CLI::App* cmd = app.add_subcommand(name, what);
  cmd->add_option("--machine", args.machine, "machine file (calibrate --write-machine)")
      ->required();
  cmd->add_option("-o,--output", args.output, "file to write (- for stdout)")->required();
  cmd->add_flag("--json", args.json, "print the summary as one JSON document");
  return cmd;
}

void addLinuxcnc(CLI::App& app, Action& action) {
  auto args = std::make_shared<ExportArguments>();
  CLI::App* cmd = addCommon(app, "export-linuxcnc",
                            "HAL setp lines of LinuxCNC's xyzac-trt kinematics for a calibrated "
                            "trunnion-AC machine tool, and what they cannot carry",
                            *args);
  cmd->add_option("--pivot", args->pivot,
                  "LinuxCNC machine coordinates X Y Z (mm) of the slides at artcal's zero readings")
      ->required()
      ->expected(3);
  cmd->callback([&action, args] {
    action = [args] {
      checkOutputPath(args->output);
      const MachineFile file = readMachineFile(readJsonFile(args->machine), args->machine);
      const Eigen::Vector3d pivot(args->pivot[0], args->pivot[1], args->pivot[2]);
      const MachineExport e = linuxcncExport(file, pivot);
      return finish(*args, e.text, e.summary);
    };
  });
}

void addUr(CLI::App& app, Action& action) {
  auto args = std::make_shared<ExportArguments>();
  addCommon(app, "export-ur",
            "Universal Robots kinematics_config YAML (ur_description) of a calibrated serial-dh "
            "arm of 6 revolute joints, and what it cannot carry",
            *args);
  app.get_subcommand("export-ur")->callback([&action, args] {
    action = [args] {
      checkOutputPath(args->output);
      const MachineFile file = readMachineFile(readJsonFile(args->machine), args->machine);
      const MachineExport e = urKinematicsExport(file);
      return finish(*args, e.text, e.summary);
    };
  });
}

void addXacro(CLI::App& app, Action& action) {
  auto args = std::make_shared<ExportArguments>();
  CLI::App* cmd = addCommon(app, "export-xacro",
                            "xacro properties of a calibrated chain's joint origins, for a "
                            "robot description (MoveIt) to include",
                            *args);
  cmd->add_option("--urdf", args->urdf, "the URDF the machine was imported from")->required();
  cmd->callback([&action, args] {
    action = [args] {
      checkOutputPath(args->output);
      const XacroProperties x =
          calibratedXacro(readJsonFile(args->machine), args->machine, args->urdf);
      const int status = finish(*args, x.text, x.summary);
      for (const std::string& warning : x.warnings) std::cerr << "warning: " << warning << "\n";
      return status;
    };
  });
}

}  // namespace

const Registrar export_linuxcnc_registrar(82, "export-linuxcnc", addLinuxcnc);
const Registrar export_ur_registrar(83, "export-ur", addUr);
const Registrar export_xacro_registrar(84, "export-xacro", addXacro);

}  // namespace artcal::cli
