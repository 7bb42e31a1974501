// artcal import-urdf / artcal export-urdf: a URDF chain as a machine block and back (docs/models.md
// section 1).

#include <iostream>
#include <string>
#include <vector>

#include "artcal/io/calibrated_urdf.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/urdf.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {

struct ImportArguments {
  std::string urdf, base, output = kStandardOutput;
  std::vector<std::string> tips;
  bool compliance = false;
};

void addImportCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<ImportArguments>();
  CLI::App* cmd = app.add_subcommand(
      "import-urdf",
      "the machine block (model chain, mm and deg) of the joints from a base link to a tip link");
  cmd->add_option("URDF", args->urdf, "robot description (URDF, metres and radians)")->required();
  cmd->add_option("--base", args->base, "link the chain starts from")->required();
  cmd->add_option("--tip", args->tips,
                  "link whose origin is the probe centre; repeated: one machine with several tips "
                  "sharing joints (docs/urdf.md)")
      ->required()
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("-o,--output", args->output, "machine file to write (- for stdout)")
      ->capture_default_str();
  cmd->add_flag("--compliance", args->compliance,
                "add a compliance block with the links' masses (docs/compliance.md)");
  cmd->callback([&action, args] {
    action = [args] {
      checkOutputPath(args->output);
      writeJsonOutput(args->output,
                      args->compliance
                          ? importUrdfWithCompliance(args->urdf, args->base, args->tips)
                          : importUrdf(args->urdf, args->base, args->tips));
      return 0;
    };
  });
}

struct ExportArguments {
  std::string machine, urdf, output;
};

void addExportCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<ExportArguments>();
  CLI::App* cmd = app.add_subcommand(
      "export-urdf",
      "the URDF with the chain's origins set to a (calibrated) machine's, everything else kept");
  cmd->add_option("--machine", args->machine, "machine file (calibrate --write-machine)")
      ->required();
  cmd->add_option("--urdf", args->urdf, "the URDF the machine was imported from")->required();
  cmd->add_option("-o,--output", args->output, "URDF to write (- for stdout)")->required();
  cmd->callback([&action, args] {
    action = [args] {
      checkOutputPath(args->output);
      const CalibratedUrdf urdf =
          calibratedUrdf(readJsonFile(args->machine), args->machine, args->urdf);
      writeOutputFile(args->output, urdf.text);
      for (const std::string& warning : urdf.warnings) std::cerr << "warning: " << warning << "\n";
      if (!urdf.compliance_yaml.empty()) {  // docs/compliance.md section 5
        const std::string apart =
            args->output == kStandardOutput ? std::string() : args->output + ".compliance.yaml";
        if (!apart.empty()) writeOutputFile(apart, urdf.compliance_yaml);
        std::cerr << "note: a URDF cannot carry joint compliance; "
                  << (apart.empty() ? "export to a file to have it written apart"
                                    : "written apart to " + apart)
                  << "\n";
      }
      return 0;
    };
  });
}

}  // namespace

const Registrar import_urdf_registrar(80, "import-urdf", addImportCommand);
const Registrar export_urdf_registrar(81, "export-urdf", addExportCommand);

}  // namespace artcal::cli
