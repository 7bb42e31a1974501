// io/urdf.hpp through the URDF module (src/urdf/urdf_module.hpp), loaded on the first call: a
// run that reads no URDF does not load urdfdom, tinyxml2, console_bridge and tinyxml.
#include "artcal/io/urdf.hpp"

#include <dlfcn.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "../urdf/urdf_module.hpp"
#include "artcal/core/error.hpp"
#include "artcal/io/plan_io.hpp"

namespace artcal {
namespace {

/// The real path of the file that holds this code, as the kernel maps it (/proc/self/maps: an
/// absolute path with every link resolved, whatever the current folder or argv[0]): the program
/// or, in the Python module, that shared object. Empty when unknown (/proc not mounted).
std::filesystem::path fileHoldingThisCode() {
  const auto here = reinterpret_cast<std::uintptr_t>(&fileHoldingThisCode);
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);) {
    // start-end perms offset dev inode path
    std::istringstream fields(line);
    std::string range, perms, offset, device, inode, path;
    fields >> range >> perms >> offset >> device >> inode;
    std::getline(fields >> std::ws, path);
    const std::size_t dash = range.find('-');
    if (dash == std::string::npos || path.empty() || path.front() != '/') continue;
    std::uintptr_t begin = 0, end = 0;
    const char* text = range.data();
    if (std::from_chars(text, text + dash, begin, 16).ec != std::errc() ||
        std::from_chars(text + dash + 1, text + range.size(), end, 16).ec != std::errc())
      continue;
    if (here >= begin && here < end) return path;
  }
  return {};
}

/// `inner` is `outer` or inside it (both absolute and canonical).
bool isWithin(const std::filesystem::path& inner, const std::filesystem::path& outer) {
  const auto [o, i] = std::mismatch(outer.begin(), outer.end(), inner.begin(), inner.end());
  return o == outer.end();
}

/// Where the module may be, nearest first: only where artcal itself is (docs/urdf.md), never the
/// current folder or a folder above it, whatever argv[0] says.
/// - The program (its real path, /proc/self/exe): <bindir>/../<libdir>/artcal/ of its installed
///   tree (/usr/bin/artcal -> /usr/lib/artcal, /usr/local/bin -> /usr/local/lib/artcal).
/// - A shared object holding this code (the Python module): <prefix>/<libdir>/artcal/ for each
///   folder above its real path (its installed tree's prefix, a scratch root's).
/// - Either, when it lies in the build tree: the build tree's module.
std::vector<std::filesystem::path> moduleCandidates(std::string& why) {
  namespace fs = std::filesystem;
  std::vector<fs::path> out;
  std::error_code error;
  const fs::path code = fs::weakly_canonical(fileHoldingThisCode(), error);
  if (error || code.empty()) {
    why += "; the running program's real path is unknown (/proc/self/maps)";
    return out;
  }
  const fs::path program = fs::canonical("/proc/self/exe", error);
  if (!error && program == code) {
    out.push_back((program.parent_path() / ARTCAL_URDF_MODULE_FROM_BINDIR).lexically_normal());
  } else {
    fs::path at = code;
    for (int up = 0; up < 6 && at.has_parent_path() && at != at.parent_path(); ++up) {
      at = at.parent_path();
      out.push_back(at / ARTCAL_URDF_MODULE_PATH);
    }
  }
  const fs::path build = fs::weakly_canonical(ARTCAL_URDF_BUILD_DIR, error);
  const fs::path built = fs::path(ARTCAL_URDF_MODULE_BUILT).lexically_normal();
  if (!error && isWithin(code, build) && std::find(out.begin(), out.end(), built) == out.end())
    out.push_back(built);
  return out;
}

/// The module file at `path` opened without blocking and checked to be a regular file (dlopen of
/// a FIFO or a device would wait forever); -1 with `why` told otherwise.
int openModuleFile(const std::filesystem::path& path, std::string& why) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    why = errno == ENOENT ? "not there" : std::strerror(errno);
    return -1;
  }
  struct stat status {};
  if (::fstat(fd, &status) != 0 || !S_ISREG(status.st_mode)) {
    why = S_ISFIFO(status.st_mode)  ? "a FIFO, not a regular file"
          : S_ISDIR(status.st_mode) ? "a directory, not a regular file"
                                    : "not a regular file";
    ::close(fd);
    return -1;
  }
  return fd;
}

const UrdfModuleTable* openModule(const std::filesystem::path& path, std::string& why) {
  std::string problem;
  const int fd = openModuleFile(path, problem);
  if (fd < 0) {
    why += "; " + path.string() + ": " + problem;
    return nullptr;
  }
  ::close(fd);
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* error = dlerror();
    why += "; " + path.string() + ": " + (error ? error : "cannot be loaded");
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
  if (const char* forced = std::getenv("ARTCAL_URDF_MODULE"); forced && *forced) {
    // The user's own choice: an absolute path to a regular file, refused at once otherwise.
    const std::filesystem::path path(forced);
    const std::string named = std::string("ARTCAL_URDF_MODULE=") + forced;
    if (!path.is_absolute()) {
      throw InputError(named, "",
                       "not an absolute path: name the module file libartcal_urdf.so by its "
                       "full path, or unset it to use the installed module");
    }
    std::string problem;
    if (const int fd = openModuleFile(path, problem); fd >= 0) {
      ::close(fd);
    } else {
      throw InputError(named, "",
                       problem +
                           ": name the module file libartcal_urdf.so itself, or unset it "
                           "to use the installed module");
    }
    if ((table = openModule(path, why))) return *table;
    throw InputError(named, "", "not artcal's URDF module (" + why.substr(2) + ")");
  }
  for (const std::filesystem::path& candidate : moduleCandidates(why))
    if ((table = openModule(candidate, why))) return *table;
  throw std::runtime_error(
      "URDF support is artcal's module libartcal_urdf.so, loaded when a URDF is read from where "
      "artcal is installed; it was not found or not usable (install artcal whole, or set "
      "ARTCAL_URDF_MODULE to the module's absolute path)" +
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

nlohmann::json importUrdfWithCompliance(const std::string& urdf_path, const std::string& base,
                                        const std::vector<std::string>& tips) {
  nlohmann::json machine = importUrdf(urdf_path, base, tips);
  if (tips.size() != 1) {
    throw InputError(urdf_path, "",
                     "--compliance needs one --tip (a machine of one tip, docs/compliance.md)");
  }
  const urdf_module::UrdfSource source = urdfSource(urdf_path);
  machine["compliance"] = {{"gravity", {0.0, 0.0, -9.81}},
                           {"masses", urdfModule().link_masses(source, base, tips.front())}};
  return machine;
}

Eigen::VectorXd urdfNominal(const Chain& chain, const Eigen::VectorXd& p,
                            const std::string& urdf_path) {
  const urdf_module::UrdfSource source = urdfSource(urdf_path);
  return urdfModule().nominal(chain, p, source);
}

std::string exportUrdf(const Chain& chain, const Eigen::VectorXd& p, const std::string& urdf_path,
                       const std::string& machine_source, const std::vector<int>& calibrated) {
  const urdf_module::UrdfSource source = urdfSource(urdf_path);
  return urdfModule().export_urdf(chain, p, source, machine_source, calibrated);
}

std::vector<OriginEdit> calibratedOrigins(const Chain& chain, const Eigen::VectorXd& p,
                                          const std::string& urdf_path,
                                          const std::string& machine_source,
                                          const std::vector<int>& calibrated) {
  const urdf_module::UrdfSource source = urdfSource(urdf_path);
  return urdfModule().origins(chain, p, source, machine_source, calibrated);
}

}  // namespace artcal
