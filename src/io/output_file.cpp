#include "artcal/io/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
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
  const int fd = ::mkstemp(pattern.data());
  if (fd < 0) throw std::runtime_error("cannot create a temporary file beside it");
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
    throw std::runtime_error("cannot be written (" + std::string(std::strerror(saved)) + ")");
  }
  return pattern;
}

void renameOver(const std::string& temporary, const std::string& path) {
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int saved = errno;
    std::remove(temporary.c_str());
    throw std::runtime_error("cannot be written (" + std::string(std::strerror(saved)) + ")");
  }
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
    for (const auto& [temporary, target] : staged) std::remove(temporary.c_str());
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
      for (std::size_t j = i + 1; j < staged.size(); ++j) std::remove(staged[j].first.c_str());
      refuse(files[i].first, e.what());
    }
  }
}

}  // namespace artcal
