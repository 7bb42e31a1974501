#include "artcal/io/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <stdexcept>

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

}  // namespace

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
  const std::string resolved = resolveOutputPath(path);
  struct stat status {};
  if (::stat(resolved.c_str(), &status) != 0) return;  // a new file
  const std::string kind = specialFileKind(status);
  if (!kind.empty()) {
    refuse(path, "is " + kind +
                     ", not a regular file: refusing to replace it (use - for "
                     "standard output)");
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

void writeFileAtomically(const std::string& path, const std::string& content) {
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
  if (!ok || std::rename(pattern.c_str(), path.c_str()) != 0) {
    const int saved = errno;
    std::remove(pattern.c_str());
    throw std::runtime_error("cannot be written (" + std::string(std::strerror(saved)) + ")");
  }
}

}  // namespace artcal
