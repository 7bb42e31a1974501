// libFuzzer harness of the URDF import and export (artcal import-urdf / export-urdf): the input
// is a URDF file; the chain from link "base" to link "tip" is imported, read back as a machine
// block and exported onto the same file. An InputError is the proper answer to a bad URDF; any
// other escape, a crash, a hang or a non-finite number in the machine block is a finding.

#include "../../src/urdf/urdf_module.hpp"
#include "artcal/io/chain_codec.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace artcal;
  if (size > fuzz::kMaxInputBytes) return 0;
  const std::string path = fuzz::writeInputFile(data, size, ".urdf");
  try {
    const urdf_module::UrdfSource source{path, std::string(data, data + size)};
    const nlohmann::json machine = urdf_module::importUrdf(source, "base", {"tip"});
    fuzz::requireFinite(machine, "import-urdf");
    const nlohmann::json document = {{"machine", machine}};
    const MachineBlock block = readChainMachine(document, "machine.json");
    const auto& chain = static_cast<const Chain&>(*block.mechanism);
    (void)urdf_module::exportUrdf(chain, block.nominal, source, "machine.json", {});
  } catch (const InputError&) {
    return 0;
  }
  return 0;
}
