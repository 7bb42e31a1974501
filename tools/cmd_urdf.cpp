// artcal import-urdf / artcal export-urdf: a URDF chain as a machine block and back (docs/models.md
// section 1).

#include <iostream>

#include "artcal/calibration/corrections.hpp"
#include "artcal/io/chain_codec.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/urdf.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {

struct ImportArguments {
  std::string urdf, base, tip, output = kStandardOutput;
};

void addImportCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<ImportArguments>();
  CLI::App* cmd = app.add_subcommand(
      "import-urdf",
      "the machine block (model chain, mm and deg) of the joints from a base link to a tip link");
  cmd->add_option("URDF", args->urdf, "robot description (URDF, metres and radians)")->required();
  cmd->add_option("--base", args->base, "link the chain starts from")->required();
  cmd->add_option("--tip", args->tip, "link whose origin is the probe centre")->required();
  cmd->add_option("-o,--output", args->output, "machine file to write (- for stdout)")
      ->capture_default_str();
  cmd->callback([&action, args] {
    action = [args] {
      checkOutputPath(args->output);
      writeJsonOutput(args->output, importUrdf(args->urdf, args->base, args->tip));
      return 0;
    };
  });
}

// Corrections a metrologist would not believe (calibration/corrections.hpp), against the URDF's
// own origins: a warning each on stderr, the URDF written all the same.
void warnImplausibleCorrections(const MachineBlock& block, const Eigen::VectorXd& nominal) {
  Machine machine;
  machine.mechanism = block.mechanism;
  machine.nominal = nominal;
  for (int i = 0; i < block.mechanism->parameterCount(); ++i) machine.calibrated.push_back(i);
  for (const ImplausibleCorrection& c : implausibleCorrections(machine, nominal, block.nominal))
    std::cerr << "warning: " << describeCorrection(machine, c) << "\n";
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
      const MachineBlock block = readChainMachine(readJsonFile(args->machine), args->machine);
      const auto& chain = static_cast<const Chain&>(*block.mechanism);
      writeOutputFile(args->output, exportUrdf(chain, block.nominal, args->urdf, args->machine));
      warnImplausibleCorrections(block, urdfNominal(chain, block.nominal, args->urdf));
      return 0;
    };
  });
}

}  // namespace

const Registrar import_urdf_registrar(80, addImportCommand);
const Registrar export_urdf_registrar(81, addExportCommand);

}  // namespace artcal::cli
