#include "artcal/report/verification_report.hpp"
#include "artcal/report/text_format.hpp"

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <sstream>

#include "artcal/report/report.hpp"
#include "artcal/report/station_report.hpp"

namespace artcal {

using nlohmann::json;

namespace {

using report_text::fixed;

json featureToJson(const FeatureSpread& f) {
  return {{"feature", f.feature},
          {"postures", f.postures},
          {"spread_mean", finiteOrNull(f.spread_mean)},
          {"spread_rms", finiteOrNull(f.spread_rms)},
          {"predicted_spread_rms", finiteOrNull(f.predicted_spread_rms)},
          {"predicted_spread_rms_posterior", posteriorOrNull(f.predicted_spread_rms_posterior)},
          {"predicted_spread_rms_unmodelled", finiteOrNull(f.predicted_spread_rms_unmodelled)},
          {"predicted_spread_rms_total", finiteOrNull(f.predicted_spread_rms_total)},
          {"mean_position", std::vector<double>(f.mean.data(), f.mean.data() + f.mean.size())}};
}

/// A plane's flush-touch figures: height mm, roll and pitch deg (docs/planes.md, "verify").
json flushToJson(const FlushFigures& f) {
  return {{"touches", f.touches},
          {"height_rms", finiteOrNull(f.height_rms)},
          {"roll_rms_deg", finiteOrNull(radToDeg(f.roll_rms))},
          {"pitch_rms_deg", finiteOrNull(radToDeg(f.pitch_rms))}};
}

json placementToJson(const Plan& plan, const PlacementVerification& v) {
  json features = json::array();
  for (const FeatureSpread& f : v.features) features.push_back(featureToJson(f));
  json lengths = json::array();
  for (const LengthError& e : v.length_errors) {
    lengths.push_back({{"from", e.from},
                       {"to", e.to},
                       {"error", finiteOrNull(e.error)},
                       {"predicted_u", finiteOrNull(e.predicted_u)},
                       {"predicted_u_posterior", posteriorOrNull(e.predicted_u_posterior)}});
  }
  json out = {{"index", v.index},
              {"features", features},
              {"length_errors", lengths},
              {"residual_rms", finiteOrNull(v.residual_rms)},
              {"residual_max", finiteOrNull(v.residual_max)}};
  const std::string& name = plan.placements[static_cast<std::size_t>(v.index)].name;
  if (!name.empty()) out["name"] = name;
  if (v.in_frame) {  // the same residuals with the calibration's placement, not refitted
    out["in_calibration_frame"] = {{"frame_of", v.in_frame->frame_of},
                                   {"residual_rms", finiteOrNull(v.in_frame->residual_rms)},
                                   {"residual_max", finiteOrNull(v.in_frame->residual_max)}};
    if (v.in_frame->flush) out["in_calibration_frame"]["flush"] = flushToJson(*v.in_frame->flush);
  }
  if (v.flush) out["flush"] = flushToJson(*v.flush);
  return out;
}

/// The placement column of the tables: each placement's label, right-aligned in a column at
/// least as wide as the "placement" heading.
int labelWidth(const Plan& plan) {
  std::size_t width = 9;
  for (std::size_t j = 0; j < plan.placements.size(); ++j)
    width = std::max(width, placementLabel(plan.placements, j).size());
  return static_cast<int>(width);
}

std::string label(const Plan& plan, int index, int width) {
  const std::string text = placementLabel(plan.placements, static_cast<std::size_t>(index));
  return std::string(static_cast<std::size_t>(std::max(0, width - static_cast<int>(text.size()))),
                     ' ') +
         text;
}

/// A plane's flush touches per placement: height and tilts with the placement refitted and, where
/// the calibration's frame scores it, in that frame (the plane stayed where it was).
std::string flushTable(const Plan& plan, const Verification& verification,
                       const std::string& heading, int width) {
  std::ostringstream out;
  out << "\nflush touches: RMS of the height (mm) and of the tool's tilts against the face (deg) "
         "about its own x (roll) and y (pitch)\n"
      << heading
      << " touches   height   roll  pitch   in the calibration's frame: height   "
         "roll  pitch\n";
  auto row = [](const FlushFigures& f) {
    char text[80];
    std::snprintf(text, sizeof text, " %8.4f %6.3f %6.3f", f.height_rms, radToDeg(f.roll_rms),
                  radToDeg(f.pitch_rms));
    return std::string(text);
  };
  for (const PlacementVerification& v : verification.placements) {
    if (!v.flush) continue;
    char count[16];
    std::snprintf(count, sizeof count, " %7d", v.flush->touches);
    out << label(plan, v.index, width) << count << row(*v.flush);
    if (v.in_frame && v.in_frame->flush)
      out << "   (" << v.in_frame->frame_of << ")" << row(*v.in_frame->flush);
    out << "\n";
  }
  out << "  all placements: height " << fixed(verification.flush->height_rms, 4) << " mm, roll "
      << fixed(radToDeg(verification.flush->roll_rms), 3) << " deg, pitch "
      << fixed(radToDeg(verification.flush->pitch_rms), 3) << " deg";
  if (verification.flush_in_frame)
    out << "; in the calibration's frames: height "
        << fixed(verification.flush_in_frame->height_rms, 4) << " mm, roll "
        << fixed(radToDeg(verification.flush_in_frame->roll_rms), 3) << " deg, pitch "
        << fixed(radToDeg(verification.flush_in_frame->pitch_rms), 3) << " deg";
  out << "\n";
  return out.str();
}

/// A reading's place for a person: placement, feature, the how-many-th posture of that feature
/// in the placement (from 0, as placements, readings and the procedure's postures are) and, for a
/// reading from a CSV file, the file and its data row (which differs from the posture once rows are
/// excluded).
struct ReadingPlace {
  int placement, measurement, feature, posture;
  double deviation, residual;
  std::string csv;
  int csv_row;
};

std::vector<ReadingPlace> largestDeviations(const Plan& plan, const Verification& verification,
                                            int count) {
  std::vector<ReadingPlace> all;
  for (const PlacementVerification& v : verification.placements) {
    const auto& measurements = plan.placements[static_cast<std::size_t>(v.index)].measurements;
    std::vector<int> posture_of_feature;
    for (std::size_t i = 0; i < measurements.size(); ++i) {
      const int feature = measurements[i].feature;
      if (feature >= static_cast<int>(posture_of_feature.size()))
        posture_of_feature.resize(static_cast<std::size_t>(feature) + 1, 0);
      const int posture = posture_of_feature[static_cast<std::size_t>(feature)]++;
      all.push_back({v.index, static_cast<int>(i), feature, posture,
                     v.deviations[static_cast<int>(i)], v.residuals[static_cast<int>(i)],
                     measurements[i].csv, measurements[i].csv_row});
    }
  }
  const auto n = std::min<std::size_t>(all.size(), static_cast<std::size_t>(std::max(count, 0)));
  std::partial_sort(
      all.begin(), all.begin() + static_cast<long>(n), all.end(),
      [](const ReadingPlace& a, const ReadingPlace& b) { return a.deviation > b.deviation; });
  all.resize(n);
  return all;
}

json overallFiguresToJson(const Verification& v) {
  return {{"spread_mean", finiteOrNull(v.spread_mean)},
          {"spread_rms", finiteOrNull(v.spread_rms)},
          {"length_error_mean_abs", finiteOrNull(v.length_error_mean_abs)},
          {"length_error_rms", finiteOrNull(v.length_error_rms)},
          {"residual_rms", finiteOrNull(v.residual_rms)}};
}

}  // namespace

std::vector<std::string> besideNominalWarnings(const Verification& calibrated,
                                               const Verification& nominal) {
  std::vector<std::string> warnings;
  if (const std::vector<std::string> worse = worseThanNominal(calibrated, nominal);
      !worse.empty()) {
    std::ostringstream out;
    out << "on these readings the calibrated machine does worse than the plan's nominal one (";
    const char* separator = "";
    for (const ComparedFigure& figure : kComparedFigures) {
      if (std::find(worse.begin(), worse.end(), figure.name) == worse.end()) continue;
      out << separator << figure.words << " " << fixed(calibrated.*figure.value, 3) << " mm > "
          << fixed(nominal.*figure.value, 3) << " mm";
      separator = ", ";
    }
    out << "): the calibration does not hold here; calibrate with readings from more artifact "
           "positions spread over the workspace (one position determines the machine only near "
           "it), and compare the posterior prediction with the spread observed";
    warnings.push_back(out.str());
  }
  return warnings;
}

json verificationToJson(const Plan& plan, const Verification& verification,
                        const Verification* nominal) {
  json placements = json::array();
  for (const PlacementVerification& v : verification.placements)
    placements.push_back(placementToJson(plan, v));
  json verify = {
      {"placements", placements},
      {"spread_rms", finiteOrNull(verification.spread_rms)},
      {"spread_mean", finiteOrNull(verification.spread_mean)},
      {"predicted_spread_rms", finiteOrNull(verification.predicted_spread_rms)},
      {"predicted_spread_rms_posterior",
       posteriorOrNull(verification.predicted_spread_rms_posterior)},
      {"predicted_spread_rms_unmodelled",
       finiteOrNull(verification.predicted_spread_rms_unmodelled)},
      {"predicted_spread_rms_total", finiteOrNull(verification.predicted_spread_rms_total)},
      {"unmodelled_error", finiteOrNull(verification.unmodelled)},
      {"birge_ratio", posteriorOrNull(verification.birge_ratio)},
      {"posterior_probe_noise", posteriorOrNull(verification.posterior_probe_noise)},
      {"predicted_from_calibration", verification.predicted},
      {"length_error_rms", finiteOrNull(verification.length_error_rms)},
      {"length_error_mean_abs", finiteOrNull(verification.length_error_mean_abs)},
      {"residual_rms", finiteOrNull(verification.residual_rms)}};
  json largest = json::array();
  for (const ReadingPlace& r : largestDeviations(plan, verification, 10)) {
    json entry = {{"placement", r.placement},
                  {"measurement", r.measurement},
                  {"feature", r.feature},
                  {"posture", r.posture},
                  {"deviation", finiteOrNull(r.deviation)},
                  {"residual", finiteOrNull(r.residual)}};
    const std::string& name = plan.placements[static_cast<std::size_t>(r.placement)].name;
    if (!name.empty()) entry["name"] = name;
    if (r.csv_row > 0) {
      entry["csv"] = r.csv;
      entry["csv_row"] = r.csv_row;
    }
    largest.push_back(entry);
  }
  verify["largest_deviations"] = largest;
  if (verification.in_frame_placements > 0) {
    verify["in_calibration_frame"] = {
        {"placements", verification.in_frame_placements},
        {"residual_rms", finiteOrNull(verification.in_frame_residual_rms)},
        {"reregistered_residual_rms", finiteOrNull(verification.reregistered_residual_rms)}};
    if (verification.flush_in_frame)
      verify["in_calibration_frame"]["flush"] = flushToJson(*verification.flush_in_frame);
  }
  if (verification.flush) verify["flush"] = flushToJson(*verification.flush);
  if (nominal) {
    verify["nominal"] = overallFiguresToJson(*nominal);
    verify["worse_than_nominal"] = worseThanNominal(verification, *nominal);
    verify["warnings"] = besideNominalWarnings(verification, *nominal);
  }
  return {{"plan", plan.name}, {"verify", verify}};
}

std::string verificationTable(const Plan& plan, const Verification& verification, int outliers,
                              const Verification* nominal) {
  std::ostringstream out;
  out << "Plan " << plan.name << ": " << verification.placements.size()
      << " placements verified, parameters held fixed (mm)\n";
  out << "  predicted spread from "
      << (verification.predicted ? "the calibration's V_p and the reading noise"
                                 : "the reading noise alone (no covariance given)")
      << "\n";
  const bool posterior = verification.birge_ratio > 0.0;
  if (posterior) {
    if (verification.posterior_probe_noise > 0.0) {
      out << "  posterior: with the probe noise the calibration estimated, "
          << fixed(verification.posterior_probe_noise, 4) << " mm (this plan states "
          << fixed(plan.noise.probe, 4) << " mm), times its Birge ratio "
          << fixed(verification.birge_ratio, 3)
          << " (for readings that scatter as the calibration's did)\n";
    } else {
      out << "  posterior: times the calibration's Birge ratio "
          << fixed(verification.birge_ratio, 3)
          << " (for readings that scatter as the calibration's did)\n";
    }
  }
  const int width = labelWidth(plan);
  const std::string heading = std::string(static_cast<std::size_t>(width - 9), ' ') + "placement";
  out << "\n"
      << heading << " feature postures  spread_mean  spread_rms  predicted_rms"
      << (posterior ? "  posterior_rms" : "") << "\n";
  for (const PlacementVerification& v : verification.placements) {
    for (const FeatureSpread& f : v.features) {
      char line[160];
      std::snprintf(line, sizeof line, " %7d %8d %12.4f %11.4f %14.4f", f.feature, f.postures,
                    f.spread_mean, f.spread_rms, f.predicted_spread_rms);
      out << label(plan, v.index, width) << line;
      if (posterior) {
        std::snprintf(line, sizeof line, " %14.4f", f.predicted_spread_rms_posterior);
        out << line;
      }
      out << "\n";
    }
  }
  out << "\n"
      << heading << "  from  to   length error   predicted u" << (posterior ? "   posterior u" : "")
      << "   residual rms   residual max\n";
  for (const PlacementVerification& v : verification.placements) {
    for (const LengthError& e : v.length_errors) {
      char line[160];
      std::snprintf(line, sizeof line, " %5d %3d %14.4f %13.4f", e.from, e.to, e.error,
                    e.predicted_u);
      out << label(plan, v.index, width) << line;
      if (posterior) {
        std::snprintf(line, sizeof line, " %13.4f", e.predicted_u_posterior);
        out << line;
      }
      std::snprintf(line, sizeof line, " %14.4f %14.4f\n", v.residual_rms, v.residual_max);
      out << line;
    }
  }
  out << "\nall placements\n"
      << "  spread mean " << fixed(verification.spread_mean, 4) << "   spread rms "
      << fixed(verification.spread_rms, 4) << "   predicted rms "
      << fixed(verification.predicted_spread_rms, 4);
  if (posterior)
    out << "   posterior rms " << fixed(verification.predicted_spread_rms_posterior, 4);
  if (verification.predicted)
    out << "\n  with the unmodelled error (" << fixed(verification.unmodelled, 4)
        << " mm per coordinate, the calibration's cross-validation): its share "
        << fixed(verification.predicted_spread_rms_unmodelled, 4) << "   predicted total rms "
        << fixed(verification.predicted_spread_rms_total, 4);
  out << "\n"
      << "  length error mean |e| " << fixed(verification.length_error_mean_abs, 4) << "   rms "
      << fixed(verification.length_error_rms, 4) << "\n"
      << "  residual rms " << fixed(verification.residual_rms, 4) << "\n";
  if (verification.flush) out << flushTable(plan, verification, heading, width);
  if (verification.in_frame_placements > 0) {
    out << "\nresiduals in the calibration's frame (the placement calibrate estimated, not "
           "refitted: the artifact stayed where it was)\n"
        << heading
        << "  frame of          residual rms   residual max   re-registered rms    max\n";
    for (const PlacementVerification& v : verification.placements) {
      if (!v.in_frame) continue;
      char line[200];
      std::snprintf(line, sizeof line, "  %-16s %13.4f %14.4f %19.4f %6.4f\n",
                    v.in_frame->frame_of.c_str(), v.in_frame->residual_rms,
                    v.in_frame->residual_max, v.residual_rms, v.residual_max);
      out << label(plan, v.index, width) << line;
    }
    out << "  in the calibration's frame: residual rms "
        << fixed(verification.in_frame_residual_rms, 4) << "   re-registered "
        << fixed(verification.reregistered_residual_rms, 4) << "\n";
  }
  if (nominal) {
    out << "\nthe plan's nominal machine on the same readings\n"
        << "  spread mean " << fixed(nominal->spread_mean, 4) << "   spread rms "
        << fixed(nominal->spread_rms, 4) << "\n"
        << "  length error mean |e| " << fixed(nominal->length_error_mean_abs, 4) << "   rms "
        << fixed(nominal->length_error_rms, 4) << "\n"
        << "  residual rms " << fixed(nominal->residual_rms, 4) << "\n";
  }
  const std::vector<ReadingPlace> largest = largestDeviations(plan, verification, outliers);
  if (!largest.empty()) {
    out << "\nlargest deviations from their feature's mean (posture k: reading k of the "
           "feature in its placement, from 0; a CSV reading's file and data row, as "
           "\"exclude_rows\" "
           "counts them)\n";
    for (const ReadingPlace& r : largest) {
      char line[200];
      std::snprintf(line, sizeof line,
                    "  placement %s feature %d posture %d (measurement %d): %.4f mm from the "
                    "mean, residual %.4f mm",
                    placementLabel(plan.placements, static_cast<std::size_t>(r.placement)).c_str(),
                    r.feature, r.posture, r.measurement, r.deviation, r.residual);
      out << line;
      if (r.csv_row > 0) out << ", " << r.csv << " row " << r.csv_row;
      out << "\n";
    }
  }
  return out.str();
}

bool onlyStations(const Plan& plan, const StationsVerification& stations) {
  return !stations.stations.empty() && stations.stations.size() == plan.placements.size();
}

json verifyDocument(const Plan& plan, const StationsVerification& stations,
                    const Verification* artifacts, const Verification* nominal) {
  json out = artifacts ? verificationToJson(plan, *artifacts, nominal) : json{{"plan", plan.name}};
  if (!stations.stations.empty()) out["instrument"] = stationsVerificationToJson(plan, stations);
  return out;
}

}  // namespace artcal
