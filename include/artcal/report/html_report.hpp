#pragma once
// The self-contained HTML report of a plan (`artcal report`): one file with inline SVG figures
// and CSS, no scripts, nothing fetched; it prints on A4.
//
// It shows what the evaluator computed and computes nothing itself (a view over typed results:
// the Evaluation, its JSON, the Procedure): every number in a table or figure is read from
// evaluationToJson (report.hpp), the document `artcal evaluate --json` prints, and carries that
// document's JSON pointer and exact value as data-field="/tip/worst/total" data-value="0.0118..."
// so that a script (and the tests) can check that the report and `evaluate --json` agree.
//
// Figures: the layout (machine reach, artifact placements, postures; 3-D: plan XY and side XZ
// views), tip uncertainty (planar2r: S_m, S_q, S against reach, seed Fig. 6; every model: a map
// of S over the workspace with the worst point marked), the correlation matrix as a heat map;
// with a calibration, its standardised residuals with the flagged outliers.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "artcal/estimation/evaluation_result.hpp"
#include "artcal/plan/plan.hpp"
#include "artcal/planning/procedure_result.hpp"

namespace artcal {

struct ReportFigure {
  std::string name;     ///< file stem for --svg, e.g. "layout"
  std::string caption;  ///< one sentence under the figure
  std::string svg;      ///< a complete <svg> element
};

/// What the report shows. `document` is the plan file as read, for the blocks the typed Plan
/// does not keep (an optimized plan's `predicted`); `evaluation_json` is
/// evaluationToJson(plan, evaluation).
struct ReportInput {
  const Plan& plan;
  const nlohmann::json& document;
  const Evaluation& evaluation;
  const nlohmann::json& evaluation_json;
  /// calibrationToJson (calibration_report.hpp) of the plan's readings, when they are to be
  /// shown; its numbers carry data-field pointers prefixed "/calibration".
  const nlohmann::json* calibration_json = nullptr;
  double flag_threshold = 3.0;  ///< the calibrator's, drawn on the residual plot
  /// planAcceptanceToJson (acceptance_report.hpp) of the plan's acceptance test, when it names
  /// one: its P(pass), quantiles and (ISO 9283) points are tabled, with data-field pointers
  /// prefixed "/acceptance".
  const nlohmann::json* acceptance_json = nullptr;
  /// The operator's procedure (planning/procedure.hpp, operatorProcedure), or null with
  /// `no_procedure` saying why there is none (no joint values reach a placed feature); both
  /// empty: no procedure section.
  const Procedure* procedure = nullptr;
  std::string no_procedure = {};
  /// An instrument plan's held-out stations verified with the nominal and the calibrated
  /// machine: {"plan": FILE, "nominal": ..., "calibrated": ...}, each stationsVerificationToJson
  /// (station_report.hpp); tabled with data-field pointers prefixed "/held_out".
  const nlohmann::json* held_out_json = nullptr;
};

/// The report's figures, in the order the report shows them.
std::vector<ReportFigure> reportFigures(const ReportInput& input);

/// The whole HTML page, with `figures` (from reportFigures) inline.
std::string htmlReport(const ReportInput& input, const std::vector<ReportFigure>& figures);

}  // namespace artcal
