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
          {"predicted_rms_posterior", posteriorOrNull(s.predicted_rms_posterior)},
          {"predicted_rms_unmodelled", finiteOrNull(s.predicted_rms_unmodelled)},
          {"predicted_rms_total", finiteOrNull(s.predicted_rms_total)}};
}

std::string summaryRow(const std::string& label, int stationing, const DeviationSummary& s) {
  char line[200];
  std::snprintf(line, sizeof line, "%-16s %10d %9d %10.4f %10.4f %10.4f %14.4f", label.c_str(),
                stationing, s.count, s.mean, s.rms, s.max, s.predicted_rms);
  char posterior[32] = "            -";  // no Birge ratio: no posterior (not 0)
  if (s.predicted_rms_posterior > 0.0)
    std::snprintf(posterior, sizeof posterior, " %12.4f", s.predicted_rms_posterior);
  char total[48] = "";
  if (s.predicted_rms_total > 0.0)
    std::snprintf(total, sizeof total, " %10.4f %10.4f", s.predicted_rms_unmodelled,
                  s.predicted_rms_total);
  return std::string(line) + posterior + total + "\n";
}

std::string inFrameRow(const std::string& label, const std::string& frame_of,
                       const DeviationSummary& in_frame, const DeviationSummary& refitted) {
  char line[240];
  std::snprintf(line, sizeof line, "%-16s %-16s %9d %10.4f %10.4f %10.4f %14.4f %10.4f",
                label.c_str(), frame_of.c_str(), in_frame.count, in_frame.mean, in_frame.rms,
                in_frame.max, refitted.rms, refitted.max);
  std::string out = line;
  if (in_frame.predicted_rms_total > 0.0) {  // the predicted totals in each frame
    std::snprintf(line, sizeof line, " %15.4f %16.4f", in_frame.predicted_rms_total,
                  refitted.predicted_rms_total);
    out += line;
  }
  return out + "\n";
}

/// The held-out readings of the stations scored in the calibration's frame, beside the same
/// readings re-registered ("" when no station was).
std::string inFrameTable(const Plan& plan, const StationsVerification& v) {
  if (!v.in_frame_all) return {};
  std::string out =
      "\nthe same held-out readings in the calibration's frame (the station calibrate estimated, "
      "not refitted: the instrument stood still; mm)\n"
      "station          frame of          held-out       mean        rms        max  "
      "re-registered rms    max" +
      std::string(v.in_frame_all->predicted_rms_total > 0.0 ? "  predicted total  re-registered"
                                                            : "") +
      "\n";
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
      in_frame["frame_of"] = f.frame_of;
      nlohmann::json deviations_in_frame = nlohmann::json::array();
      for (int i = 0; i < f.deviations.size(); ++i)
        deviations_in_frame.push_back(finiteOrNull(f.deviations[i]));
      in_frame["deviations"] = deviations_in_frame;
      if (f.angular) {
        in_frame["angular"] = summaryToJson(*f.angular);
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
    nlohmann::json in_frame = {{"all", summaryToJson(*v.in_frame_all)},
                               {"reregistered", summaryToJson(*v.reregistered_all)}};
    if (v.in_frame_angular_all) {
      in_frame["angular_all"] = summaryToJson(*v.in_frame_angular_all);
      in_frame["angular_reregistered"] = summaryToJson(*v.reregistered_angular_all);
    }
    out["in_calibration_frame"] = in_frame;
  }
  return out;
}

std::string stationsVerificationTable(const Plan& plan, const StationsVerification& v) {
  std::string out =
      "\nheld-out readings of each station (station fitted on its stationing readings; mm)\n"
      "station          stationing  held-out       mean        rms        max  predicted rms"
      "    posterior" +
      std::string(v.all.predicted_rms_total > 0.0 ? " unmodelled      total" : "") + "\n";
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
      "    posterior" +
      std::string(v.all.predicted_rms_total > 0.0 ? " unmodelled      total" : "") + "\n";
  for (const StationVerification& s : v.stations) {
    if (!s.angular) continue;
    out += summaryRow(placementLabel(plan.placements, static_cast<std::size_t>(s.placement)),
                      s.stationing, *s.angular);
  }
  out += summaryRow("all", stationing, *v.angular_all);
  return out;
}

}  // namespace artcal
