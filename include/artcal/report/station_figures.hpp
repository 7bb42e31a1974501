#pragma once
// The report's figures of an instrument calibration (instruments.md, "What verify and the
// report give"): per station, the measured points and the residual vectors after the
// calibration; and the histogram of held-out deviations, nominal machine against calibrated.
// A view: the points come from the plan, the residuals from calibrate --json
// (calibrationToJson), the deviations from stationsVerificationToJson of each machine.

#include <nlohmann/json.hpp>
#include <vector>

#include "artcal/plan/plan.hpp"
#include "artcal/report/html_report.hpp"

namespace artcal {

/// One figure "station-<j>" per instrument placement j of `calibration` (calibrate --json of
/// `plan`'s placements): the measured points seen along the station's z axis, each with its
/// residual (predicted - measured) drawn enlarged by the factor its caption states.
std::vector<ReportFigure> stationResidualFigures(const Plan& plan,
                                                 const nlohmann::json& calibration);

/// The figure "held-out-deviations": histograms of the held-out readings' deviations (mm) with
/// the nominal and with the calibrated machine, from {"nominal": ..., "calibrated": ...}, each
/// stationsVerificationToJson of the same held-out plan. Empty when no deviation is finite.
std::vector<ReportFigure> heldOutDeviationFigures(const nlohmann::json& held_out);

}  // namespace artcal
