// io/urdf.hpp through the URDF module (src/urdf/urdf_module.hpp), loaded on the first call: a
// run that reads no URDF does not load urdfdom, tinyxml2, console_bridge and tinyxml.
#include "artcal/io/urdf.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>

#include "../urdf/urdf_module.hpp"
#include "artcal/core/error.hpp"
#include "artcal/io/plan_io.hpp"

namespace artcal {
namespace {

/// Where the module may be: $ARTCAL_URDF_MODULE; then <prefix>/ARTCAL_URDF_MODULE_PATH for each
/// folder above the program or library this code is part of (the installed tree's prefix, a
/// scratch root's, the build tree: the nearest first); then the configured install prefix's.
std::vector<std::filesystem::path> moduleCandidates() {
  std::vector<std::filesystem::path> out;
  if (const char* forced = std::getenv("ARTCAL_URDF_MODULE"); forced && *forced) {
    out.emplace_back(forced);
    return out;
  }
  Dl_info self{};
  if (dladdr(reinterpret_cast<void*>(&moduleCandidates), &self) != 0 && self.dli_fname) {
    std::error_code error;
    std::filesystem::path at = std::filesystem::canonical(self.dli_fname, error);
    for (int up = 0; !error && up < 6 && at.has_parent_path() && at != at.parent_path(); ++up) {
      at = at.parent_path();
      out.push_back(at / ARTCAL_URDF_MODULE_PATH);
    }
  }
  out.emplace_back(ARTCAL_URDF_MODULE_INSTALLED);
  return out;
}

const UrdfModuleTable* openModule(const std::filesystem::path& path, std::string& why) {
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    why += "; " + path.string() + ": " + dlerror();
    return nullptr;
  }
  using Entry = const UrdfModuleTable* (*)();
  const auto entry = reinterpret_cast<Entry>(dlsym(handle, kUrdfModuleSymbol));
  const UrdfModuleTable* table = entry ? entry() : nullptr;
  if (!table || table->abi() != urdfModuleAbi()) {
    why += "; " + path.string() + ": built for " + (table ? table->abi() : "another program") +
           ", not for " + urdfModuleAbi();
    dlclose(handle);
    return nullptr;
  }
  return table;  // kept loaded for the process' life
}

const UrdfModuleTable& urdfModule() {
  static std::mutex mutex;
  static const UrdfModuleTable* table = nullptr;
  const std::lock_guard lock(mutex);
  if (table) return *table;
  std::string why;
  for (const std::filesystem::path& candidate : moduleCandidates()) {
    std::error_code error;
    if (!std::filesystem::exists(candidate, error)) {
      why += "; " + candidate.string() + ": not there";
      continue;
    }
    if ((table = openModule(candidate, why))) return *table;
  }
  throw std::runtime_error(
      "URDF support is artcal's module libartcal_urdf.so, loaded when a URDF is read; it was "
      "not found or not usable (install artcal whole, or set ARTCAL_URDF_MODULE to the file)" +
      why);
}

/// The URDF file's text, read here so that it is one of the run's inputs.
urdf_module::UrdfSource urdfSource(const std::string& path) {
  try {
    return {path, readInputFile(path)};
  } catch (const InputError& e) {
    if (std::string(e.what()) != "cannot be read") throw;
    throw InputError(path, "", "cannot read the URDF file");
  }
}

}  // namespace

nlohmann::json importUrdf(const std::string& urdf_path, const std::string& base,
                          const std::string& tip) {
  return importUrdf(urdf_path, base, std::vector<std::string>{tip});
}

nlohmann::json importUrdf(const std::string& urdf_path, const std::string& base,
                          const std::vector<std::string>& tips) {
  const urdf_module::UrdfSource source = urdfSource(urdf_path);
  return urdfModule().import_urdf(source, base, tips);
}

Eigen::VectorXd urdfNominal(const Chain& chain, const Eigen::VectorXd& p,
                            const std::string& urdf_path) {
  const urdf_module::UrdfSource source = urdfSource(urdf_path);
  return urdfModule().nominal(chain, p, source);
}

std::string exportUrdf(const Chain& chain, const Eigen::VectorXd& p, const std::string& urdf_path,
                       const std::string& machine_source) {
  const urdf_module::UrdfSource source = urdfSource(urdf_path);
  return urdfModule().export_urdf(chain, p, source, machine_source);
}

}  // namespace artcal
