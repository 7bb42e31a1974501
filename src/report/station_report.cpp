#include "artcal/report/station_report.hpp"

#include <cstdio>

#include "artcal/report/report.hpp"

namespace artcal {

namespace {

nlohmann::json summaryToJson(const DeviationSummary& s) {
  return {{"readings", s.count},
          {"mean", finiteOrNull(s.mean)},
          {"rms", finiteOrNull(s.rms)},
          {"max", finiteOrNull(s.max)},
          {"predicted_rms", finiteOrNull(s.predicted_rms)},
          {"predicted_rms_posterior", posteriorOrNull(s.predicted_rms_posterior)}};
}

std::string summaryRow(const std::string& label, int stationing, const DeviationSummary& s) {
  char line[200];
  std::snprintf(line, sizeof line, "%-16s %10d %9d %10.4f %10.4f %10.4f %14.4f", label.c_str(),
                stationing, s.count, s.mean, s.rms, s.max, s.predicted_rms);
  char posterior[32] = "            -";  // no Birge ratio: no posterior (not 0)
  if (s.predicted_rms_posterior > 0.0)
    std::snprintf(posterior, sizeof posterior, " %12.4f", s.predicted_rms_posterior);
  return std::string(line) + posterior + "\n";
}

}  // namespace

nlohmann::json stationsVerificationToJson(const Plan& plan, const StationsVerification& v) {
  nlohmann::json stations = nlohmann::json::array();
  for (const StationVerification& s : v.stations) {
    nlohmann::json entry = summaryToJson(s.summary);
    entry["placement"] = placementLabel(plan.placements, static_cast<std::size_t>(s.placement));
    entry["stationing"] = s.stationing;
    nlohmann::json deviations = nlohmann::json::array();
    for (int i = 0; i < s.deviations.size(); ++i)
      deviations.push_back(finiteOrNull(s.deviations[i]));
    entry["deviations"] = deviations;
    entry["held_out"] = s.held_out;
    if (s.angular) {  // a pose instrument: the angular deviations, deg
      nlohmann::json angular = summaryToJson(*s.angular);
      nlohmann::json angles = nlohmann::json::array();
      for (int i = 0; i < s.angular_deviations.size(); ++i)
        angles.push_back(finiteOrNull(s.angular_deviations[i]));
      angular["deviations"] = angles;
      entry["angular"] = angular;
    }
    stations.push_back(entry);
  }
  nlohmann::json out = {{"stations", stations}, {"all", summaryToJson(v.all)}};
  if (v.angular_all) out["angular_all"] = summaryToJson(*v.angular_all);
  return out;
}

std::string stationsVerificationTable(const Plan& plan, const StationsVerification& v) {
  std::string out =
      "\nheld-out readings of each station (station fitted on its stationing readings; mm)\n"
      "station          stationing  held-out       mean        rms        max  predicted rms"
      "    posterior\n";
  for (const StationVerification& s : v.stations) {
    out += summaryRow(placementLabel(plan.placements, static_cast<std::size_t>(s.placement)),
                      s.stationing, s.summary);
  }
  int stationing = 0;
  for (const StationVerification& s : v.stations) stationing += s.stationing;
  out += summaryRow("all", stationing, v.all);
  if (!v.angular_all) return out;
  out +=
      "\nangular deviations of the held-out poses (orientation residual |log(R_pred R_meas^T)|; "
      "deg)\n"
      "station          stationing  held-out       mean        rms        max  predicted rms"
      "    posterior\n";
  for (const StationVerification& s : v.stations) {
    if (!s.angular) continue;
    out += summaryRow(placementLabel(plan.placements, static_cast<std::size_t>(s.placement)),
                      s.stationing, *s.angular);
  }
  out += summaryRow("all", stationing, *v.angular_all);
  return out;
}

}  // namespace artcal
