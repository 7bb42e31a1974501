#pragma once
// Results of `verify` (docs/models.md section 6) as JSON (mm; the fields the spec lists, under
// "verify") and as a human table: per placement, each feature's spread beside its predicted
// spread, the length errors beside their predicted u, the residuals of the rigid fit and the
// readings that stand out.

#include <nlohmann/json.hpp>
#include <string>

#include "artcal/calibration/station_verification.hpp"
#include "artcal/calibration/verification.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// `nominal` (verify --machine): the plan's nominal machine on the same readings, shown beside
/// (JSON "nominal", "worse_than_nominal" and "warnings"; the table's last block).
nlohmann::json verificationToJson(const Plan& plan, const Verification& verification,
                                  const Verification* nominal = nullptr);
/// `outliers`: how many of the largest deviations from their feature's mean to list.
std::string verificationTable(const Plan& plan, const Verification& verification, int outliers = 5,
                              const Verification* nominal = nullptr);
/// The warnings of a machine verified beside the plan's nominal one, each with its figures and
/// what to do: none, or that it does worse than nominal on these readings (worseThanNominal).
std::vector<std::string> besideNominalWarnings(const Verification& calibrated,
                                               const Verification& nominal);

/// True when every placement of `plan` is an instrument station `stations` verified: each reading
/// is then a feature of its own, and the artifact figures (a feature's spread over its postures,
/// the lengths between features) say nothing; verify reports the stations alone.
bool onlyStations(const Plan& plan, const StationsVerification& stations);
/// `artcal verify --json`'s document (and Python's Plan.verify): the artifact figures of
/// `artifacts` with the stations' under "instrument", or, for a plan of stations alone
/// (`artifacts` null), the plan's name and the stations' figures.
nlohmann::json verifyDocument(const Plan& plan, const StationsVerification& stations,
                              const Verification* artifacts, const Verification* nominal = nullptr);

}  // namespace artcal
