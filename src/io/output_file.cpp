#include "artcal/io/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

#include "artcal/core/error.hpp"

namespace artcal {

namespace fs = std::filesystem;

namespace {

/// Symbolic links followed at most this many times (Linux's own bound, ELOOP beyond).
constexpr int kMaxLinkHops = 40;

[[noreturn]] void refuse(const std::string& path, const std::string& why) {
  throw InputError(path, "", why);
}

/// What kind of non-regular file `status` describes, or "" for a regular file or nothing.
std::string specialFileKind(const struct stat& status) {
  if (S_ISDIR(status.st_mode)) return "a directory";
  if (S_ISCHR(status.st_mode) || S_ISBLK(status.st_mode)) return "a device";
  if (S_ISFIFO(status.st_mode)) return "a FIFO";
  if (S_ISSOCK(status.st_mode)) return "a socket";
  return "";
}

/// The inputs of this run: (device, inode) and the name they were read by.
std::map<std::pair<dev_t, ino_t>, std::string>& inputFiles() {
  static std::map<std::pair<dev_t, ino_t>, std::string> files;
  return files;
}

std::mutex& inputFilesMutex() {
  static std::mutex mutex;
  return mutex;
}

}  // namespace

void noteInputFile(const std::string& path) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0 || !S_ISREG(status.st_mode)) return;
  const std::lock_guard lock(inputFilesMutex());
  inputFiles().emplace(std::make_pair(status.st_dev, status.st_ino), path);
}

std::string resolveOutputPath(const std::string& path) {
  fs::path current(path);
  for (int hop = 0; hop < kMaxLinkHops; ++hop) {
    std::error_code ec;
    if (!fs::is_symlink(fs::symlink_status(current, ec))) return current.string();
    const fs::path target = fs::read_symlink(current, ec);
    if (ec) refuse(path, "the symbolic link cannot be read: " + ec.message());
    current = target.is_absolute() ? target : current.parent_path() / target;
  }
  refuse(path, "more than " + std::to_string(kMaxLinkHops) + " symbolic links to follow");
}

void checkOutputPath(const std::string& path) {
  if (path == kStandardOutput) return;
  if (path.empty()) refuse(path, "an empty output name (use - for standard output)");
  struct stat status {};
  // Through its links first: /dev/stdout on a pipe is a link to "pipe:[N]", which no path
  // resolves to, and is refused as the FIFO it is, with the advice to write "-".
  const bool exists = ::stat(path.c_str(), &status) == 0;
  if (!exists || specialFileKind(status).empty()) {
    const std::string resolved = resolveOutputPath(path);
    if (::stat(resolved.c_str(), &status) != 0) return;  // a new file
  }
  const std::string kind = specialFileKind(status);
  if (!kind.empty()) {
    refuse(path, "is " + kind +
                     ", not a regular file: refusing to replace it (use - for "
                     "standard output)");
  }
  const std::lock_guard lock(inputFilesMutex());
  const auto input = inputFiles().find({status.st_dev, status.st_ino});
  if (input != inputFiles().end()) {
    refuse(path, "is the input " + input->second +
                     ": refusing to replace an input (write the output to another file)");
  }
}

void writeOutputFile(const std::string& path, const std::string& content) {
  if (path == kStandardOutput) {
    std::cout << content << std::flush;
    if (!std::cout) throw InputError("-", "", "standard output cannot be written");
    return;
  }
  checkOutputPath(path);
  const std::string resolved = resolveOutputPath(path);
  try {
    writeFileAtomically(resolved, content);
  } catch (const std::runtime_error& e) {
    refuse(path, e.what() + (resolved == path ? std::string()
                                              : " (through the link to " + resolved + ")"));
  }
}

namespace {

// ---------------------------------------------------------------- temporary files on a signal
// An output is written to a temporary file beside it and renamed into place. A run ended by a
// signal while it writes (SIGTERM, SIGINT, SIGHUP, SIGXFSZ at a file size limit) or by exit()
// removes the temporary files it holds (issue 44: 2 MB of debris after SIGTERM during
// `simulate -o`). The names sit in fixed slots that the handler reads with async-signal-safe
// calls only (unlink, sigaction, raise); a handler is installed only where the signal's action is
// the default one (the Python interpreter's SIGINT handler is left alone).

constexpr std::size_t kTemporarySlots = 256;
constexpr std::size_t kTemporaryNameBytes = 4096;
char g_temporary_names[kTemporarySlots][kTemporaryNameBytes];
volatile std::sig_atomic_t g_temporary_used[kTemporarySlots];
std::mutex g_temporary_mutex;
constexpr int kCleanedSignals[] = {SIGTERM, SIGINT, SIGHUP, SIGXFSZ};

void removeTemporaryFiles() {
  for (std::size_t i = 0; i < kTemporarySlots; ++i) {
    if (g_temporary_used[i]) ::unlink(g_temporary_names[i]);
  }
}

extern "C" void removeTemporaryFilesAndDie(int signal_number) {
  removeTemporaryFiles();
  struct sigaction fallback {};
  fallback.sa_handler = SIG_DFL;
  sigemptyset(&fallback.sa_mask);
  ::sigaction(signal_number, &fallback, nullptr);
  ::raise(signal_number);  // delivered on return: the status says which signal ended the run
}

void installTemporaryCleanup() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (const int signal_number : kCleanedSignals) {
      struct sigaction current {};
      if (::sigaction(signal_number, nullptr, &current) != 0 || current.sa_handler != SIG_DFL)
        continue;
      struct sigaction handler {};
      handler.sa_handler = removeTemporaryFilesAndDie;
      sigemptyset(&handler.sa_mask);
      for (const int other : kCleanedSignals) sigaddset(&handler.sa_mask, other);
      ::sigaction(signal_number, &handler, nullptr);
    }
    std::atexit(removeTemporaryFiles);
  });
}

/// Holds the name of a temporary file until it is renamed or removed; its slot, or
/// kTemporarySlots when every slot is taken (the file is then only removed on error paths).
std::size_t holdTemporary(const std::string& name) {
  installTemporaryCleanup();
  const std::lock_guard lock(g_temporary_mutex);
  if (name.size() >= kTemporaryNameBytes) return kTemporarySlots;
  for (std::size_t i = 0; i < kTemporarySlots; ++i) {
    if (g_temporary_used[i]) continue;
    std::memcpy(g_temporary_names[i], name.c_str(), name.size() + 1);
    std::atomic_signal_fence(std::memory_order_seq_cst);
    g_temporary_used[i] = 1;
    return i;
  }
  return kTemporarySlots;
}

/// The temporary file `name` renamed or removed: no longer the run's to remove.
void releaseTemporary(const std::string& name) {
  const std::lock_guard lock(g_temporary_mutex);
  for (std::size_t i = 0; i < kTemporarySlots; ++i) {
    if (g_temporary_used[i] && name == g_temporary_names[i]) {
      g_temporary_used[i] = 0;
      return;
    }
  }
}

/// Writes `content` to a new temporary file beside the regular file `path` (which keeps its
/// permissions when it exists), fsynced; returns its name. std::runtime_error on failure, the
/// temporary file removed.
std::string writeTemporaryBeside(const std::string& path, const std::string& content) {
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::string name = target.filename().string();
  name.insert(name.begin(), '.');
  name.append(".XXXXXX");
  std::string pattern = (dir / name).string();
  // Held from the moment it exists until it is renamed or removed.
  const int fd = ::mkstemp(pattern.data());
  if (fd < 0) throw std::runtime_error("cannot create a temporary file beside it");
  holdTemporary(pattern);
  const char* data = content.data();
  std::size_t left = content.size();
  bool ok = true;
  while (left > 0) {
    const ssize_t written = ::write(fd, data, left);
    if (written <= 0) {
      ok = false;
      break;
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  // The replaced file keeps its permissions; a new one gets the mode open(2) would give it.
  struct stat existing {};
  mode_t mode = 0;
  if (::stat(path.c_str(), &existing) == 0) {
    mode = existing.st_mode & 07777;
  } else {
    const mode_t mask = ::umask(0);
    ::umask(mask);
    mode = 0644 & ~mask;
  }
  ok = ok && ::fchmod(fd, mode) == 0;
  ok = ok && ::fsync(fd) == 0;
  ok = (::close(fd) == 0) && ok;
  if (!ok) {
    const int saved = errno;
    std::remove(pattern.c_str());
    releaseTemporary(pattern);
    throw std::runtime_error("cannot be written (" + std::string(std::strerror(saved)) + ")");
  }
  return pattern;
}

void renameOver(const std::string& temporary, const std::string& path) {
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int saved = errno;
    std::remove(temporary.c_str());
    releaseTemporary(temporary);
    throw std::runtime_error("cannot be written (" + std::string(std::strerror(saved)) + ")");
  }
  releaseTemporary(temporary);
}

void removeTemporary(const std::string& temporary) {
  std::remove(temporary.c_str());
  releaseTemporary(temporary);
}

}  // namespace

void writeFileAtomically(const std::string& path, const std::string& content) {
  renameOver(writeTemporaryBeside(path, content), path);
}

void checkOutputDirectory(const std::string& path) {
  if (path == kStandardOutput || path.empty()) {
    refuse(path, "several files are written: name a directory (not - or an empty name)");
  }
  struct stat status {};
  if (::stat(resolveOutputPath(path).c_str(), &status) == 0 && !S_ISDIR(status.st_mode)) {
    refuse(path, "not a directory: several files are written there");
  }
}

void createOutputDirectory(const std::string& path) {
  checkOutputDirectory(path);
  std::error_code error;
  fs::create_directories(resolveOutputPath(path), error);
  if (error) refuse(path, "the directory cannot be created: " + error.message());
}

void writeOutputFiles(const std::vector<std::pair<std::string, std::string>>& files) {
  for (const auto& [path, content] : files) checkOutputPath(path);
  std::vector<std::pair<std::string, std::string>> staged;  // temporary, target
  const auto discard = [&] {
    for (const auto& [temporary, target] : staged) removeTemporary(temporary);
  };
  for (const auto& [path, content] : files) {
    const std::string resolved = resolveOutputPath(path);
    try {
      staged.emplace_back(writeTemporaryBeside(resolved, content), resolved);
    } catch (const std::runtime_error& e) {
      discard();
      refuse(path, e.what());
    }
  }
  // Every file is written in full before the first rename: a failure above leaves the old set.
  for (std::size_t i = 0; i < staged.size(); ++i) {
    try {
      renameOver(staged[i].first, staged[i].second);
    } catch (const std::runtime_error& e) {
      for (std::size_t j = i + 1; j < staged.size(); ++j) removeTemporary(staged[j].first);
      refuse(files[i].first, e.what());
    }
  }
}

}  // namespace artcal
