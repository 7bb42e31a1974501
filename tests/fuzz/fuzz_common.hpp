#pragma once
// What both harnesses run behind the parser: a bounded evaluation whose every output must be
// finite (JSON through finiteOrNull, tables without nan/inf). A fault aborts, which libFuzzer
// reports as a finding; an InputError is the proper answer of the parser (or of the evaluator to a
// plan without a usable workspace configuration) and ends the run quietly.

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "artcal/internal.hpp"

namespace artcal::fuzz {

/// Inputs larger than this are skipped: the interesting faults are in structure, not bulk.
inline constexpr std::size_t kMaxInputBytes = 64 * 1024;
/// Bounds on the work done for one input, so that the fuzzer keeps a high execution rate.
inline constexpr int kMaxWorkspace = 32;
inline constexpr std::size_t kMaxReadings = 256;
inline constexpr int kProfileSteps = 5;

[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "fuzz finding: %s\n", what.c_str());
  std::abort();
}

/// A file of this process holding `data`, for the readers that take a path (URDF, CSV).
inline std::string writeInputFile(const std::uint8_t* data, std::size_t size, const char* suffix) {
  const std::string path = "/tmp/artcal-fuzz-" + std::to_string(::getpid()) + suffix;
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

/// Every number of a JSON output is finite (non-finite values must have become null).
inline void requireFinite(const nlohmann::json& value, const std::string& where) {
  if (value.is_number_float() && !std::isfinite(value.get<double>())) {
    finding("non-finite number in JSON output at " + where);
  }
  if (value.is_structured()) {
    for (const auto& [key, item] : value.items()) requireFinite(item, where + "/" + key);
  }
}

/// A human table never shows nan or inf.
inline void requireNoNonFinite(const std::string& table) {
  for (const char* word : {"nan", "inf"}) {
    for (std::size_t at = table.find(word); at != std::string::npos;
         at = table.find(word, at + 1)) {
      const bool starts_word = at == 0 || !std::isalpha(static_cast<unsigned char>(table[at - 1]));
      const std::size_t end = at + 3;
      const bool ends_word =
          end >= table.size() || !std::isalpha(static_cast<unsigned char>(table[end]));
      if (starts_word && ends_word) finding(std::string("\"") + word + "\" in a table");
    }
  }
}

/// The plan's workspace, cut to kMaxWorkspace configurations.
inline void boundWorkspace(Plan& plan) {
  WorkspaceSpec& ws = plan.workspace;
  long grid_size = 1;
  for (int n : ws.grid) grid_size *= n;
  if (ws.kind == WorkspaceSpec::Kind::Configurations &&
      ws.configurations.size() > static_cast<std::size_t>(kMaxWorkspace)) {
    ws.configurations.resize(kMaxWorkspace);
  } else if (ws.kind == WorkspaceSpec::Kind::Grid && grid_size > kMaxWorkspace) {
    ws.kind = WorkspaceSpec::Kind::Samples;
  }
  ws.samples = std::min(ws.samples, kMaxWorkspace);
}

inline std::size_t readingCount(const Plan& plan) {
  std::size_t n = 0;
  for (const Placement& placement : plan.placements) n += placement.measurements.size();
  return n;
}

/// check + evaluate as the CLI runs them, with bounded effort, outputs checked.
inline void evaluateBounded(Plan plan) {
  if (readingCount(plan) > kMaxReadings) return;
  boundWorkspace(plan);
  const Evaluation evaluation = evaluatePlan(plan, {kDefaultRankTolerance, kProfileSteps});
  requireFinite(identifiabilityToJson(evaluation.identifiability), "check");
  requireFinite(evaluationToJson(plan, evaluation), "evaluate");
  requireNoNonFinite(identifiabilityTable(plan, evaluation.identifiability));
  requireNoNonFinite(evaluationTable(plan, evaluation));
  if (evaluation.covariance && !evaluation.covariance->u.allFinite()) {
    finding("non-finite parameter uncertainty");
  }
}

}  // namespace artcal::fuzz
