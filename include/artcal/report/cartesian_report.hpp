#pragma once
// The answers to a CMM lab's questions about a plan of a Cartesian machine (docs/models.md section
// 4), beside the generic check / evaluate output: which frame rotations the placements absorb (a
// property of any artifact calibration, not a defect of the plan), which error functions the plan
// leaves unseparated (named as functions and degrees), and each error function's predicted
// standard uncertainty along its axis. Translations in um and rotations in um/m in tables; in
// JSON translations in mm and rotations in um/m (the parameters' file units).

#include <nlohmann/json.hpp>
#include <string>

#include "artcal/estimation/error_functions.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/plan/plan.hpp"
#include "artcal/report/html_report.hpp"

namespace artcal {

/// The plan's machine as a Cartesian CMM, or null for other models.
const Cartesian* cartesianOf(const Plan& plan);

/// What check and evaluate answer for a Cartesian CMM; empty for other models.
struct CartesianAnswers {
  std::vector<AbsorbedRotation> absorbed;
  std::vector<std::string> held_by_frame;  ///< per absorbed rotation, the parameter it fixes
  struct Unseparated {
    std::string function;  ///< "z.rx"
    std::string meaning;   ///< "tilt about x"
    std::vector<int> degrees;
  };
  std::vector<Unseparated> unseparated;
  std::vector<ErrorFunctionProfile> profiles;  ///< evaluate only (needs V_p)
};

/// `evaluation` may be null (check): then no profiles.
CartesianAnswers cartesianAnswers(const Plan& plan, const Evaluation* evaluation,
                                  int profile_steps = 11);
/// {"frame_rotations_absorbed": [...], "unseparated_functions": [...], "error_functions": [...]}
nlohmann::json cartesianAnswersToJson(const Plan& plan, const CartesianAnswers& answers);
std::string cartesianAnswersTable(const Plan& plan, const CartesianAnswers& answers);

/// The error functions drawn along their axes (`artcal report`, docs/report.md), from
/// errorFunctionProfiles of V_p and p. Per axis, "error-functions-<axis>-translations" (um) and
/// "error-functions-<axis>-rotations" (um/m): each function's band e(u) +- u_e(u), e = 0 for a
/// plan at nominal (evaluate), the estimate after a calibration (`calibrated`). With `truth`
/// (the simulated machine's full parameter vector), also "error-functions-<axis>-recovery":
/// (estimate - truth) / u_e along the axis against +-3. Every curve carries data-function,
/// data-curve (lower, centre, upper, recovery), data-position (mm) and data-value (plotted unit).
std::vector<ReportFigure> errorFunctionFigures(const Plan& plan, const Eigen::MatrixXd& V,
                                               const Eigen::VectorXd& p, bool calibrated,
                                               const Eigen::VectorXd* truth = nullptr,
                                               int steps = 21);

}  // namespace artcal
