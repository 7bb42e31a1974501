// artcal: plan and run the kinematic calibration of measuring mechanisms with artifacts.

#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <new>
#include <stdexcept>

#include "artcal/core/assignment.hpp"
#include "artcal/core/error.hpp"
#include "artcal/io/json_node.hpp"
#include "artcal/io/output_file.hpp"
#include "artcal/io/plan_io.hpp"
#include "commands.hpp"

namespace artcal::cli {

namespace {
std::vector<RegisteredCommand>& registry() {
  static std::vector<RegisteredCommand> commands;
  return commands;
}
}  // namespace

Registrar::Registrar(int order, const char* name, CommandFactory factory) {
  registry().push_back({order, name, factory});
}

std::vector<RegisteredCommand> registeredCommands() {
  auto sorted = registry();
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const auto& a, const auto& b) { return a.order < b.order; });
  return sorted;
}

namespace {

/// A validator of the numbers `accept` takes, naming them as `expected` ("a number > 0"): decimal
/// numbers only (0x10, inf, nan refused, docs/hardening.md "Hardening IV"), within the bound of
/// every number read (kMaxInputMagnitude: 1e9 mm, deg, or a count).
CLI::Validator numberValidator(bool (*accept)(double), const std::string& expected) {
  return CLI::Validator(
      [accept, expected](std::string& input) -> std::string {
        const std::optional<double> value = decimalNumber(input);
        if (!value)
          return "expected " + expected + ", not \"" + input + "\" (decimal numbers only)";
        if (!accept(*value)) return "expected " + expected + ", not \"" + input + "\"";
        if (std::abs(*value) > kMaxInputMagnitude)
          return "expected " + expected + " within 1e9, not \"" + input + "\"";
        return {};
      },
      "NUMBER", "");
}

/// CLI11 reads an integer option's 0x10 as 16 and a floating one's 0x1p-2 as 0.25: every option
/// of every command that takes a number reads it with decimalNumber (one rule for all options),
/// the ones that check a range with positiveNumber or nonNegativeNumber besides. A seed is a
/// count of its own (any whole number); every other number is within the input bound.
void readNumbersAsDecimals(CLI::App& app) {
  const CLI::Validator decimal = numberValidator([](double) { return true; }, "a decimal number");
  const CLI::Validator any_decimal(
      [](std::string& input) -> std::string {
        if (decimalNumber(input)) return {};
        return "expected a decimal number, not \"" + input + "\" (decimal numbers only)";
      },
      "", "");
  for (CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; })) {
    for (CLI::Option* option : command->get_options()) {
      const std::string type = option->get_type_name();
      if (type != "INT" && type != "UINT" && type != "FLOAT") continue;
      option->check(option->check_lname("seed") ? any_decimal : decimal);
    }
  }
}

/// An option given more than once (one rule for every option of every command): the same value
/// again counts once; another value is refused, naming both (CLI11 refused even the same value
/// twice, and a repeatable option kept the first or the last). The repeatable options (--hold,
/// --tip, --tip-of, --frame-of, --marker) apply the same rule per joint, tip or placement where
/// their entries are read.
void takeOptionsGivenTwiceOnce(CLI::App& app) {
  for (CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; })) {
    for (CLI::Option* option : command->get_options()) {
      if (option->get_multi_option_policy() == CLI::MultiOptionPolicy::Throw &&
          option->get_expected_max() == 1)
        option->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    }
  }
}

/// The first option of the parsed command given twice with two values, as "--seed: given twice,
/// 1 and 2: give it once", or "".
std::string optionGivenTwice(CLI::App& app) {
  for (CLI::App* command : app.get_subcommands()) {
    for (const CLI::Option* option : command->get_options()) {
      if (option->get_multi_option_policy() != CLI::MultiOptionPolicy::TakeLast) continue;
      const CLI::results_t& values = option->results();
      for (const std::string& value : values) {
        if (value == values.front()) continue;
        return option->get_name() + ": given twice, " + values.front() + " and " + value +
               ": give it once";
      }
    }
  }
  return "";
}

}  // namespace

CLI::Validator positiveNumber() {
  return numberValidator([](double v) { return v > 0.0; }, "a number > 0");
}

CLI::Validator nonNegativeNumber() {
  return numberValidator([](double v) { return v >= 0.0; }, "a number >= 0");
}

Plan loadPlanReporting(const std::string& path, bool require_placements) {
  Plan plan = loadPlan(path, require_placements);
  for (const std::string& warning : plan.warnings) std::cerr << "warning: " << warning << "\n";
  return plan;
}

/// RunError naming the first number of `document` that is not finite: nlohmann would write it as
/// null (every output's numbers are finite, docs/hardening.md; "not computable" is an explicit
/// null put there by finiteOrNull, never a NaN).
void checkFiniteNumbers(const nlohmann::json& document, const std::string& pointer = "") {
  if (document.is_number_float() && !std::isfinite(document.get<double>())) {
    throw RunError("-", pointer.empty() ? "/" : pointer,
                   "a result is not finite (an internal fault: please report it with the input)");
  }
  if (document.is_object()) {
    for (const auto& [key, value] : document.items())
      checkFiniteNumbers(value, pointer + "/" + key);
  } else if (document.is_array()) {
    for (std::size_t i = 0; i < document.size(); ++i)
      checkFiniteNumbers(document[i], pointer + "/" + std::to_string(i));
  }
}

void printJson(const nlohmann::json& document) {
  checkFiniteNumbers(document);
  std::cout << document.dump(2) << std::endl;
}

void writeJsonOutput(const std::string& path, const nlohmann::json& document) {
  checkFiniteNumbers(document);
  writeOutputFile(path,
                  path == kStandardOutput ? document.dump(2) + "\n" : document.dump(1) + "\n");
}

std::ostream& summaryStream(const std::string& output) {
  return output == kStandardOutput ? std::cerr : std::cout;
}

void printPlanSummary(const std::string& command, const std::string& output, const Plan& plan) {
  std::size_t readings = 0;
  for (const Placement& placement : plan.placements) readings += placement.measurements.size();
  summaryStream(output) << command << ": " << plan.placements.size() << " placements, " << readings
                        << " readings\n";
}

}  // namespace artcal::cli

namespace {

/// The first argument (or the value of --option=value) that reads as a non-finite number ("nan",
/// "-inf", "Infinity", "1e999"), with the option it is given to, or "": CLI11 converts them to
/// double and its range checks let NaN through (--rank-tol nan) or print the range with 300
/// digits (--rank-tol inf). One guard for every number option of every command, before CLI11
/// parses. The message names the option ("--cube: nan: ..."), or the value alone for a
/// positional argument.
std::string nonFiniteArgument(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    std::string value = argv[i];
    std::string option;
    if (value.starts_with("--") && value.find('=') != std::string::npos) {
      option = value.substr(0, value.find('='));
      value = value.substr(value.find('=') + 1);
    } else if (i > 1 && argv[i - 1][0] == '-' && argv[i - 1][1] != '\0') {
      option = argv[i - 1];
    }
    const char* begin = value.c_str();
    char* end = nullptr;
    const double number = std::strtod(begin, &end);
    if (end != begin && *end == '\0' && !std::isfinite(number))
      return (option.empty() ? "" : option + ": ") + value;
  }
  return "";
}

bool isOutputOption(const CLI::Option& option) {
  return option.check_lname("output") || option.check_lname("write-machine") ||
         option.check_lname("svg");
}

/// The files the command line names as inputs (every value of an option but the outputs that
/// is an existing file), noted so that no output replaces one; the first names the run's input
/// in messages that have no file of their own.
std::string noteCommandLineInputs(CLI::App& app) {
  std::string first;
  for (CLI::App* sub : app.get_subcommands()) {
    for (const CLI::Option* option : sub->get_options()) {
      if (isOutputOption(*option)) continue;
      for (const std::string& value : option->results()) {
        std::error_code error;
        if (!std::filesystem::is_regular_file(value, error)) continue;
        artcal::noteInputFile(value);
        if (first.empty()) first = value;
      }
    }
  }
  return first;
}

/// A library's message without its own tag ("[json.exception.type_error.302] ...").
std::string withoutTag(const std::string& message) {
  if (!message.starts_with("[")) return message;
  const auto end = message.find("] ");
  return end == std::string::npos ? message : message.substr(end + 2);
}

constexpr int kBrokenPipeStatus = 141;

/// Whether stdout is a pipe (or socket) whose reader has gone: a write would fail with EPIPE.
bool standardOutputReaderGone() {
  struct stat status {};
  if (::fstat(STDOUT_FILENO, &status) != 0 ||
      !(S_ISFIFO(status.st_mode) || S_ISSOCK(status.st_mode)))
    return false;
  pollfd out{STDOUT_FILENO, POLLOUT, 0};
  return ::poll(&out, 1, 0) == 1 && (out.revents & (POLLERR | POLLHUP)) != 0;
}

/// Exit status 2 with "error: -: standard output cannot be written" when stdout failed (a full
/// disk, a closed pipe): a command must not end with 0 and a truncated output.
int checkStandardOutput(int status) {
  std::cout.flush();
  if (std::fflush(stdout) == 0 && !std::ferror(stdout) && std::cout.good()) return status;
  // A reader that closed the pipe (`artcal ... | head`) has what it wanted: silent, as other
  // tools, with the status of a death by SIGPIPE (128 + 13) for `set -o pipefail`.
  if (errno == EPIPE || standardOutputReaderGone()) return kBrokenPipeStatus;
  std::cerr << "error: -: standard output cannot be written (" << std::strerror(errno)
            << "): the output is incomplete" << std::endl;
  return 2;
}

/// The subcommands a command line needs (start-up: the options of all of them cost more than
/// the rest of `artcal --version`): the one it names; none when it names none and asks for no
/// help (`--version`, or the error that a subcommand is required); every one for --help and for
/// a name that is not a subcommand (CLI11's answer then is as with them all).
void addSubcommands(CLI::App& app, artcal::cli::Action& action, int argc, char** argv) {
  std::string named;
  bool help = false;
  for (int i = 1; i < argc && named.empty(); ++i) {
    const std::string argument = argv[i];
    if (!argument.starts_with("-")) named = argument;
    help = help || argument == "-h" || argument == "--help" || argument == "--help-all";
  }
  const auto commands = artcal::cli::registeredCommands();
  const bool known = std::any_of(commands.begin(), commands.end(),
                                 [&](const auto& command) { return command.name == named; });
  for (const auto& command : commands) {
    if (known ? command.name != named : named.empty() && !help) continue;
    command.factory(app, action);
    const auto added = app.get_subcommands(
        [&](const CLI::App* subcommand) { return subcommand->get_name() == command.name; });
    if (added.empty())
      throw std::logic_error("the registrar of \"" + command.name + "\" names no subcommand");
  }
}

int runAction(const artcal::cli::Action& action, const std::string& input) {
  const std::string file = input.empty() ? "artcal" : input;
  try {
    return action();
  } catch (const artcal::InputError& e) {
    if (e.describe().starts_with("-: ") && standardOutputReaderGone()) return kBrokenPipeStatus;
    std::cerr << "error: " << e.describe() << std::endl;
    return 2;
  } catch (const artcal::RunError& e) {
    std::cerr << "error: " << e.describe() << std::endl;
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "error: " << file
              << ": not enough memory for this input (make it smaller, or run on a machine "
                 "with more memory)"
              << std::endl;
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    std::cerr << "error: " << (e.path1().empty() ? file : e.path1().string()) << ": "
              << e.code().message() << std::endl;
    return 2;
  } catch (const std::invalid_argument& e) {  // an option's value (checkOptions)
    std::cerr << "error: " << e.what() << std::endl;
    return 2;
  } catch (const std::exception& e) {  // a library's (nlohmann::json, Eigen, ...)
    std::cerr << "error: " << file << ": " << withoutTag(e.what()) << std::endl;
    return 2;
  }
}

}  // namespace

int main(int argc, char** argv) {
  // A closed pipe on stdout (`artcal evaluate P | head -1`) is a write error that
  // checkStandardOutput reports (exit 2), not a death by SIGPIPE (exit 141).
  std::signal(SIGPIPE, SIG_IGN);
  CLI::App app{
      "artcal: plans and runs the kinematic calibration of measuring mechanisms with calibrated "
      "artifacts (ball bars, ball plates, step gauges). Units in files: mm and degrees.",
      "artcal"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "artcal 0.1.0");
  artcal::cli::Action action;
  addSubcommands(app, action, argc, argv);
  artcal::cli::readNumbersAsDecimals(app);
  artcal::cli::takeOptionsGivenTwiceOnce(app);
  if (const std::string bad = nonFiniteArgument(argc, argv); !bad.empty()) {
    std::cerr << "error: " << bad << ": expected a finite number (every number option)"
              << std::endl;
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, as every input error: what is wrong, and where to look.
    std::cerr << "error: " << e.what() << " (artcal --help; artcal COMMAND --help)" << std::endl;
    return 2;
  }
  if (const std::string twice = artcal::cli::optionGivenTwice(app); !twice.empty()) {
    std::cerr << "error: " << twice << std::endl;
    return 2;
  }
  const std::string input = noteCommandLineInputs(app);
  return checkStandardOutput(runAction(action, input));
}
