#pragma once
// Runs the built artcal binary (ARTCAL_CLI) from a test: the one helper every test file uses to
// check the command line's exit status and output.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace artcal::test_support {

/// What is captured: stdout alone (stderr discarded), both merged, or stderr alone (stdout
/// discarded). No temporary file is involved, so tests may run in parallel.
enum class Stderr { Discard, Merge, Only };

struct CliRun {
  int status = -1;  ///< exit status; -1 when the program did not exit normally
  std::string out;  ///< what was captured (see Stderr)
};

/// Runs `artcal ARGUMENTS` through the shell (arguments are not quoted for it).
inline CliRun runCli(const std::string& arguments, Stderr err = Stderr::Discard) {
  const char* redirection = err == Stderr::Merge  ? " 2>&1"
                            : err == Stderr::Only ? " 2>&1 >/dev/null"
                                                  : " 2>/dev/null";
  const std::string command = std::string(ARTCAL_CLI) + " " + arguments + redirection;
  CliRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    run.out.append(buffer.data(), n);
  const int status = pclose(pipe);
  run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

}  // namespace artcal::test_support
