#pragma once
// Results as JSON (file units: mm, deg; the fields docs/plan-format.md promises) and as human
// tables. Every result has both: the table for a person, the JSON twin for a script.

#include <nlohmann/json.hpp>
#include <string>

#include "artcal/calibration/calibrate_readings.hpp"
#include "artcal/calibration/unmodelled_error.hpp"
#include "artcal/estimation/cartesian_answers.hpp"
#include "artcal/estimation/evaluation_result.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// A number for JSON: non-finite values become null (JSON has no NaN or infinity).
nlohmann::json finiteOrNull(double value);
/// A posterior figure: it exists only when the calibration's Birge ratio is known (the figure is
/// then > 0); null otherwise, never 0.0 (docs/hardening.md, values that do not exist).
nlohmann::json posteriorOrNull(double value);

/// Joint values in file units (deg or mm).
std::vector<double> jointsToFile(const Machine& machine, const Eigen::VectorXd& q);

nlohmann::json countingToJson(const CountingCondition& counting);
nlohmann::json identifiabilityToJson(const Identifiability& identifiability);
/// "calibrate_resolved", "calibrate_dropped", "calibrate_ties" of a plan whose calibrate was
/// "identifiable" (docs/models.md section 1); an empty object otherwise.
nlohmann::json calibrateSelectionToJson(const Plan& plan);
nlohmann::json tipToJson(const Machine& machine, const TipSummary& tip,
                         const std::vector<Eigen::VectorXd>& workspace);
nlohmann::json evaluationToJson(const Plan& plan, const Evaluation& evaluation);
/// The probe noise a prediction used (calibration/calibrate_readings.hpp, PredictionNoise):
/// {"value", "unit": "mm", "estimated", "source"}.
nlohmann::json predictionNoiseToJson(double value, bool estimated, const std::string& source);
/// The tip map with the unmodelled error (unmodelled_error.hpp, tipWithUnmodelled):
/// {"sigma", "trace_share", "worst_total", "mean_total", "rms_total", "unit": "mm", "scheme",
/// "folds"}, and its table: two lines in um.
nlohmann::json tipWithUnmodelledToJson(const TipWithUnmodelled& tip, const UnmodelledError& from);
/// `artcal evaluate --json`'s document, for the command line and Python alike: the evaluation,
/// the Cartesian answers (cartesianAnswers of that evaluation), "probe_noise" and, where the
/// readings told it, "tip_with_unmodelled".
nlohmann::json evaluateCommandToJson(const NoisedEvaluation& noised, const CartesianAnswers& cmm);
std::string tipWithUnmodelledTable(const TipWithUnmodelled& tip, const UnmodelledError& from);

/// How a dropped parameter is tied to the kept ones (`tie`: the dropped one first, then the
/// kept ones with their scaled coefficients): "not observed, ..." when alone, otherwise the
/// combination the plan cannot tell from zero ("+1 L  -0.92 E_Z0A   (scaled parameters)").
std::string tieText(const Plan& plan, const std::vector<std::pair<int, double>>& tie);

std::string identifiabilityTable(const Plan& plan, const Identifiability& identifiability);
std::string evaluationTable(const Plan& plan, const Evaluation& evaluation);
/// One line: the dropped parameters to fix, each with its tie, and the kept ones to calibrate
/// (the `fix:` advice for a set no plan or design identifies).
std::string calibrateFixText(const Plan& plan, const CalibratedSetResolution& resolution);

}  // namespace artcal
