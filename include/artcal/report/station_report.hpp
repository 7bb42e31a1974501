#pragma once
// verify's figures of an instrument's held-out stations (calibration/station_verification.hpp):
// a table per station and in all, and its --json twin.

#include <nlohmann/json.hpp>
#include <string>

#include "artcal/calibration/station_verification.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

nlohmann::json stationsVerificationToJson(const Plan& plan, const StationsVerification& v);
std::string stationsVerificationTable(const Plan& plan, const StationsVerification& v);

}  // namespace artcal
