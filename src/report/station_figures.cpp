#include "artcal/report/station_figures.hpp"

#include <algorithm>
#include <cmath>

#include "artcal/report/svg.hpp"
#include "artcal/report/text_format.hpp"

namespace artcal {

using nlohmann::json;

namespace {

using report_text::format;

svg::Style strokeOnly(const std::string& colour, double width, svg::Dash dash = svg::Dash::Solid) {
  svg::Style style;
  style.stroke = colour;
  style.width = width;
  style.dash = dash;
  return style;
}

double euclideanLength(const json& vector) {
  double sum = 0.0;
  for (const json& c : vector) sum += c.get<double>() * c.get<double>();
  return std::sqrt(sum);
}

Eigen::Vector2d planView(const json& vector) {
  return {vector.at(0).get<double>(), vector.at(1).get<double>()};
}

/// A round enlargement (1, 2 or 5 times a power of ten) that draws the largest residual at
/// about a tenth of the points' extent; 1 when the residuals are zero.
double residualScale(double extent, double largest) {
  if (!(largest > 0.0) || !(extent > 0.0)) return 1.0;
  const double wanted = 0.1 * extent / largest;
  const double decade = std::pow(10.0, std::floor(std::log10(wanted)));
  for (const double step : {5.0, 2.0, 1.0}) {
    if (step * decade <= wanted) return step * decade;
  }
  return decade;
}

ReportFigure stationFigure(const Plan& plan, std::size_t j, const json& entries) {
  const Placement& placement = plan.placements[j];
  double largest = 0.0;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY), hi = -lo;
  for (std::size_t m = 0; m < entries.size() && m < placement.measurements.size(); ++m) {
    const Eigen::VectorXd& point = placement.measurements[m].point;
    if (point.size() < 2) continue;
    lo = lo.cwiseMin(point.head<2>());
    hi = hi.cwiseMax(point.head<2>());
    largest = std::max(largest, planView(entries[m].at("residual")).norm());
  }
  const double scale = residualScale((hi - lo).maxCoeff(), largest);
  const std::string label = placementLabel(plan.placements, j);
  svg::Plot plot("station-" + std::to_string(j), label + ": residuals after the calibration",
                 "x (mm)", "y (mm)", 520.0, 440.0);
  plot.setEqualAspect(true);
  for (std::size_t m = 0; m < entries.size() && m < placement.measurements.size(); ++m) {
    const Eigen::VectorXd& point = placement.measurements[m].point;
    if (point.size() < 2) continue;
    const Eigen::Vector2d at = point.head<2>();
    const Eigen::Vector2d residual = planView(entries[m].at("residual"));
    plot.polyline(
        {at, at + scale * residual}, strokeOnly("#000000", 1.5), format("residual x %g", scale),
        {{"data-field", format("/calibration/residuals/%zu/measurements/%zu/residual", j, m)}});
    svg::Style dot = strokeOnly("#000000", 1.0);
    dot.fill = "#ffffff";
    plot.marker(
        at, svg::Shape::Circle, 6.0, dot, "measured point", {},
        format("reading %zu: residual %.4f mm", m, euclideanLength(entries[m].at("residual"))));
  }
  return {"station-" + std::to_string(j),
          format("Station %s: each measured point (circle, in the instrument's frame, seen along "
                 "its z axis) with its residual after the calibration (predicted - measured), "
                 "drawn %g times enlarged; the largest is %.4f mm in this view.",
                 label.c_str(), scale, largest),
          plot.render()};
}

std::vector<double> finiteDeviations(const json& verification) {
  std::vector<double> out;
  for (const json& station : verification.at("stations")) {
    for (const json& d : station.at("deviations")) {
      if (d.is_number() && std::isfinite(d.get<double>())) out.push_back(d.get<double>());
    }
  }
  return out;
}

/// The outline of a histogram of `values` over the bins [edges[k], edges[k+1]).
std::vector<Eigen::Vector2d> histogramOutline(const std::vector<double>& values,
                                              const std::vector<double>& edges) {
  std::vector<int> counts(edges.size() - 1, 0);
  for (const double v : values) {
    const auto upper = std::upper_bound(edges.begin(), edges.end(), v);
    const auto bin = std::clamp<std::ptrdiff_t>(upper - edges.begin() - 1, 0,
                                                static_cast<std::ptrdiff_t>(counts.size()) - 1);
    ++counts[static_cast<std::size_t>(bin)];
  }
  std::vector<Eigen::Vector2d> outline = {{edges.front(), 0.0}};
  for (std::size_t k = 0; k < counts.size(); ++k) {
    outline.emplace_back(edges[k], counts[k]);
    outline.emplace_back(edges[k + 1], counts[k]);
  }
  outline.emplace_back(edges.back(), 0.0);
  return outline;
}

}  // namespace

std::vector<ReportFigure> stationResidualFigures(const Plan& plan, const json& calibration) {
  std::vector<ReportFigure> figures;
  const json& residuals = calibration.at("residuals");
  for (std::size_t j = 0; j < residuals.size() && j < plan.placements.size(); ++j) {
    const Placement& placement = plan.placements[j];
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    if (!artifact.kind().readings_are_features) continue;
    figures.push_back(stationFigure(plan, j, residuals[j].at("measurements")));
  }
  return figures;
}

std::vector<ReportFigure> heldOutDeviationFigures(const json& held_out) {
  const std::vector<double> nominal = finiteDeviations(held_out.at("nominal"));
  const std::vector<double> calibrated = finiteDeviations(held_out.at("calibrated"));
  if (nominal.empty() && calibrated.empty()) return {};
  double top = 0.0;
  for (const double v : nominal) top = std::max(top, v);
  for (const double v : calibrated) top = std::max(top, v);
  // Bins of a round width, about 20 over [0, the largest deviation].
  const std::vector<double> ticks = svg::niceTicks(0.0, top > 0.0 ? top : 1.0, 40);
  const double width = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
  std::vector<double> edges;
  for (double edge = 0.0; edges.size() < 2 || edges.back() <= top; edge += width)
    edges.push_back(edge);
  svg::Plot plot("held-out-deviations", "Deviations of the held-out readings",
                 "deviation |measured - predicted| (mm)", "readings", 640.0, 380.0);
  const auto nominal_outline = histogramOutline(nominal, edges);
  const auto calibrated_outline = histogramOutline(calibrated, edges);
  double tallest = 1.0;
  for (const auto* outline : {&nominal_outline, &calibrated_outline})
    for (const Eigen::Vector2d& corner : *outline) tallest = std::max(tallest, corner.y());
  plot.setXRange(0.0, edges.back());
  plot.setYRange(0.0, 1.1 * tallest);
  plot.polyline(nominal_outline, strokeOnly("#777777", 2.0, svg::Dash::Dashed),
                format("nominal machine (%zu readings)", nominal.size()));
  plot.polyline(calibrated_outline, strokeOnly("#000000", 2.0),
                format("calibrated machine (%zu readings)", calibrated.size()));
  return {{"held-out-deviations",
           format("Held-out readings of each station (the station fitted on its stationing "
                  "readings): deviations from the nominal machine (dashed) and from the calibrated "
                  "machine (solid), in bins of %g mm.",
                  width),
           plot.render()}};
}

}  // namespace artcal
