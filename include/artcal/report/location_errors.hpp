#pragma once
// The machine-tool engineer's answers (docs/five-axis.md), for models whose parameters are ISO
// 230-7 location errors (Mechanism::hasLocationErrors): each location error with u in deg and
// urad or mm and um and the confounding index F_k; after a calibration, the controller table (one
// row per entry: determined, dropped or held, its value, u and U = 2 u; the table's kind and its
// chained form).

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "artcal/estimation/evaluation_result.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// The location errors with u (and the estimate when `estimate` is not null, a full parameter
/// vector) and F_k, and the hint "F <= 2: well separated".
std::string locationErrorTable(const Plan& plan, const ParameterCovariance& covariance,
                               const Eigen::VectorXd* estimate);
nlohmann::json locationErrorsToJson(const Plan& plan, const ParameterCovariance& covariance,
                                    const Eigen::VectorXd* estimate);
/// What the calibration says of one controller-table entry (docs/five-axis.md section 5).
enum class EntryStatus {
  Determined,  ///< calibrated: its value is measured, with u
  Dropped,     ///< left out by the rank rule: the plan cannot separate it (tied to kept ones)
  Held,        ///< not calibrated otherwise: weakly determined, or fixed by the plan's list
};
/// "determined", "dropped", "held".
std::string entryStatusName(EntryStatus status);

/// One entry of the controller table: a location error or the tool length.
struct ControllerEntry {
  int parameter = -1;  ///< model parameter index
  std::string name;    ///< "E_Y0A", "L"
  std::string axis;    ///< "A", "B", "C", "X", "Y", "Z" or "tool"
  std::string entry;   ///< what it is: "Y offset", "tilt about Y", "zero", ...
  EntryStatus status = EntryStatus::Held;
  double value = 0.0;  ///< file units: the model's value (measured only when determined)
  double u = 0.0;      ///< file units, standard uncertainty; 0 unless determined
  std::string unit;    ///< "mm" or "deg"
  std::vector<std::string> tied_to;  ///< dropped: the kept parameters it trades against
  /// Dropped or held: why, and what to do; determined: what else it carries (a dropped one tied
  /// to it), else empty.
  std::string note;
};

/// The entries of the controller table in the model's parameter order; `covariance` (over
/// plan.machine.calibrated) gives the determined entries' u (null: 0).
std::vector<ControllerEntry> controllerEntries(const Plan& plan, const Eigen::VectorXd& parameters,
                                               const ParameterCovariance* covariance);

/// The coverage factor of the tables' expanded uncertainty U = k u.
inline constexpr double kCoverageFactor = 2.0;

/// The controller table of the full parameter vector `parameters` (internal units): its kind
/// (actual location; a correction table negates), the chained form, and one row per entry with
/// its status, value, u and U (k = 2); undetermined entries print no value.
std::string controllerTable(const Plan& plan, const Eigen::VectorXd& parameters,
                            const ParameterCovariance* covariance);
/// Its JSON twin: "kind", "coverage_factor", "chained_form", "entries", and the per-axis rows
/// "axes" (values with each cell's "status") and "tool_length_mm" kept from earlier versions.
nlohmann::json controllerTableToJson(const Plan& plan, const Eigen::VectorXd& parameters,
                                     const ParameterCovariance* covariance);

}  // namespace artcal
