#pragma once
// Results of `acceptance` (docs/method.md section 9) as JSON, human tables and the E-against-L
// figure. Lengths, ends and joints in file units (mm, deg); E's standard deviations and the MPE in
// um in the fields ending `_um` and in the tables (the items also carry `sigma_sys`, `sigma_noise`,
// `sigma_total` in mm, the reference's fields).

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "artcal/acceptance/length_acceptance.hpp"
#include "artcal/acceptance/plan_acceptance.hpp"
#include "artcal/acceptance/pose_acceptance.hpp"
#include "artcal/report/html_report.hpp"

namespace artcal {

/// One warning per parameter taken as exact that some results depend on, naming the lines.
std::vector<std::string> unseenParameterWarnings(const AcceptanceInput& input,
                                                 const LengthTestPrediction& prediction);

nlohmann::json lengthTestToJson(const AcceptanceInput& input,
                                const LengthTestPrediction& prediction,
                                const MonteCarloOptions& options);
std::string lengthTestTable(const AcceptanceInput& input, const LengthTestPrediction& prediction,
                            const MonteCarloOptions& options);
/// E against L as a datasheet draws it: each gauge's predicted 95 % band (+-1.96 sigma_total,
/// um), the +-MPE lines.
std::string lengthTestSvg(const LengthTestPrediction& prediction);

/// The report's "acceptance" figure (`artcal report`) of the plan's ISO 10360-2 test (its
/// "acceptance" block, predicted by predictPlanAcceptance): the E-against-L figure, P(pass) in
/// its caption. std::nullopt for an ISO 9283 test (the report shows its points as a table).
std::optional<ReportFigure> acceptanceReportFigure(const PlanAcceptance& acceptance);

/// The plan's test as `artcal acceptance PLAN --json` prints it (lengthTestToJson or
/// poseTestToJson), and its table.
nlohmann::json planAcceptanceToJson(const PlanAcceptance& acceptance);
std::string planAcceptanceTable(const PlanAcceptance& acceptance);

nlohmann::json poseTestToJson(const AcceptanceInput& input, const PoseTestPrediction& prediction,
                              const PoseTestOptions& options);
std::string poseTestTable(const AcceptanceInput& input, const PoseTestPrediction& prediction,
                          const PoseTestOptions& options);

}  // namespace artcal
