#pragma once
// What `artcal optimize SPEC -o PLAN` and `artcal optimize SPEC --placements A..B -o DIR/` write
// (docs/plan-format.md, optimization spec; docs/optimize.md): the optimized plan with its
// `predicted` block (the `optimization` record of the search included), and the sweep's plans and
// summary. The command line and the Python module (python/artcal_module.cpp) both compile this
// file and build their outputs here, so that their documents are the same. It lives beside the
// commands, not in report/: it runs the planning layer's searches and evaluations (report/ is a
// view over typed results, tests/report/report_includes.cmake).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "artcal/core/error.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/plan/plan.hpp"
#include "artcal/planning/optimizer.hpp"

namespace artcal {

/// `"calibrate": "identifiable"` in a spec: resolved on random placements of the design space
/// (planning/design_identifiability.hpp), from the listed candidates, not from the spec's fixed
/// placements alone (which parsePlan resolved on). Returns how many placements decided (0: no
/// resolution, the spec unchanged).
int resolveOnDesigns(Plan& spec, std::uint64_t seed);

/// The error of a search that found no identifiable design (exit status 1, one line): the
/// parameters to fix when no design of the space can separate them (the union of random
/// placements cannot), otherwise the advice of more placements or postures. `why` is the search's
/// own reason.
RunError unidentifiableDesignError(const Plan& spec, std::uint64_t seed, const std::string& source,
                                   const std::string& why);

/// A criterion value in its display unit (the pass quantities as they are, lengths in mm).
nlohmann::json criterionJson(Criterion criterion, double value);

/// How the optimum compares with its starting designs: `predicted.optimization` of the plan
/// written (criterion values in mm; for "pass" the quantity each value stands for, PassObjective).
nlohmann::json optimizationToJson(const Plan& spec, const OptimizerOptions& options,
                                  const OptimizerSummary& summary);

/// The optimized plan: the spec with the designed placements, its evaluation and the document
/// written (`spec_document` with `placements` and `predicted`).
struct OptimizedPlan {
  Plan plan;
  Evaluation evaluation;
  nlohmann::json document;
};

/// The plan of a finished search on `spec` (resolved by resolveOnDesigns, which decided on
/// `resolved_on` placements). RunError (unidentifiableDesignError) when the search found no
/// design or the rank policy refuses the one it found.
OptimizedPlan optimizedPlan(const nlohmann::json& spec_document, const Plan& spec,
                            const std::string& source, const OptimizerOptions& options,
                            const OptimizerSummary& summary, int resolved_on);

/// A placement sweep's outputs: the summary document (the --json twin), its table, and every
/// file to write into the directory (path, content): one plan per count, summary.json, .txt, .svg.
struct PlacementSweepOutput {
  nlohmann::json summary;
  std::string table;
  std::vector<std::pair<std::string, std::string>> files;
};

/// The sweep of counts `range` ("A..B") on a parsed spec (`spec_document` as read, for the plans
/// written into `directory`); `target` overrides design.target_tip. Every file is checked
/// (checkOutputPath) before the search; nothing is written here. `progress(m, G)` after each
/// count.
PlacementSweepOutput placementSweepOutput(const nlohmann::json& spec_document, const Plan& spec,
                                          const OptimizerOptions& options, const std::string& range,
                                          std::optional<double> target,
                                          const std::string& directory,
                                          std::function<void(int, double)> progress = {});

}  // namespace artcal
