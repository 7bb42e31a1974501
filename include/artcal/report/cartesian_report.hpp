#pragma once
// The answers to a CMM lab's questions about a plan of a Cartesian machine (docs/models.md section
// 4), beside the generic check / evaluate output: which frame rotations the placements absorb (a
// property of any artifact calibration, not a defect of the plan), which error functions the plan
// leaves unseparated (named as functions and degrees), and each error function's predicted
// standard uncertainty along its axis. Translations in um and rotations in um/m in tables; in
// JSON translations in mm and rotations in um/m (the parameters' file units).

#include <nlohmann/json.hpp>
#include <string>

#include "artcal/estimation/cartesian_answers.hpp"
#include "artcal/plan/plan.hpp"
#include "artcal/report/html_report.hpp"

namespace artcal {

/// {"frame_rotations_absorbed": [...], "unseparated_functions": [...], "error_functions": [...]}
nlohmann::json cartesianAnswersToJson(const Plan& plan, const CartesianAnswers& answers);
std::string cartesianAnswersTable(const Plan& plan, const CartesianAnswers& answers);

/// The error functions drawn along their axes (`artcal report`, docs/report.md), from
/// errorFunctionBands (error_functions.hpp). Per axis, "error-functions-<axis>-translations" (um)
/// and "error-functions-<axis>-rotations" (um/m): each function's band e(u) +- u_e(u), e = 0 for
/// a plan at nominal (evaluate), the estimate after a calibration (`bands.calibrated`). With the
/// functions at the truth (a simulated machine), also "error-functions-<axis>-recovery":
/// (estimate - truth) / u_e along the axis against +-3. Every curve carries data-function,
/// data-curve (lower, centre, upper, recovery), data-position (mm) and data-value (plotted unit).
std::vector<ReportFigure> errorFunctionFigures(const Plan& plan, const ErrorFunctionBands& bands);

}  // namespace artcal
