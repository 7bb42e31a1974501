#include "artcal/report/acceptance_report.hpp"
#include "artcal/report/text_format.hpp"

#include <cstdio>
#include <sstream>

#include "artcal/core/units.hpp"
#include "artcal/report/report.hpp"
#include "artcal/report/svg.hpp"

namespace artcal {

using nlohmann::json;

namespace {

constexpr double kCoverage95 = 1.959963984540054;

using report_text::fixed;

json vectorJson(const Eigen::VectorXd& v) {
  json out = json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(finiteOrNull(v[i]));
  return out;
}

// E0, or E150 for a stylus offset of 150 mm (E followed by the offset in mm).
std::string lengthQuantity(const LengthTestPrediction& prediction) {
  if (!(prediction.stylus_offset > 0.0)) return "E0";
  std::ostringstream name;
  name << "E" << prediction.stylus_offset;
  return name.str();
}

std::string lineName(const LengthTestPrediction& prediction, int line) {
  for (const Gauge& gauge : prediction.gauges)
    if (gauge.line == line) return std::to_string(line) + " (" + gauge.kind + ")";
  return std::to_string(line);
}

json noiseJson(const AcceptanceInput& input) {
  return {{"probe", finiteOrNull(input.noise.probe)},
          {"encoder", jointsToFile(*input.machine, input.noise.encoder)}};
}

json calibratedNames(const AcceptanceInput& input) {
  json names = json::array();
  for (int k : input.uncertainty.indices)
    names.push_back(input.machine->mechanism->parameters()[static_cast<std::size_t>(k)].name);
  return names;
}

json quantilesJson(const Quantiles& q, double unit = 1.0) {
  return {{"mean", finiteOrNull(q.mean * unit)},
          {"50", finiteOrNull(q.median * unit)},
          {"95", finiteOrNull(q.q95 * unit)}};
}

json monteCarloJson(const MonteCarloSummary& mc, const MonteCarloOptions& options) {
  return {{"trials", mc.trials},
          {"adaptive", mc.adaptive},
          {"stable", mc.stable},
          {"seed", options.seed}};
}

json gaugeJson(const AcceptanceInput& input, const Gauge& gauge) {
  const double total = gauge.sigmaTotal();
  return {{"line", gauge.line},
          {"kind", gauge.kind},
          {"direction", vectorJson(gauge.direction)},
          {"f", gauge.fraction},
          {"length", finiteOrNull(gauge.length)},
          {"stylus_offset", vectorJson(gauge.stylus_offset)},
          {"a", vectorJson(gauge.a)},
          {"b", vectorJson(gauge.b)},
          {"joints_a", jointsToFile(*input.machine, gauge.joints_a)},
          {"joints_b", jointsToFile(*input.machine, gauge.joints_b)},
          {"mpe_um", finiteOrNull(gauge.mpe / kMmPerMicrometre)},
          {"sigma_sys", finiteOrNull(gauge.sigma_sys)},
          {"sigma_noise", finiteOrNull(gauge.sigma_noise)},
          {"sigma_total", finiteOrNull(total)},
          {"sigma_sys_um", finiteOrNull(gauge.sigma_sys / kMmPerMicrometre)},
          {"sigma_noise_um", finiteOrNull(gauge.sigma_noise / kMmPerMicrometre)},
          {"sigma_total_um", finiteOrNull(total / kMmPerMicrometre)}};
}

}  // namespace

std::vector<std::string> unseenParameterWarnings(const AcceptanceInput& input,
                                                 const LengthTestPrediction& prediction) {
  std::vector<std::string> warnings;
  for (const UnseenParameter& unseen : prediction.unseen) {
    std::string lines;
    for (int line : unseen.lines) lines += (lines.empty() ? "" : ", ") + lineName(prediction, line);
    warnings.push_back(
        "parameter " +
        input.machine->mechanism->parameters()[static_cast<std::size_t>(unseen.parameter)].name +
        " is not calibrated (taken as exact) but the results of line(s) " + lines +
        " depend on it: the prediction cannot say how the machine does there");
  }
  return warnings;
}

json lengthTestToJson(const AcceptanceInput& input, const LengthTestPrediction& prediction,
                      const MonteCarloOptions& options) {
  json items = json::array();
  for (const Gauge& gauge : prediction.gauges) items.push_back(gaugeJson(input, gauge));
  const MonteCarloSummary& mc = prediction.monte_carlo;
  json out = {{"test", "iso10360-2"},
              {"quantity", lengthQuantity(prediction)},
              {"stylus_offset", prediction.stylus_offset},
              {"mpe", prediction.mpe.text()},
              {"mpe_A_um", prediction.mpe.a / kMmPerMicrometre},
              {"mpe_K", prediction.mpe.k > 0.0 ? json(prediction.mpe.k) : json(nullptr)},
              {"mpe_C_um", prediction.mpe.cap > 0.0 ? json(prediction.mpe.cap / kMmPerMicrometre)
                                                    : json(nullptr)},
              {"units",
               {{"a, b, length, joints, stylus_offset, sigma_sys, sigma_noise, sigma_total", "mm"},
                {"*_um", "um"},
                {"quantiles", "max |E|/MPE, dimensionless"}}},
              {"box",
               {{"lo", vectorJson(prediction.box_lo)},
                {"hi", vectorJson(prediction.box_hi)},
                {"center", vectorJson(prediction.center)}}},
              {"noise", noiseJson(input)},
              {"calibrated", calibratedNames(input)},
              {"lines", prediction.lines},
              {"repetitions", prediction.repetitions},
              {"results", static_cast<int>(prediction.gauges.size()) * prediction.repetitions},
              {"items", items},
              {"p_pass", finiteOrNull(mc.p_pass)},
              {"p_pass_standard_error", finiteOrNull(mc.p_pass_standard_error)},
              {"quantiles", quantilesJson(mc.statistic)},
              {"monte_carlo", monteCarloJson(mc, options)},
              {"warnings", unseenParameterWarnings(input, prediction)}};
  return out;
}

std::string lengthTestTable(const AcceptanceInput& /*input*/,
                            const LengthTestPrediction& prediction,
                            const MonteCarloOptions& options) {
  std::ostringstream out;
  const MonteCarloSummary& mc = prediction.monte_carlo;
  out << "ISO 10360-2 length test predicted, " << lengthQuantity(prediction)
      << ",MPE = " << prediction.mpe.text() << " (um, L in mm)\n";
  out << "tip box (stylus 0) [" << fixed(prediction.box_lo.x(), 1) << ", "
      << fixed(prediction.box_hi.x(), 1) << "] x [" << fixed(prediction.box_lo.y(), 1) << ", "
      << fixed(prediction.box_hi.y(), 1) << "] x [" << fixed(prediction.box_lo.z(), 1) << ", "
      << fixed(prediction.box_hi.z(), 1) << "] mm; " << prediction.lines << " lines x "
      << prediction.gauges.size() /
             std::max<std::size_t>(1, static_cast<std::size_t>(prediction.lines))
      << " lengths x " << prediction.repetitions << " repetitions\n";
  for (int line = 0; line < prediction.lines && prediction.stylus_offset > 0.0; ++line) {
    for (const Gauge& gauge : prediction.gauges) {
      if (gauge.line != line) continue;
      out << "line " << line << ": stylus 0 offset by (" << fixed(gauge.stylus_offset.x(), 1)
          << ", " << fixed(gauge.stylus_offset.y(), 1) << ", " << fixed(gauge.stylus_offset.z(), 1)
          << ") mm, the " << gauge.kind << " diagonal of its tip's box\n";
      break;
    }
  }
  out << "\n";
  out << "line  kind        f    L/mm      sigma_sys/um  sigma_noise/um  sigma_total/um  MPE/um\n";
  for (const Gauge& gauge : prediction.gauges) {
    char row[160];
    std::snprintf(row, sizeof row, "%4d  %-9s %4.2f  %8.2f  %12.4f  %14.4f  %14.4f  %6.3f\n",
                  gauge.line, gauge.kind.c_str(), gauge.fraction, gauge.length,
                  gauge.sigma_sys / kMmPerMicrometre, gauge.sigma_noise / kMmPerMicrometre,
                  gauge.sigmaTotal() / kMmPerMicrometre, gauge.mpe / kMmPerMicrometre);
    out << row;
  }
  out << "\nmax |E|/MPE over the "
      << prediction.gauges.size() * static_cast<std::size_t>(prediction.repetitions)
      << " results: median " << fixed(mc.statistic.median, 3) << ", 95 % quantile "
      << fixed(mc.statistic.q95, 3) << "\n";
  out << "P(pass) = " << fixed(mc.p_pass, 4) << " +- " << fixed(mc.p_pass_standard_error, 4)
      << " (Monte-Carlo standard error; " << mc.trials << " trials, seed " << options.seed
      << (mc.adaptive ? (mc.stable ? ", adaptive" : ", adaptive, not stable at the limit") : "")
      << ")\n";
  return out.str();  // the warnings go to stderr (the command line) and into the JSON
}

std::string lengthTestSvg(const LengthTestPrediction& prediction) {
  svg::Plot plot("acceptance-e-vs-l",
                 lengthQuantity(prediction) + " against L: predicted 95 % band of each result",
                 "L / mm", "E / um");
  double longest = 0.0;
  for (const Gauge& gauge : prediction.gauges) longest = std::max(longest, gauge.length);
  const double spread = 0.004 * longest;
  const svg::Style diagonal{"#3b528b", "none", svg::Dash::Solid, 2.5, 0.9};
  const svg::Style axis_line{"#21918c", "none", svg::Dash::Solid, 2.5, 0.9};
  for (const Gauge& gauge : prediction.gauges) {
    const double x = gauge.length + spread * (gauge.line - 0.5 * (prediction.lines - 1));
    const double half = kCoverage95 * gauge.sigmaTotal() / kMmPerMicrometre;
    const bool is_diagonal = gauge.kind == "diagonal";
    plot.polyline({Eigen::Vector2d(x, -half), Eigen::Vector2d(x, half)},
                  is_diagonal ? diagonal : axis_line,
                  is_diagonal ? "95 % band, diagonals" : "95 % band, other lines",
                  {{"data-line", std::to_string(gauge.line)}});
  }
  const svg::Style mpe_style{"#000000", "none", svg::Dash::Dashed, 1.5, 1.0};
  std::vector<Eigen::Vector2d> upper, lower;
  for (int i = 0; i <= 20; ++i) {
    const double length = longest * 1.05 * i / 20.0;
    const double mpe = prediction.mpe.at(length) / kMmPerMicrometre;
    upper.emplace_back(length, mpe);
    lower.emplace_back(length, -mpe);
  }
  plot.polyline(upper, mpe_style, "+-MPE = " + prediction.mpe.text() + " um");
  plot.polyline(lower, mpe_style);
  plot.setXRange(0.0, longest * 1.05);
  return plot.render();
}

std::optional<ReportFigure> acceptanceReportFigure(const PlanAcceptance& acceptance) {
  if (!acceptance.length) return std::nullopt;
  const LengthTestPrediction& prediction = *acceptance.length;
  const MonteCarloSummary& mc = prediction.monte_carlo;
  char caption[400];
  std::snprintf(caption, sizeof caption,
                "ISO 10360-2 predicted from this plan's V_p (artcal acceptance): E0,MPE = %s um "
                "(L in mm); P(pass) = %.3f +- %.3f (%ld Monte-Carlo trials); max |E|/MPE: median "
                "%.3f, 95 %% quantile %.3f. Bars: each gauge's predicted 95 %% band of E.",
                prediction.mpe.text().c_str(), mc.p_pass, mc.p_pass_standard_error, mc.trials,
                mc.statistic.median, mc.statistic.q95);
  return ReportFigure{"acceptance-e-vs-l", caption, lengthTestSvg(prediction)};
}

json planAcceptanceToJson(const PlanAcceptance& acceptance) {
  if (acceptance.length)
    return lengthTestToJson(acceptance.input, *acceptance.length,
                            acceptance.length_options.monte_carlo);
  return poseTestToJson(acceptance.input, *acceptance.pose, acceptance.pose_options);
}

std::string planAcceptanceTable(const PlanAcceptance& acceptance) {
  if (acceptance.length)
    return lengthTestTable(acceptance.input, *acceptance.length,
                           acceptance.length_options.monte_carlo);
  return poseTestTable(acceptance.input, *acceptance.pose, acceptance.pose_options);
}

namespace {

/// The cube's set-up as the JSON states it (mm, deg; the seed posture in the joints' units).
void addPoseSetUp(json& out, const AcceptanceInput& input, const PoseTestOptions& options) {
  out["orientation"] = vectorJson(Eigen::Vector3d(options.orientation / kDegree));
  out["seed_posture"] =
      options.seed_posture ? json(jointsToFile(*input.machine, *options.seed_posture)) : json();
  out["unmodelled"] = options.unmodelled;
}

}  // namespace

json poseTestToJson(const AcceptanceInput& input, const PoseTestPrediction& prediction,
                    const PoseTestOptions& options) {
  json points = json::array();
  for (std::size_t i = 0; i < prediction.points.size(); ++i) {
    const PosePoint& point = prediction.points[i];
    char name[32];
    std::snprintf(name, sizeof name, "P%zu", i + 1);
    points.push_back({{"point", name},
                      {"commanded", vectorJson(point.commanded)},
                      {"joints", jointsToFile(*input.machine, point.joints)},
                      {"sigma_sys", finiteOrNull(point.sigma_sys)},
                      {"sigma_noise", finiteOrNull(point.sigma_noise)},
                      {"sigma_unmodelled", finiteOrNull(point.sigma_unmodelled)},
                      {"ap_expected", finiteOrNull(point.ap_expected)},
                      {"rp", finiteOrNull(point.rp)},
                      {"ap", quantilesJson(point.ap)}});
  }
  const MonteCarloSummary& mc = prediction.monte_carlo;
  json out = {{"test", "iso9283"},
              {"cube", options.cube},
              {"center", vectorJson(options.center)},
              {"cycles", options.cycles},
              {"units",
               {{"commanded, sigma_sys, sigma_noise, sigma_unmodelled, ap_expected, rp, ap, "
                 "max_ap, mpe, unmodelled",
                 "mm"},
                {"orientation", "deg"},
                {"joints, seed_posture", "deg or mm per joint"}}},
              {"noise", noiseJson(input)},
              {"calibrated", calibratedNames(input)},
              {"items", points},
              {"max_ap", quantilesJson(prediction.max_ap)},
              {"monte_carlo", monteCarloJson(mc, options.monte_carlo)}};
  addPoseSetUp(out, input, options);
  if (prediction.mpe) {
    out["mpe"] = *prediction.mpe;
    out["p_pass"] = finiteOrNull(mc.p_pass);
    out["p_pass_standard_error"] = finiteOrNull(mc.p_pass_standard_error);
  }
  return out;
}

std::string poseTestTable(const AcceptanceInput& input, const PoseTestPrediction& prediction,
                          const PoseTestOptions& options) {
  std::ostringstream out;
  const MonteCarloSummary& mc = prediction.monte_carlo;
  const Eigen::Vector3d rpy = options.orientation / kDegree;
  out << "ISO 9283 pose accuracy predicted: cube " << fixed(options.cube, 1) << " mm at ("
      << fixed(options.center.x(), 1) << ", " << fixed(options.center.y(), 1) << ", "
      << fixed(options.center.z(), 1) << ") mm, roll-pitch-yaw (" << fixed(rpy.x(), 1) << ", "
      << fixed(rpy.y(), 1) << ", " << fixed(rpy.z(), 1) << ") deg, " << options.cycles
      << " cycles, unmodelled error " << fixed(options.unmodelled, 5) << " mm per coordinate\n\n";
  out << "point  commanded/mm                    sigma_sys/mm  sigma_noise/mm  sigma_unmod/mm  "
         "E[AP]/mm  AP mean/mm  AP 50%/mm  AP 95%/mm  RP/mm     joints\n";
  for (std::size_t i = 0; i < prediction.points.size(); ++i) {
    const PosePoint& p = prediction.points[i];
    char row[240];
    std::snprintf(row, sizeof row,
                  "P%zu     (%8.2f, %8.2f, %8.2f)  %12.5f  %14.5f  %14.5f  %8.5f  %10.5f  %9.5f  "
                  "%9.5f  %8.5f  ",
                  i + 1, p.commanded.x(), p.commanded.y(), p.commanded.z(), p.sigma_sys,
                  p.sigma_noise, p.sigma_unmodelled, p.ap_expected, p.ap.mean, p.ap.median,
                  p.ap.q95, p.rp);
    out << row;
    for (double v : jointsToFile(*input.machine, p.joints)) out << fixed(v, 3) << " ";
    out << "\n";
  }
  out << "\nmax AP_P: mean " << fixed(prediction.max_ap.mean, 5) << " mm, median "
      << fixed(prediction.max_ap.median, 5) << " mm, 95 % quantile "
      << fixed(prediction.max_ap.q95, 5) << " mm (" << mc.trials << " trials, seed "
      << options.monte_carlo.seed << ")\n";
  if (prediction.mpe)
    out << "P(every AP_P <= " << *prediction.mpe << " mm) = " << fixed(mc.p_pass, 4) << " +- "
        << fixed(mc.p_pass_standard_error, 4) << "\n";
  return out.str();
}

}  // namespace artcal
