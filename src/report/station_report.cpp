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

std::string inFrameRow(const std::string& label, const std::string& frame_of,
                       const DeviationSummary& in_frame, const DeviationSummary& refitted) {
  char line[240];
  std::snprintf(line, sizeof line, "%-16s %-16s %9d %10.4f %10.4f %10.4f %14.4f %10.4f\n",
                label.c_str(), frame_of.c_str(), in_frame.count, in_frame.mean, in_frame.rms,
                in_frame.max, refitted.rms, refitted.max);
  return line;
}

/// The held-out readings of the stations scored in the calibration's frame, beside the same
/// readings re-registered ("" when no station was).
std::string inFrameTable(const Plan& plan, const StationsVerification& v) {
  if (!v.in_frame_all) return {};
  std::string out =
      "\nthe same held-out readings in the calibration's frame (the station calibrate estimated, "
      "not refitted: the instrument stood still; mm)\n"
      "station          frame of          held-out       mean        rms        max  "
      "re-registered rms    max\n";
  for (const StationVerification& s : v.stations) {
    if (!s.in_frame) continue;
    out += inFrameRow(placementLabel(plan.placements, static_cast<std::size_t>(s.placement)),
                      s.in_frame->frame_of, s.in_frame->summary, s.summary);
  }
  out += inFrameRow("all", "", *v.in_frame_all, *v.reregistered_all);
  if (v.in_frame_angular_all) {
    out += "angular deviations (deg)\n";
    for (const StationVerification& s : v.stations) {
      if (!s.in_frame || !s.in_frame->angular || !s.angular) continue;
      out += inFrameRow(placementLabel(plan.placements, static_cast<std::size_t>(s.placement)),
                        s.in_frame->frame_of, *s.in_frame->angular, *s.angular);
    }
    out += inFrameRow("all", "", *v.in_frame_angular_all, *v.reregistered_angular_all);
  }
  return out;
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
    if (s.in_frame) {  // the same readings with the calibration's station, not refitted
      const InFrameDeviations& f = *s.in_frame;
      nlohmann::json in_frame = summaryToJson(f.summary);
      in_frame.erase("predicted_rms");
      in_frame.erase("predicted_rms_posterior");
      in_frame["frame_of"] = f.frame_of;
      nlohmann::json deviations_in_frame = nlohmann::json::array();
      for (int i = 0; i < f.deviations.size(); ++i)
        deviations_in_frame.push_back(finiteOrNull(f.deviations[i]));
      in_frame["deviations"] = deviations_in_frame;
      if (f.angular) {
        nlohmann::json angular = summaryToJson(*f.angular);
        angular.erase("predicted_rms");
        angular.erase("predicted_rms_posterior");
        in_frame["angular"] = angular;
      }
      entry["in_calibration_frame"] = in_frame;
    }
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
  if (v.in_frame_all) {
    auto observed = [](const DeviationSummary& s) {
      nlohmann::json j = summaryToJson(s);
      j.erase("predicted_rms");
      j.erase("predicted_rms_posterior");
      return j;
    };
    nlohmann::json in_frame = {{"all", observed(*v.in_frame_all)},
                               {"reregistered", observed(*v.reregistered_all)}};
    if (v.in_frame_angular_all) {
      in_frame["angular_all"] = observed(*v.in_frame_angular_all);
      in_frame["angular_reregistered"] = observed(*v.reregistered_angular_all);
    }
    out["in_calibration_frame"] = in_frame;
  }
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
  out += inFrameTable(plan, v);
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
