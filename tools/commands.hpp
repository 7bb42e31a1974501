#pragma once
// The artcal command line: each subcommand lives in its own file and registers itself here.
// A command returns its exit status; InputError escapes to main, which answers with status 2.

#include <CLI/CLI.hpp>
#include <functional>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "artcal/plan/plan.hpp"

namespace artcal::cli {

/// CLI11's PositiveNumber and NonNegativeNumber, saying what they expect in a line a user reads
/// (CLI11's own prints the range up to the largest double).
CLI::Validator positiveNumber();
CLI::Validator nonNegativeNumber();

/// What main runs once the command line is parsed.
using Action = std::function<int()>;

/// Adds one subcommand to the app; its callback sets `action`.
using CommandFactory = void (*)(CLI::App& app, Action& action);

/// Each cmd_*.cpp registers its subcommands with a static Registrar: the subcommand's name, which
/// its factory adds, and `order`, which sorts --help.
struct Registrar {
  Registrar(int order, const char* name, CommandFactory factory);
};

/// A registered subcommand.
struct RegisteredCommand {
  int order;
  std::string name;
  CommandFactory factory;
};

/// The registered subcommands, sorted by order.
std::vector<RegisteredCommand> registeredCommands();

/// Loads a plan and prints its warnings (unknown fields) on stderr.
Plan loadPlanReporting(const std::string& path, bool require_placements = true);

/// `artcal check`'s answer for `plan` (table or JSON on stdout) and its exit status; also
/// calibrate's answer to a plan with fewer equations than unknowns (docs/hardening.md).
int printCheck(const Plan& plan, bool json, double rank_tolerance);

/// Prints a JSON document (2-space indent) on stdout.
void printJson(const nlohmann::json& document);

/// Writes JSON where an output option says (writeOutputFile: "-" is stdout; devices, FIFOs and
/// directories refused; symbolic links followed).
void writeJsonOutput(const std::string& path, const nlohmann::json& document);

/// "COMMAND: N placements, M readings" of a plan a command wrote to `output`, on
/// summaryStream(output).
void printPlanSummary(const std::string& command, const std::string& output, const Plan& plan);

/// Where a command that writes `output` prints its own summary: stdout, or stderr when the
/// output itself goes to stdout ("-"), so that stdout holds the output file alone.
std::ostream& summaryStream(const std::string& output);

}  // namespace artcal::cli
