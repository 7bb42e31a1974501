#include "artcal/report/html_report.hpp"
#include "artcal/report/text_format.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <map>
#include <optional>
#include <sstream>

#include "artcal/report/procedure.hpp"
#include "artcal/report/report.hpp"
#include "artcal/report/svg.hpp"

namespace artcal {

using nlohmann::json;

namespace {

using report_text::format;

using report_text::exact;
constexpr const char* kMicro = report_text::kMicrometreSymbol;

// Line styles of the three tip-uncertainty curves, as in the seed's Fig. 6.
svg::Style curveStyle(svg::Dash dash, const std::string& colour) {
  svg::Style style;
  style.stroke = colour;
  style.dash = dash;
  style.width = 2.0;
  return style;
}

svg::Style faint(const std::string& colour, double width, double opacity) {
  svg::Style style;
  style.stroke = colour;
  style.width = width;
  style.opacity = opacity;
  return style;
}

svg::Style filled(const std::string& stroke, const std::string& fill, double width = 1.0) {
  svg::Style style;
  style.stroke = stroke;
  style.fill = fill;
  style.width = width;
  return style;
}

// ---------------------------------------------------------------------------------------------
// Geometry in the machine frame

/// Projection of a machine point onto one view: (x, y) or, for the side view, (x, z).
enum class View { Plan, Side };

Eigen::Vector2d project(const Eigen::VectorXd& x, View view) {
  if (x.size() < 3 || view == View::Plan) return {x[0], x[1]};
  return {x[0], x[2]};
}

Eigen::VectorXd probePosition(const Machine& machine, const Eigen::VectorXd& q) {
  Eigen::VectorXd x;
  forwardOrThrow(*machine.mechanism, machine.nominal, q, x);
  return x;
}

/// Inner and outer reach when the model's workspace is an annulus about its base
/// (Mechanism::reachRange; planar2r: |l1 - l2| and l1 + l2).
std::optional<std::array<double, 2>> reachAnnulus(const Machine& machine) {
  return machine.mechanism->reachRange(machine.nominal);
}

/// Marks shrink and arm links fade as placements crowd the layout (every one is still drawn).
double crowding(const Plan& plan) {
  return std::clamp(std::sqrt(40.0 / std::max<double>(plan.placements.size(), 1.0)), 0.35, 1.0);
}

/// The arm's links at one reading, faint (Mechanism::skeleton; nothing for a model not drawn).
void drawArm(svg::Plot& plot, const Machine& machine, const Eigen::VectorXd& q, View view,
             double density) {
  const std::vector<Eigen::VectorXd> points = machine.mechanism->skeleton(machine.nominal, q);
  if (points.empty()) return;
  std::vector<Eigen::Vector2d> projected;
  for (const Eigen::VectorXd& point : points) projected.push_back(project(point, view));
  plot.polyline(projected, faint("#555555", 1.0, 0.3 * density * density), "arm links per reading");
}

/// Cells of a regular grid over projected points: the largest value per cell (a map of the
/// worst case in each column of the workspace). Bounded size whatever the number of points.
struct GridMap {
  Eigen::Vector2d origin;
  double cell = 1.0;
  int columns = 0, rows = 0;
  std::map<std::pair<int, int>, double> largest;
};

GridMap binLargest(const std::vector<Eigen::Vector2d>& points, const std::vector<double>& values,
                   int cells_across) {
  GridMap grid;
  if (points.empty()) return grid;
  Eigen::Vector2d lo = points.front(), hi = points.front();
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  grid.cell = std::max((hi - lo).maxCoeff() / cells_across, 1e-9);
  grid.origin = lo;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Eigen::Vector2d rel = (points[k] - lo) / grid.cell;
    const std::pair<int, int> key{std::min(static_cast<int>(rel.x()), cells_across - 1),
                                  std::min(static_cast<int>(rel.y()), cells_across - 1)};
    auto [it, inserted] = grid.largest.emplace(key, values[k]);
    if (!inserted) it->second = std::max(it->second, values[k]);
  }
  return grid;
}

/// A planar arm's S depends on the reach alone (docs/method.md section 4: a turn of the whole
/// arm is a rigid motion the placements absorb), and the profile gives it against reach: the map
/// is drawn from the profile, each cell of a grid over the reach disc coloured by S at its centre's
/// reach (linear between profile rows), smooth and without holes where no sample fell.
GridMap reachProfileMap(const json& profile, int cells_across) {
  std::vector<std::pair<double, double>> rows;  // reach mm, S um
  for (const json& p : profile) {
    rows.emplace_back(p.at("reach").get<double>(), p.at("total").get<double>() * 1e3);
  }
  std::sort(rows.begin(), rows.end());
  GridMap grid;
  if (rows.size() < 2) return grid;
  const double r_min = rows.front().first, r_max = rows.back().first;
  grid.origin = Eigen::Vector2d::Constant(-r_max);
  grid.cell = 2.0 * r_max / cells_across;
  for (int i = 0; i < cells_across; ++i) {
    for (int j = 0; j < cells_across; ++j) {
      const double r = (grid.origin + grid.cell * Eigen::Vector2d(i + 0.5, j + 0.5)).norm();
      if (r < r_min || r > r_max) continue;
      const auto above =
          std::upper_bound(rows.begin(), rows.end(), std::make_pair(r, 0.0),
                           [](const auto& a, const auto& b) { return a.first < b.first; });
      const auto& hi = above == rows.end() ? rows.back() : *above;
      const auto& lo = above == rows.begin() ? rows.front() : *(above - 1);
      const double t = hi.first > lo.first ? (r - lo.first) / (hi.first - lo.first) : 0.0;
      grid.largest[{i, j}] = lo.second + t * (hi.second - lo.second);
    }
  }
  return grid;
}

void drawGrid(svg::Plot& plot, const GridMap& grid, double lo, double hi, bool coloured) {
  for (const auto& [key, value] : grid.largest) {
    const Eigen::Vector2d a = grid.origin + grid.cell * Eigen::Vector2d(key.first, key.second);
    const double t = hi > lo ? (value - lo) / (hi - lo) : 0.5;
    plot.cell(a, a + Eigen::Vector2d::Constant(grid.cell), coloured ? svg::viridis(t) : "#e4e4e4",
              {{"class", "map-cell"}});
  }
}

std::vector<Eigen::Vector2d> projectedWorkspace(const Machine& machine,
                                                const std::vector<Eigen::VectorXd>& workspace,
                                                View view) {
  std::vector<Eigen::Vector2d> points;
  points.reserve(workspace.size());
  for (const auto& q : workspace) points.push_back(project(probePosition(machine, q), view));
  return points;
}

void drawArtifacts(svg::Plot& plot, const Plan& plan, const std::vector<Eigen::MatrixXd>& features,
                   View view, bool numbered) {
  const double density = crowding(plan);
  svg::Style bar = curveStyle(svg::Dash::Solid, "#000000");
  bar.width = 2.0 * density;
  for (std::size_t j = 0; j < features.size(); ++j) {
    const Artifact& artifact =
        plan.artifacts[static_cast<std::size_t>(plan.placements[j].artifact)];
    const Eigen::MatrixXd& f = features[j];
    if (artifact.kind().drawn_as_line && f.cols() >= 2) {
      plot.polyline({project(f.col(0), view), project(f.col(f.cols() - 1), view)}, bar, "artifact");
    }
    for (int i = 0; i < f.cols(); ++i) {
      plot.marker(
          project(f.col(i), view), svg::Shape::Circle, 7.0 * density,
          filled("#000000", "#ffffff", density), "feature", {},
          format("placement %s, feature %d", placementLabel(plan.placements, j).c_str(), i));
    }
    if (numbered) plot.label(project(f.col(0), view), format("%zu", j));
  }
}

void drawPostures(svg::Plot& plot, const Plan& plan, View view) {
  const double density = crowding(plan);
  const Machine& machine = plan.machine;
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    for (const Measurement& m : plan.placements[j].measurements) {
      const Eigen::VectorXd tip = probePosition(machine, m.joints);
      drawArm(plot, machine, m.joints, view, density);
      plot.marker(project(tip, view), svg::Shape::Cross, 5.0 * density, faint("#000000", 1.0, 1.0),
                  "probe position per reading");
    }
  }
}

svg::Plot layoutPlot(const ReportInput& in, const std::vector<Eigen::MatrixXd>& features,
                     View view) {
  const Plan& plan = in.plan;
  const bool side = view == View::Side;
  const std::string id = side ? "layout-side" : "layout";
  svg::Plot plot(id,
                 plan.machine.dimension() == 2 ? "Layout in the machine frame"
                 : side                        ? "Layout, side view (XZ)"
                                               : "Layout, plan view (XY)",
                 "x / mm", side ? "z / mm" : "y / mm");
  plot.setEqualAspect(true);
  if (const auto annulus = reachAnnulus(plan.machine)) {
    const auto [inner, outer] = *annulus;
    svg::Style reach = faint("#000000", 1.2, 1.0);
    plot.circle(Eigen::Vector2d::Zero(), outer, reach, "outer reach l1 + l2");
    reach.dash = svg::Dash::Dashed;
    if (inner > 0) plot.circle(Eigen::Vector2d::Zero(), inner, reach, "inner reach |l1 - l2|");
  } else {
    // The reach of a general arm: where its workspace samples project (grey cells).
    const auto points = projectedWorkspace(plan.machine, in.evaluation.workspace, view);
    drawGrid(plot, binLargest(points, std::vector<double>(points.size(), 0.0), 48), 0, 1, false);
  }
  plot.marker(Eigen::Vector2d::Zero(), svg::Shape::Square, 9.0, filled("#000000", "#000000"),
              "machine origin");
  drawPostures(plot, plan, view);
  drawArtifacts(plot, plan, features, view, plan.placements.size() <= 40);
  return plot;
}

// ---------------------------------------------------------------------------------------------
// Tip uncertainty figures

ReportFigure profileFigure(const ReportInput& in) {
  const json& profile = in.evaluation_json.at("profile");
  svg::Plot plot("tip-profile", "Tip uncertainty against reach (worse elbow branch)", "reach / mm",
                 std::string("standard uncertainty / ") + kMicro);
  struct Curve {
    const char* key;
    const char* legend;
    svg::Dash dash;
    svg::Shape shape;
  };
  const Curve curves[] = {{"total", "S (total)", svg::Dash::Solid, svg::Shape::Circle},
                          {"kinematic", "S_m (parameters)", svg::Dash::Dashed, svg::Shape::Square},
                          {"encoder", "S_q (encoders)", svg::Dash::Dotted, svg::Shape::Triangle}};
  double top = 0.0;
  for (const Curve& c : curves) {
    std::vector<Eigen::Vector2d> points;
    for (std::size_t k = 0; k < profile.size(); ++k) {
      const double value = profile[k].at(c.key).get<double>();
      points.emplace_back(profile[k].at("reach").get<double>(), value * 1e3);
      top = std::max(top, value * 1e3);
    }
    plot.polyline(points, curveStyle(c.dash, "#000000"), c.legend);
    for (std::size_t k = 0; k < profile.size(); ++k) {
      const std::string field = format("/profile/%zu/%s", k, c.key);
      plot.marker(points[k], c.shape, 5.0, filled("#000000", "#ffffff"), {},
                  {{"data-field", field}, {"data-value", exact(profile[k].at(c.key))}},
                  format("%s at %.1f mm: %.3f um", c.legend, points[k].x(), points[k].y()));
    }
  }
  plot.setYRange(0.0, top * 1.08 + 1e-12);
  return {"tip-profile",
          "S_m, S_q and S against the distance from the machine origin (seed Fig. 6).",
          plot.render()};
}

/// Up to this many workspace configurations are drawn one by one; more are binned into cells.
constexpr std::size_t kFewPoints = 400;

ReportFigure tipMapFigure(const ReportInput& in, const std::vector<double>& totals_um,
                          const std::vector<Eigen::MatrixXd>& features, View view) {
  const Plan& plan = in.plan;
  const bool side = view == View::Side;
  const std::string name = side ? "tip-map-side" : "tip-map";
  svg::Plot plot(name,
                 plan.machine.dimension() == 2 ? "Tip uncertainty S over the workspace"
                 : side                        ? "Tip uncertainty S, side view (XZ)"
                                               : "Tip uncertainty S, plan view (XY)",
                 "x / mm", side ? "z / mm" : "y / mm", 640.0, 460.0);
  plot.setEqualAspect(true);
  const auto [lowest, highest] = std::minmax_element(totals_um.begin(), totals_um.end());
  double lo = *lowest, hi = *highest;
  const auto points = projectedWorkspace(plan.machine, in.evaluation.workspace, view);
  const bool from_profile = in.evaluation_json.contains("profile");
  GridMap profile_map;
  if (from_profile) {
    profile_map = reachProfileMap(in.evaluation_json.at("profile"), 48);
    for (const auto& [cell, value] : profile_map.largest) {
      lo = std::min(lo, value);
      hi = std::max(hi, value);
    }
  }
  plot.setColourBar(lo, hi,
                    std::string(from_profile ? "S / " : "largest S in the cell / ") + kMicro);
  if (from_profile) {
    drawGrid(plot, profile_map, lo, hi, true);
  } else if (points.size() > kFewPoints) {
    drawGrid(plot, binLargest(points, totals_um, 48), lo, hi, true);
  } else {
    for (std::size_t g = 0; g < points.size(); ++g) {
      const double t = hi > lo ? (totals_um[g] - lo) / (hi - lo) : 0.5;
      plot.marker(points[g], svg::Shape::Square, 9.0, filled("#000000", svg::viridis(t), 0.5));
    }
  }
  for (std::size_t j = 0; j < features.size(); ++j) {
    for (int i = 0; i < features[j].cols(); ++i) {
      plot.marker(project(features[j].col(i), view), svg::Shape::Circle, 6.0,
                  filled("#000000", "#ffffff"), "artifact feature");
    }
  }
  const json& worst = in.evaluation_json.at("/tip/worst"_json_pointer);
  const int index = worst.at("index").get<int>();
  const Eigen::Vector2d at = points[static_cast<std::size_t>(index)];
  plot.marker(at, svg::Shape::Diamond, 14.0, filled("#000000", "#ffffff", 2.5), "worst point",
              {{"data-field", "/tip/worst/total"}, {"data-value", exact(worst.at("total"))}},
              format("worst S = %.3f um", worst.at("total").get<double>() * 1e3));
  plot.label(at, format("worst S = %.2f %s", worst.at("total").get<double>() * 1e3, kMicro));
  return {name,
          from_profile
              ? std::string("Tip uncertainty S over the arm's reach, drawn from the profile "
                            "against reach (S depends on the reach alone); the diamond marks "
                            "the worst of the ") +
                    std::to_string(points.size()) + " workspace configurations."
              : std::string("Tip uncertainty S over the ") + std::to_string(points.size()) +
                    " workspace configurations" + (side ? " seen from the side" : "") +
                    (points.size() > kFewPoints
                         ? ": each cell shows the largest S of the points projecting into it; the "
                           "diamond marks the worst configuration."
                         : ", each a square coloured by S; the diamond marks the worst one."),
          plot.render()};
}

ReportFigure correlationFigure(const ReportInput& in) {
  const json& corr = in.evaluation_json.at("correlation");
  const int n = static_cast<int>(corr.size());
  Eigen::MatrixXd values(n, n);
  std::vector<std::string> labels;
  for (int i = 0; i < n; ++i) {
    labels.push_back(in.evaluation_json.at("parameters")[static_cast<std::size_t>(i)].at("name"));
    for (int j = 0; j < n; ++j)
      values(i, j) = corr[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
  }
  return {"correlation",
          "Correlation of the calibrated parameters predicted by the plan (dark: -1, light: "
          "+1); values printed where |r| >= 0.5.",
          svg::matrixHeatMap("correlation", "Parameter correlation", labels, values, -1.0, 1.0,
                             "/correlation")};
}

/// Flagged readings are labelled on the residual plot up to this many (then only tabled).
constexpr int kLabelledOutliers = 8;
/// Rows of the flagged-readings table.
constexpr std::size_t kTabledOutliers = 50;

ReportFigure residualFigure(const json& calibration, double threshold) {
  svg::Plot plot("residuals", "Normalized residuals of the calibration",
                 "reading (in plan order, from 0)", "standardized residual (standard deviations)",
                 640.0, 400.0);
  const svg::Shape shapes[] = {svg::Shape::Circle, svg::Shape::Square, svg::Shape::Triangle};
  const char* names[] = {"coordinate x", "coordinate y", "coordinate z"};
  // Readings numbered from 0 in plan order, as placements, readings and postures are in the
  // tables, the JSON and the procedure (docs/plan-format.md, Numbering).
  int reading = -1;
  double largest = threshold;
  const json& placements = calibration.at("residuals");
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const json& measurements = placements[j].at("measurements");
    for (std::size_t m = 0; m < measurements.size(); ++m) {
      ++reading;
      const json& entry = measurements[m];
      const json& standardized = entry.at("standardized");
      for (std::size_t c = 0; c < standardized.size() && c < 3; ++c) {
        if (!standardized[c].is_number()) continue;
        const double v = standardized[c].get<double>();
        largest = std::max(largest, std::abs(v));
        // Coordinates of one reading side by side, so that none hides another.
        const double offset = 0.18 * (static_cast<double>(c) - 0.5 * (standardized.size() - 1.0));
        plot.marker({reading + offset, v}, shapes[c], 6.0,
                    filled("#000000", c == 0 ? "#ffffff" : "#999999"),
                    standardized.size() == 1 ? "valued coordinate" : names[c]);
      }
      if (entry.at("flagged").get<bool>()) {
        // The diamond sits on the coordinate that decided the flag (largest |standardized|).
        double worst = 0.0;
        for (const json& v : standardized) {
          if (v.is_number() && std::abs(v.get<double>()) > std::abs(worst)) worst = v.get<double>();
        }
        const std::string field = format("/calibration/residuals/%zu/measurements/%zu/score", j, m);
        const double score = entry.at("score").get<double>();
        plot.marker({reading, worst}, svg::Shape::Diamond, 14.0, filled("#000000", "none", 2.0),
                    "flagged outlier", {{"data-field", field}, {"data-value", exact(score)}},
                    format("placement %s, reading %zu: score %.2f",
                           placements[j].contains("name")
                               ? placements[j].at("name").get<std::string>().c_str()
                               : std::to_string(j).c_str(),
                           m, score));
        if (calibration.at("flagged").get<int>() <= kLabelledOutliers) {
          plot.label({reading, worst}, format("P%zu R%zu", j, m));
        }
      }
    }
  }
  const double x_hi = std::max(reading, 0) + 0.5;
  svg::Style limit = faint("#000000", 1.2, 1.0);
  limit.dash = svg::Dash::Dashed;
  const std::string legend = format("flag threshold +/-%.3g", threshold);
  plot.polyline({{-0.5, threshold}, {x_hi, threshold}}, limit, legend);
  plot.polyline({{-0.5, -threshold}, {x_hi, -threshold}}, limit, legend);
  plot.setXRange(-0.5, x_hi);
  plot.setYRange(-1.15 * largest, 1.15 * largest);
  return {"residuals",
          "Each reading's residual in its valued artifact coordinates, divided by its standard "
          "deviation under the noise model; readings beyond the threshold are flagged (diamond, "
          "labelled placement and reading).",
          plot.render()};
}

// ---------------------------------------------------------------------------------------------
// HTML

/// An element `tag` (with `attributes`) showing a number of `source` at `pointer`, scaled for
/// display, with the exact JSON value in data-value (a dash for null).
std::string numberElement(const char* tag, const char* attributes, const json& source,
                          const std::string& pointer, double scale, const char* fmt,
                          const std::string& field_prefix = {}) {
  const json& value = source.at(json::json_pointer(pointer));
  const std::string open = std::string("<") + tag + attributes + " data-field=\"" +
                           svg::escape(field_prefix + pointer) + "\" data-value=\"";
  const std::string close = std::string("</") + tag + ">";
  if (!value.is_number()) return open + "null\">&#8212;" + close;
  return open + exact(value.get<double>()) + "\">" +
         svg::escape(format(fmt, value.get<double>() * scale)) + close;
}

/// A table cell showing a number of `source` at `pointer` (numberElement).
std::string numberCell(const json& source, const std::string& pointer, double scale,
                       const char* fmt, const std::string& field_prefix = {}) {
  return numberElement("td", " class=\"num\"", source, pointer, scale, fmt, field_prefix);
}

/// The same number in running text.
std::string numberSpan(const json& source, const std::string& pointer, double scale,
                       const char* fmt) {
  return numberElement("span", "", source, pointer, scale, fmt);
}

/// The truth and (estimate - truth) / u of one calibrated parameter (calibrate --json's entry),
/// the truth from a simulation block's parameters by name, both in file units.
std::string truthCells(const json& parameter, const json& truth) {
  const std::string name = parameter.at("name").get<std::string>();
  const json& u = parameter.at("u");
  if (!truth.contains(name) || !truth[name].is_number() || !u.is_number() ||
      !(u.get<double>() > 0.0)) {
    return "<td class=\"num\">&#8212;</td><td class=\"num\">&#8212;</td>";
  }
  const double t = truth[name].get<double>();
  const double z = (parameter.at("estimate").get<double>() - t) / u.get<double>();
  return "<td class=\"num\">" + svg::escape(format("%.6f", t)) + "</td><td class=\"num\">" +
         svg::escape(format("%+.2f", z)) + "</td>";
}

const char* kStyle = R"(
body { font-family: sans-serif; font-size: 10.5pt; color: #000; max-width: 190mm; margin: 0 auto;
       padding: 8mm 6mm; line-height: 1.35; }
h1 { font-size: 17pt; margin: 0 0 2mm 0; }
h2 { font-size: 13pt; margin: 7mm 0 2mm 0; border-bottom: 1px solid #000; }
table { border-collapse: collapse; margin: 2mm 0; }
th, td { border: 1px solid #999; padding: 1px 6px; text-align: left; }
th { background: #eee; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
figure { margin: 3mm 0; break-inside: avoid; page-break-inside: avoid; }
figure svg { max-width: 100%; height: auto; display: block; }
figcaption { font-size: 9pt; color: #333; }
.verdict { font-weight: bold; padding: 2mm 3mm; border: 2px solid #000; display: inline-block; }
.verdict.bad { border-style: dashed; }
.muted { color: #444; font-size: 9pt; }
code { font-size: 9pt; }
h3 { font-size: 11pt; margin: 4mm 0 1mm 0; }
section.placement { break-inside: avoid; page-break-inside: avoid; margin-bottom: 4mm; }
section.placement .views { display: flex; flex-wrap: wrap; gap: 2mm; }
section.placement .views svg { width: 60mm; height: auto; }
section.placement .views svg:only-child { width: 100mm; }
section.placement p.view-legend { font-size: 9pt; margin: 1mm 0; }
section.placement p.view-legend svg { vertical-align: middle; }
table.procedure { font-size: 8.5pt; }
@page { size: A4; margin: 14mm; }
@media print { body { max-width: none; padding: 0; } h2 { break-after: avoid; }
               section.placement + section.placement { break-before: page; } }
)";

void writeHead(std::ostream& out, const Plan& plan) {
  const std::string title = plan.name.empty() ? plan.source : plan.name;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n"
      << "<meta name=\"generator\" content=\"artcal report\"/>\n<title>artcal report: "
      << svg::escape(title) << "</title>\n<style>" << kStyle << "</style>\n</head>\n<body>\n";
  out << "<h1>Calibration plan " << svg::escape(title) << "</h1>\n";
  if (!plan.description.empty()) out << "<p>" << svg::escape(plan.description) << "</p>\n";
  out << "<p class=\"muted\">Plan file <code>" << svg::escape(plan.source) << "</code>; model "
      << svg::escape(plan.machine.mechanism->modelName()) << ", " << plan.placements.size()
      << " placements. Units: mm and degrees; uncertainties are standard uncertainties (k = 1). "
      << "Every number below is the one <code>artcal evaluate --json</code> prints.</p>\n";
}

void writeVerdict(std::ostream& out, const json& ev) {
  const bool ok = ev.at("identifiable").get<bool>();
  out << "<h2>Identifiability</h2>\n<p class=\"verdict " << (ok ? "ok" : "bad")
      << "\" data-field=\"/identifiable\" data-value=\"" << (ok ? "true" : "false") << "\">"
      << (ok ? "IDENTIFIABLE: the plan separates every calibrated parameter."
             : "NOT IDENTIFIABLE: the plan cannot separate every calibrated parameter; no "
               "uncertainties exist for it.")
      << "</p>\n<table>\n<tr><th>counting condition</th><th>N(b)</th><th>N(r)</th><th>N(p)</th>"
      << "<th>satisfied</th><th>rank</th><th>deficiency</th><th>condition number</th></tr>\n<tr>"
      << "<td>N(b) - N(r) &#8805; N(p)</td>" << numberCell(ev, "/counting/N_b", 1, "%.0f")
      << numberCell(ev, "/counting/N_r", 1, "%.0f") << numberCell(ev, "/counting/N_p", 1, "%.0f")
      << "<td>" << (ev.at("/counting/satisfied"_json_pointer).get<bool>() ? "yes" : "NO") << "</td>"
      << numberCell(ev, "/rank/rank", 1, "%.0f") << numberCell(ev, "/rank/deficiency", 1, "%.0f")
      << numberCell(ev, "/rank/condition_number", 1, "%.3g") << "</tr>\n</table>\n";
  const json& combinations = ev.at("/rank/combinations"_json_pointer);
  if (combinations.empty()) return;
  out << "<p>Parameter combinations the plan cannot separate (coefficients of the scaled "
         "parameters, largest 1):</p>\n<ol>\n";
  for (std::size_t k = 0; k < combinations.size(); ++k) {
    out << "<li>";
    const json& c = combinations[k];
    for (std::size_t i = 0; i < c.at("parameters").size(); ++i) {
      // A coefficient that could not be computed is null in the JSON: a dash here, as in the
      // tables (never nan, never a library exception).
      const json& coefficient = c.at("coefficients")[i];
      const bool known = coefficient.is_number() && std::isfinite(coefficient.get<double>());
      out << "<span data-field=\"" << format("/rank/combinations/%zu/coefficients/%zu", k, i)
          << "\" data-value=\"" << (known ? exact(coefficient) : std::string("null")) << "\">"
          << (known ? svg::escape(format("%+.4g ", coefficient.get<double>())) : "&#8212; ")
          << "</span>" << svg::escape(c.at("parameters")[i].get<std::string>()) << " ";
    }
    out << "</li>\n";
  }
  out << "</ol>\n";
}

void writeParameters(std::ostream& out, const json& ev) {
  out << "<h2>Parameters</h2>\n<table>\n<tr><th>parameter</th><th>nominal</th><th>unit</th>"
      << "<th>standard uncertainty u</th><th>unit of u</th></tr>\n";
  const json& parameters = ev.at("parameters");
  for (std::size_t k = 0; k < parameters.size(); ++k) {
    const json& p = parameters[k];
    const bool angle = p.at("unit") == "deg";
    const std::string base = format("/parameters/%zu/", k);
    out << "<tr><td>" << svg::escape(p.at("name").get<std::string>()) << "</td>"
        << numberCell(ev, base + "nominal", 1, "%.4f") << "<td>"
        << svg::escape(p.at("unit").get<std::string>()) << "</td>"
        << numberCell(ev, base + "u", angle ? 1.0 : 1e3, angle ? "%.6f" : "%.3f") << "<td>"
        << (angle ? "deg" : kMicro) << "</td></tr>\n";
  }
  out << "</table>\n";
}

/// A machine tool's location errors (ISO 230-7; evaluate --json "location_errors", or the
/// calibration's with its estimates): u in um / urad and the confounding index F.
void writeLocationErrors(std::ostream& out, const json& source, const std::string& prefix) {
  if (!source.contains("location_errors")) return;
  const json& errors = source.at("location_errors");
  const bool estimates = !errors.empty() && errors[0].contains("estimate_fine");
  out << "<h3>Location errors (ISO 230-7)</h3>\n<p>Each calibrated location error by its axis, "
         "with its standard uncertainty u in "
      << kMicro
      << " (offsets) or \xC2\xB5rad (orientations, zeros, squareness) and its confounding index F "
         "= u / u(alone) (u "
         "were every other calibrated parameter known): F &#8805; 1; F &#8804; 2: well "
         "separated.</p>\n<table>\n<tr><th>name</th><th>axis</th><th>kind</th>"
      << (estimates ? "<th>estimate</th>" : "") << "<th>u</th><th>unit</th><th>F</th></tr>\n";
  for (std::size_t k = 0; k < errors.size(); ++k) {
    const json& e = errors[k];
    const std::string base = format("/location_errors/%zu/", k);
    out << "<tr><td>" << svg::escape(e.at("name").get<std::string>()) << "</td><td>"
        << svg::escape(e.at("axis").get<std::string>()) << "</td><td>"
        << svg::escape(e.at("kind").get<std::string>()) << "</td>";
    if (estimates) out << numberCell(source, base + "estimate_fine", 1, "%+.2f", prefix);
    out << numberCell(source, base + "u_fine", 1, "%.2f", prefix) << "<td>"
        << (e.at("unit_fine") == "um" ? kMicro : "\xC2\xB5rad") << "</td>"
        << numberCell(source, base + "confounding_index", 1, "%.2f", prefix) << "</tr>\n";
  }
  out << "</table>\n";
}

/// A calibrated machine tool's controller table (calibrate --json "controller_table"): one row
/// per entry with its status; only a determined entry shows a value (with u and U, k = 2).
void writeControllerTable(std::ostream& out, const json& cal, const std::string& prefix) {
  if (!cal.contains("controller_table")) return;
  const json& table = cal.at("controller_table");
  out << "<h3>Controller table</h3>\n<p>"
      << svg::escape(table.value("sign", std::string("actual location of each axis")))
      << ". Chained form: "
      << svg::escape(table.at("/chained_form/description"_json_pointer).get<std::string>())
      << ". Only determined entries have a value; a dropped or held entry was not measured. U = "
      << format("%g", table.value("coverage_factor", 2.0))
      << " u.</p>\n<table>\n<tr><th>axis</th><th>entry</th><th>status</th><th>value</th>"
         "<th>u</th><th>U</th><th>unit</th><th>note</th></tr>\n";
  const json& entries = table.at("entries");
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const json& e = entries[i];
    const std::string base = format("/controller_table/entries/%zu/", i);
    const bool angle = e.at("unit") == "deg";
    out << "<tr><td>" << svg::escape(e.at("axis").get<std::string>()) << "</td><td>"
        << svg::escape(e.at("entry").get<std::string>()) << "</td><td>"
        << svg::escape(e.at("status").get<std::string>()) << "</td>"
        << numberCell(cal, base + "value", 1, angle ? "%+.6f" : "%+.4f", prefix)
        << numberCell(cal, base + "u", 1, angle ? "%.6f" : "%.4f", prefix)
        << numberCell(cal, base + "U", 1, angle ? "%.6f" : "%.4f", prefix) << "<td>"
        << svg::escape(e.at("unit").get<std::string>()) << "</td><td>"
        << svg::escape(e.at("note").get<std::string>()) << "</td></tr>\n";
  }
  // The chained form's rows (C relative to A on the trunnion), mm.
  const json& chained = table.at("/chained_form/entries"_json_pointer);
  for (std::size_t i = 0; i < chained.size(); ++i) {
    const json& c = chained[i];
    const std::string base = format("/controller_table/chained_form/entries/%zu/", i);
    out << "<tr><td>" << svg::escape(c.at("axis").get<std::string>()) << "</td><td>"
        << svg::escape(c.at("entry").get<std::string>()) << "</td><td>"
        << svg::escape(c.at("status").get<std::string>()) << "</td>"
        << numberCell(cal, base + "value", 1, "%+.4f", prefix)
        << numberCell(cal, base + "u", 1, "%.4f", prefix)
        << numberCell(cal, base + "U", 1, "%.4f", prefix) << "<td>mm</td><td>"
        << svg::escape(c.value("note", std::string())) << "</td></tr>\n";
  }
  out << "</table>\n";
}

// The tip map with the unmodelled error the calibration estimated by cross-validation
// (report.hpp, tipWithUnmodelledToJson), when it did.
void writeTipWithUnmodelled(std::ostream& out, const json& ev) {
  if (!ev.contains("tip_with_unmodelled")) return;
  const json& t = ev.at("tip_with_unmodelled");
  out << "<p>With the error the model does not explain, s_u = "
      << numberSpan(ev, "/tip_with_unmodelled/sigma", 1e3, "%.2f") << " " << kMicro
      << " per coordinate (cross-validation, " << t.at("folds").get<int>() << " folds by "
      << svg::escape(t.at("scheme").get<std::string>())
      << "): worst S_u = " << numberSpan(ev, "/tip_with_unmodelled/worst_total", 1e3, "%.3f") << " "
      << kMicro << ", mean " << numberSpan(ev, "/tip_with_unmodelled/mean_total", 1e3, "%.3f")
      << " " << kMicro << " (S_u<sup>2</sup> = S<sup>2</sup> + d s_u<sup>2</sup>).</p>\n";
}

void writeTipSummary(std::ostream& out, const Plan& plan, const json& ev) {
  if (!ev.contains("tip")) return;
  out << "<table>\n<tr><th>tip uncertainty (" << kMicro << ")</th><th>S</th><th>S_m</th>"
      << "<th>S_q</th><th>at joints</th></tr>\n<tr><td>worst of "
      << ev.at("/tip/configurations"_json_pointer).get<std::size_t>() << " configurations</td>"
      << numberCell(ev, "/tip/worst/total", 1e3, "%.3f")
      << numberCell(ev, "/tip/worst/kinematic", 1e3, "%.3f")
      << numberCell(ev, "/tip/worst/encoder", 1e3, "%.3f") << "<td>";
  const json& joints = ev.at("/tip/worst/joints"_json_pointer);
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const Quantity q = jointQuantity(plan.machine.mechanism->jointKind(static_cast<int>(i)));
    out << (i ? ", " : "") << "<span data-field=\"/tip/worst/joints/" << i << "\" data-value=\""
        << exact(joints[i]) << "\">" << format("%.2f", joints[i].get<double>()) << "</span> "
        << unitName(q);
  }
  out << "</td></tr>\n<tr><td>mean over the workspace</td>"
      << numberCell(ev, "/tip/mean", 1e3, "%.3f") << "<td></td><td></td><td></td></tr>\n"
      << "<tr><td>root mean square</td>" << numberCell(ev, "/tip/rms", 1e3, "%.3f")
      << "<td></td><td></td><td></td></tr>\n";
  // A machine with several tips: each tip's worst at the same configurations (the rows above
  // are the first tip's).
  if (ev.contains("tips")) {
    for (std::size_t t = 0; t < ev.at("tips").size(); ++t) {
      const std::string base = format("/tips/%zu/tip/worst/", t);
      out << "<tr><td>worst of tip " << svg::escape(ev.at("tips")[t].at("name").get<std::string>())
          << "</td>" << numberCell(ev, base + "total", 1e3, "%.3f")
          << numberCell(ev, base + "kinematic", 1e3, "%.3f")
          << numberCell(ev, base + "encoder", 1e3, "%.3f") << "<td></td></tr>\n";
    }
  }
  out << "</table>\n";
  writeTipWithUnmodelled(out, ev);
}

void writeProfileTable(std::ostream& out, const json& ev) {
  if (!ev.contains("profile")) return;
  out << "<table>\n<tr><th>reach (mm)</th><th>S_m (" << kMicro << ")</th><th>S_q (" << kMicro
      << ")</th><th>S (" << kMicro << ")</th></tr>\n";
  for (std::size_t k = 0; k < ev.at("profile").size(); ++k) {
    const std::string base = format("/profile/%zu/", k);
    out << "<tr>" << numberCell(ev, base + "reach", 1, "%.1f")
        << numberCell(ev, base + "kinematic", 1e3, "%.3f")
        << numberCell(ev, base + "encoder", 1e3, "%.3f")
        << numberCell(ev, base + "total", 1e3, "%.3f") << "</tr>\n";
  }
  out << "</table>\n";
}

void writeFigure(std::ostream& out, const ReportFigure& figure) {
  out << "<figure id=\"figure-" << svg::escape(figure.name) << "\">\n"
      << figure.svg << "<figcaption>" << svg::escape(figure.caption)
      << "</figcaption>\n</figure>\n";
}

void writeFigures(std::ostream& out, const std::vector<ReportFigure>& figures,
                  const std::string& prefix) {
  for (const ReportFigure& f : figures) {
    if (f.name.starts_with(prefix)) writeFigure(out, f);
  }
}

/// The leaves of a JSON value as (pointer, value) rows.
void flatten(const json& value, const std::string& pointer,
             std::vector<std::pair<std::string, json>>& rows) {
  if (value.is_object()) {
    for (const auto& [key, child] : value.items()) flatten(child, pointer + "/" + key, rows);
  } else if (value.is_array() && !value.empty() && !value.front().is_primitive()) {
    for (std::size_t i = 0; i < value.size(); ++i) {
      flatten(value[i], pointer + "/" + std::to_string(i), rows);
    }
  } else {
    rows.emplace_back(pointer, value);
  }
}

std::string jsonText(const json& value) {
  if (value.is_number_float()) return format("%.6g", value.get<double>());
  if (value.is_string()) return value.get<std::string>();
  return value.dump();
}

/// The optimizer's search: its criterion from the random starting designs to the optimum
/// (the `optimization` block `artcal optimize` writes into `predicted`).
void writeOptimization(std::ostream& out, const json& optimization) {
  const bool mm = optimization.value("unit", "") == "mm";
  const auto row = [&](const char* what, const json::json_pointer& at) {
    if (!optimization.contains(at) || !optimization.at(at).is_number()) return;
    const double v = optimization.at(at).get<double>();
    // Criterion "pass": the quantity of each stage (1 - P(pass), or the 95 % quantile where
    // P(pass) saturated), as `optimize --json` names it.
    std::string stage = at.to_string().substr(1);
    std::replace(stage.begin(), stage.end(), '/', '_');
    const json::json_pointer quantity("/pass/stage_objectives/" + stage);
    const bool named = optimization.contains(quantity) && optimization.at(quantity).is_string();
    out << "<tr><td>" << what
        << (named ? " (" + svg::escape(optimization.at(quantity).get<std::string>()) + ")" : "")
        << "</td><td class=\"num\">"
        << svg::escape(mm ? format("%.3f", v * 1e3) : format("%.6g", v)) << "</td></tr>\n";
  };
  out << "<p>The search (" << svg::escape(jsonText(optimization.value("algorithm", json("?"))))
      << ", " << svg::escape(jsonText(optimization.value("starts_done", json("?")))) << " of "
      << svg::escape(jsonText(optimization.value("starts", json("?")))) << " starts, "
      << svg::escape(jsonText(optimization.value("termination", json("?")))) << "): the criterion "
      << svg::escape(jsonText(optimization.value("criterion", json("?"))))
      << " from the starting designs to the optimum.</p>\n<table>\n<tr><th>design</th><th>"
      << (mm ? std::string("criterion (") + kMicro + ")"
             : "criterion (" + svg::escape(optimization.value("unit", "")) + ")")
      << "</th></tr>\n";
  row("random starting designs, median", "/random_initial/median"_json_pointer);
  row("random starting designs, best", "/random_initial/best"_json_pointer);
  row("best start as drawn", "/best_start/initial"_json_pointer);
  row("best start after the exchange", "/best_start/exchanged"_json_pointer);
  row("best start after refinement", "/best_start/refined"_json_pointer);
  row("optimum written to the plan", "/value"_json_pointer);
  out << "</table>\n";
}

/// One number of the optimizer's predicted block beside the same figure evaluated now.
struct PredictedRow {
  std::string label;  ///< its pointer in the predicted block, named elements by name (and unit)
  json value;         ///< as the plan file has it
  std::string now;    ///< its pointer in evaluate --json; empty: not evaluated now
};

const json* memberOf(const json* now, const std::string& key) {
  return now && now->is_object() && now->contains(key) ? &now->at(key) : nullptr;
}

const json* elementOf(const json* now, std::size_t i) {
  return now && now->is_array() && i < now->size() ? &(*now)[i] : nullptr;
}

std::optional<std::string> nameOfElement(const json& element) {
  if (!element.is_object() || !element.contains("name") || !element.at("name").is_string())
    return std::nullopt;
  return element.at("name").get<std::string>();
}

/// The leaves of the predicted `value` paired with the same figure of the evaluation `now`: an
/// element of an array of named objects (the parameters) is matched by its name, not by its index
/// (the parameter set may have changed since the optimizer ran), and labelled by its name and unit.
void pairPredicted(const json& value, const std::string& label, const json* now,
                   const std::string& now_pointer, const std::string& unit,
                   std::vector<PredictedRow>& rows) {
  if (value.is_object()) {
    for (const auto& [key, leaf] : value.items()) {
      pairPredicted(leaf, label + "/" + key, memberOf(now, key), now_pointer + "/" + key, unit,
                    rows);
    }
  } else if (value.is_array() && !value.empty() && !value.front().is_primitive()) {
    for (std::size_t i = 0; i < value.size(); ++i) {
      const json& element = value[i];
      const std::optional<std::string> name = nameOfElement(element);
      std::size_t j = i;  // unnamed elements pair by index
      if (name) {
        j = std::string::npos;  // none of that name now
        for (std::size_t k = 0; now && now->is_array() && k < now->size(); ++k) {
          if (nameOfElement((*now)[k]) == name) {
            j = k;
            break;
          }
        }
      }
      const std::string element_unit =
          element.is_object() && element.contains("unit") && element.at("unit").is_string()
              ? element.at("unit").get<std::string>()
              : unit;
      pairPredicted(element, label + "/" + (name ? *name : std::to_string(i)), elementOf(now, j),
                    now_pointer + "/" + std::to_string(j), element_unit, rows);
    }
  } else if (value.is_number()) {
    const bool evaluated = now && now->is_number();
    rows.push_back({label + (unit.empty() ? "" : " (" + unit + ")"), value,
                    evaluated ? now_pointer : std::string()});
  }
}

/// The predicted numbers the optimizer wrote beside the same figures evaluated now (the same
/// figures of evaluate --json, parameters by name; the profile and correlation are shown in their
/// figures).
void writePredicted(std::ostream& out, const json& predicted, const json& evaluation) {
  std::vector<PredictedRow> rows;
  pairPredicted(predicted, "", &evaluation, "", "", rows);
  out << "<table>\n<tr><th>predicted by the optimizer</th><th>in the plan file</th>"
      << "<th>evaluated now</th></tr>\n";
  for (const PredictedRow& row : rows) {
    if (row.label.starts_with("/optimization") || row.label.starts_with("/profile") ||
        row.label.starts_with("/correlation")) {
      continue;
    }
    out << "<tr><td>" << svg::escape(row.label.substr(1)) << "</td><td class=\"num\">"
        << svg::escape(jsonText(row.value)) << "</td>"
        << (row.now.empty() ? "<td></td>" : numberCell(evaluation, row.now, 1, "%.6g"))
        << "</tr>\n";
  }
  out << "</table>\n";
}

/// An optimized plan (docs/plan-format.md, optimization spec): its design block, the search from
/// the starting designs to the optimum, and its predicted block beside the evaluation now.
void writeDesign(std::ostream& out, const ReportInput& in) {
  if (!in.document.contains("design") && !in.document.contains("predicted")) return;
  out << "<h2>Design</h2>\n";
  if (in.document.contains("design")) {
    std::vector<std::pair<std::string, json>> rows;
    flatten(in.document.at("design"), "", rows);
    out << "<table>\n<tr><th>design</th><th>value</th></tr>\n";
    for (const auto& [pointer, value] : rows) {
      out << "<tr><td>" << svg::escape(pointer.substr(1)) << "</td><td>"
          << svg::escape(jsonText(value)) << "</td></tr>\n";
    }
    out << "</table>\n";
  }
  if (!in.document.contains("predicted") || !in.document.at("predicted").is_object()) return;
  const json& predicted = in.document.at("predicted");
  if (predicted.contains("optimization") && predicted.at("optimization").is_object()) {
    writeOptimization(out, predicted.at("optimization"));
  }
  writePredicted(out, predicted, in.evaluation_json);
}

/// The flagged readings, worst first (the first kTabledOutliers of them).
void writeFlagged(std::ostream& out, const json& cal) {
  struct Flag {
    std::size_t placement, measurement;
    double score;
  };
  std::vector<Flag> flags;
  const json& residuals = cal.at("residuals");
  for (std::size_t j = 0; j < residuals.size(); ++j) {
    const json& measurements = residuals[j].at("measurements");
    for (std::size_t m = 0; m < measurements.size(); ++m) {
      if (measurements[m].at("flagged").get<bool>()) {
        flags.push_back({j, m, measurements[m].at("score").get<double>()});
      }
    }
  }
  if (flags.empty()) {
    out << "<p>No reading is flagged.</p>\n";
    return;
  }
  std::stable_sort(flags.begin(), flags.end(),
                   [](const Flag& a, const Flag& b) { return a.score > b.score; });
  // Gross errors (calibrate's gross_errors), with the CSV file and row a reading came from.
  std::map<std::pair<std::size_t, std::size_t>, std::string> gross;
  if (const auto it = cal.find("gross_errors"); it != cal.end()) {
    for (const json& g : *it) {
      std::string where = "yes";
      if (g.contains("csv_row"))
        where += ": " + g.at("csv").get<std::string>() + " row " +
                 std::to_string(g.at("csv_row").get<int>());
      gross[{g.at("placement").get<std::size_t>(), g.at("measurement").get<std::size_t>()}] = where;
    }
  }
  if (!gross.empty()) {
    out << "<p><strong>" << gross.size() << (gross.size() == 1 ? " gross error" : " gross errors")
        << "</strong> (|z| beyond the gross threshold times max(1, Birge ratio)): check each (a "
           "ball not seated, a socket that moved). A reading from a CSV file is left out with "
           "<code>\"exclude_rows\"</code> in its measurement entry.</p>\n";
  }
  out << "<table>\n<tr><th>flagged reading</th><th>feature</th><th>score (largest |standardized "
         "residual|)</th>"
      << (gross.empty() ? "" : "<th>gross error</th>") << "</tr>\n";
  for (std::size_t k = 0; k < std::min(flags.size(), kTabledOutliers); ++k) {
    const Flag& f = flags[k];
    const std::string base = format("/residuals/%zu/measurements/%zu/", f.placement, f.measurement);
    const json& entry = cal.at("residuals")[f.placement];
    const std::string placement =
        entry.contains("name") ? entry.at("name").get<std::string>() : std::to_string(f.placement);
    out << "<tr><td>placement " << svg::escape(placement) << ", reading " << f.measurement
        << "</td>" << numberCell(cal, base + "feature", 1, "%.0f", "/calibration")
        << numberCell(cal, base + "score", 1, "%.2f", "/calibration");
    if (!gross.empty()) {
      const auto it = gross.find({f.placement, f.measurement});
      out << "<td>" << svg::escape(it == gross.end() ? std::string() : it->second) << "</td>";
    }
    out << "</tr>\n";
  }
  out << "</table>\n";
  if (flags.size() > kTabledOutliers) {
    out << "<p>and " << flags.size() - kTabledOutliers << " more flagged readings.</p>\n";
  }
}

/// calibrate's noise estimate, the parameters it held at nominal and its warnings (implausible
/// corrections, readings that fit to rounding), as calibrate --json has them.
void writeCalibrationWarnings(std::ostream& out, const json& cal) {
  if (const auto it = cal.find("noise_estimate"); it != cal.end()) {
    out << "<p>Probe noise estimated from the fit: "
        << format("%.4g", it->at("probe").get<double>() * 1e3) << " " << kMicro << " (u "
        << format("%.2g", it->at("u").get<double>() * 1e3) << " " << kMicro << ").</p>\n";
  }
  if (const auto it = cal.find("weakly_determined"); it != cal.end() && !it->empty()) {
    out << "<p>Held at nominal, weakly determined (the surviving fraction of their information "
           "is below 1e-6: set by the model mismatch, not by the readings):";
    for (const json& w : *it)
      out << " <code>" << svg::escape(w.at("name").get<std::string>()) << "</code>";
    out << "</p>\n";
  }
  if (const auto it = cal.find("calibrated_in_place"); it != cal.end() && !it->empty()) {
    out << "<p>Calibrated in their place (dropped by the structural rule as tied to them):";
    for (const json& name : *it)
      out << " <code>" << svg::escape(name.get<std::string>()) << "</code>";
    out << "</p>\n";
  }
  if (const auto it = cal.find("warnings"); it != cal.end() && !it->empty()) {
    out << "<ul class=\"warnings\">\n";
    for (const json& w : *it)
      out << "<li class=\"bad\">warning: " << svg::escape(w.get<std::string>()) << "</li>\n";
    out << "</ul>\n";
  }
}

/// The angular deviations of a pose instrument's held-out readings (verify's `angular`, deg): one
/// row per station and one for all of them, with each machine; nothing for a point instrument.
void writeHeldOutAngles(std::ostream& out, const json& held) {
  if (!held.contains(json::json_pointer("/calibrated/angular_all"))) return;
  out << "<p>Angular deviations of the held-out poses: the orientation residual "
      << "|log(R<sub>predicted</sub> R<sub>measured</sub><sup>T</sup>)| (deg).</p>\n<table>\n"
      << "<tr><th>machine</th><th>station</th><th>readings</th><th>mean</th><th>RMS</th>"
      << "<th>max</th><th>predicted RMS</th></tr>\n";
  for (const char* machine : {"nominal", "calibrated"}) {
    const bool calibrated = std::string(machine) == "calibrated";
    const auto row = [&](const std::string& label, const std::string& at) {
      out << "<tr><td>" << machine << "</td><td>" << svg::escape(label) << "</td>"
          << numberCell(held, at + "readings", 1, "%.0f", "/held_out")
          << numberCell(held, at + "mean", 1, "%.5f", "/held_out")
          << numberCell(held, at + "rms", 1, "%.5f", "/held_out")
          << numberCell(held, at + "max", 1, "%.5f", "/held_out")
          << (calibrated ? numberCell(held, at + "predicted_rms", 1, "%.5f", "/held_out")
                         : std::string("<td></td>"))
          << "</tr>\n";
    };
    const json& stations = held.at(machine).at("stations");
    for (std::size_t s = 0; s < stations.size(); ++s) {
      if (!stations[s].contains("angular")) continue;
      row(stations[s].value("placement", std::to_string(s)),
          format("/%s/stations/%zu/angular/", machine, s));
    }
    if (held.at(machine).contains("angular_all"))
      row("all", std::string("/") + machine + "/angular_all/");
  }
  out << "</table>\n";
}

/// Held-out stations (report --held-out): deviations with the nominal and the calibrated machine.
void writeHeldOut(std::ostream& out, const ReportInput& in,
                  const std::vector<ReportFigure>& figures) {
  if (!in.held_out_json) return;
  const json& held = *in.held_out_json;
  out << "<h3>Held-out stations</h3>\n<p>The readings of <code>"
      << svg::escape(held.value("plan", "")) << "</code>, each station fitted on its stationing "
      << "readings; deviations of the others (mm).</p>\n<table>\n<tr><th>machine</th>"
      << "<th>readings</th><th>mean</th><th>RMS</th><th>max</th><th>predicted RMS</th></tr>\n";
  for (const char* machine : {"nominal", "calibrated"}) {
    const std::string at = std::string("/") + machine + "/all/";
    out << "<tr><td>" << machine << "</td>"
        << numberCell(held, at + "readings", 1, "%.0f", "/held_out")
        << numberCell(held, at + "mean", 1, "%.4f", "/held_out")
        << numberCell(held, at + "rms", 1, "%.4f", "/held_out")
        << numberCell(held, at + "max", 1, "%.4f", "/held_out")
        << (std::string(machine) == "calibrated"
                ? numberCell(held, at + "predicted_rms", 1, "%.4f", "/held_out")
                : std::string("<td></td>"))
        << "</tr>\n";
  }
  out << "</table>\n";
  writeHeldOutAngles(out, held);
  writeFigures(out, figures, "held-out");
}

/// The calibration of the plan's readings (calibrate --json, pointers under /calibration).
void writeCalibration(std::ostream& out, const ReportInput& in,
                      const std::vector<ReportFigure>& figures) {
  if (!in.calibration_json) return;
  const json& cal = *in.calibration_json;
  const std::string prefix = "/calibration";
  const bool converged = cal.at("converged").get<bool>();
  out << "<h2>Calibration of the readings</h2>\n<p class=\"verdict " << (converged ? "ok" : "bad")
      << "\" data-field=\"/calibration/converged\" data-value=\"" << (converged ? "true" : "false")
      << "\">" << (converged ? "CONVERGED" : "NOT CONVERGED") << ": "
      << svg::escape(cal.value("message", "")) << "</p>\n<table>\n<tr><th>iterations</th>"
      << "<th>chi2</th><th>dof</th><th>chi2 / dof</th><th>flagged readings</th></tr>\n<tr>"
      << numberCell(cal, "/iterations", 1, "%.0f", prefix)
      << numberCell(cal, "/chi2", 1, "%.4g", prefix) << numberCell(cal, "/dof", 1, "%.0f", prefix)
      << numberCell(cal, "/chi2_per_dof", 1, "%.4g", prefix)
      << numberCell(cal, "/flagged", 1, "%.0f", prefix) << "</tr>\n</table>\n";
  // Readings simulated by `artcal simulate`: its simulation block names the true parameters
  // (file units), and the table shows each estimate against the truth in its u.
  const json* truth = nullptr;
  if (in.document.contains("simulation") && in.document["simulation"].contains("parameters")) {
    truth = &in.document["simulation"]["parameters"];
  }
  out << "<table>\n<tr><th>parameter</th><th>nominal</th><th>estimate</th><th>unit</th>"
      << "<th>u</th><th>u posterior</th><th>unit of u</th>"
      << (truth ? "<th>truth</th><th>(estimate - truth) / u</th>" : "") << "</tr>\n";
  const json& parameters = cal.at("parameters");
  for (std::size_t k = 0; k < parameters.size(); ++k) {
    const json& p = parameters[k];
    const std::string unit = p.at("unit").get<std::string>();
    const bool mm = unit == "mm";  // u of a length in um; every other u in its own unit
    const std::string base = format("/parameters/%zu/", k);
    out << "<tr><td>" << svg::escape(p.at("name").get<std::string>()) << "</td>"
        << numberCell(cal, base + "nominal", 1, "%.4f", prefix)
        << numberCell(cal, base + "estimate", 1, "%.6f", prefix) << "<td>" << svg::escape(unit)
        << "</td>" << numberCell(cal, base + "u", mm ? 1e3 : 1.0, mm ? "%.3f" : "%.6g", prefix)
        << numberCell(cal, base + "u_posterior", mm ? 1e3 : 1.0, mm ? "%.3f" : "%.6g", prefix)
        << "<td>" << (mm ? kMicro : svg::escape(unit)) << "</td>";
    if (truth) out << truthCells(p, *truth);
    out << "</tr>\n";
  }
  out << "</table>\n";
  writeLocationErrors(out, cal, prefix);
  writeControllerTable(out, cal, prefix);
  writeCalibrationWarnings(out, cal);
  writeFigures(out, figures, "residuals");
  writeFlagged(out, cal);
  writeFigures(out, figures, "station-");
  writeHeldOut(out, in, figures);
}

/// The operator's procedure (procedure.hpp); a plan whose features cannot be reached gets a note.
void writeProcedure(std::ostream& out, const ReportInput& in) {
  if (in.procedure) {
    out << procedureHtml(in.plan, *in.procedure);
  } else if (!in.no_procedure.empty()) {
    out << "<h2>Procedure</h2>\n<p>No procedure: " << svg::escape(in.no_procedure) << "</p>\n";
  }
}

}  // namespace

/// One cell per value of `source` at `pointers` (numberCell, pointers prefixed "/acceptance").
void acceptanceCells(std::ostream& out, const json& source, const std::string& at,
                     std::initializer_list<const char*> pointers, const char* fmt) {
  for (const char* pointer : pointers) {
    const std::string full = at + pointer;
    if (source.contains(json::json_pointer(full)))
      out << numberCell(source, full, 1, fmt, "/acceptance");
    else
      out << "<td></td>";
  }
}

/// A point's joints (file units) in one cell, the exact list in data-value.
std::string jointsCell(const json& joints, const std::string& pointer) {
  std::string text;
  for (const json& q : joints)
    text += (text.empty() ? "" : ", ") + (q.is_number() ? format("%.3f", q.get<double>()) : "?");
  return "<td class=\"num\" data-field=\"/acceptance" + svg::escape(pointer) + "\" data-value=\"" +
         svg::escape(joints.dump()) + "\">" + svg::escape(text) + "</td>";
}

/// ISO 9283 (poseTestToJson): the five points, their joints and AP_P, then max AP_P and P(pass).
void writePoseTest(std::ostream& out, const json& test) {
  const json& center = test.at("center");
  out << "<p>ISO 9283 pose accuracy predicted from this plan's V_p (artcal acceptance): cube "
      << svg::escape(jsonText(test.at("cube"))) << " mm centred at ("
      << svg::escape(jsonText(center.at(0))) << ", " << svg::escape(jsonText(center.at(1))) << ", "
      << svg::escape(jsonText(center.at(2))) << ") mm, " << svg::escape(jsonText(test.at("cycles")))
      << " cycles, unmodelled error " << svg::escape(jsonText(test.value("unmodelled", json(0))))
      << " mm per coordinate; AP_P = |mean attained - commanded position| in mm, its expectation "
         "E[AP], mean, 50 % and 95 % quantiles over the calibration's residual error, the "
         "unmodelled error and the encoder noise; RP the predicted repeatability (method.md "
         "section 9).</p>\n<table>\n"
         "<tr><th>point</th><th>commanded x</th><th>y</th><th>z (mm)</th><th>joints (deg or "
         "mm)</th><th>sigma_sys</th><th>sigma_noise</th><th>sigma_unmodelled</th><th>E[AP]</th>"
         "<th>AP mean</th><th>AP 50 %</th><th>AP 95 %</th><th>RP</th></tr>\n";
  const json& items = test.at("items");
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string at = "/items/" + std::to_string(i);
    out << "<tr><td>" << svg::escape(jsonText(items[i].value("point", json("?")))) << "</td>";
    acceptanceCells(out, test, at, {"/commanded/0", "/commanded/1", "/commanded/2"}, "%.2f");
    out << jointsCell(items[i].at("joints"), at + "/joints");
    acceptanceCells(out, test, at,
                    {"/sigma_sys", "/sigma_noise", "/sigma_unmodelled", "/ap_expected", "/ap/mean",
                     "/ap/50", "/ap/95", "/rp"},
                    "%.5f");
    out << "</tr>\n";
  }
  out << "<tr><td>max over the points</td><td></td><td></td><td></td><td></td><td></td><td></td>"
         "<td></td><td></td>";
  acceptanceCells(out, test, "/max_ap", {"/mean", "/50", "/95"}, "%.5f");
  out << "<td></td></tr>\n</table>\n";
  if (!test.contains("p_pass")) return;
  out << "<table>\n<tr><th>MPE (mm)</th><th>P(every AP_P &lt;= MPE)</th><th>standard error</th>"
         "<th>Monte-Carlo trials</th></tr>\n<tr>";
  acceptanceCells(out, test, "", {"/mpe"}, "%.4g");
  acceptanceCells(out, test, "", {"/p_pass", "/p_pass_standard_error"}, "%.4f");
  acceptanceCells(out, test, "", {"/monte_carlo/trials"}, "%.0f");
  out << "</tr>\n</table>\n";
}

/// ISO 10360-2 (lengthTestToJson): P(pass) and the quantiles of max |E|/MPE (the gauges are in
/// the figure).
void writeLengthTestSummary(std::ostream& out, const json& test) {
  out << "<table>\n<tr><th>E0,MPE (" << kMicro << ", L in mm)</th><th>P(pass)</th>"
      << "<th>standard error</th><th>max |E|/MPE, 50 %</th><th>95 %</th>"
      << "<th>Monte-Carlo trials</th></tr>\n<tr><td>"
      << svg::escape(jsonText(test.value("mpe", json("?")))) << "</td>";
  acceptanceCells(out, test, "", {"/p_pass", "/p_pass_standard_error"}, "%.4f");
  acceptanceCells(out, test, "/quantiles", {"/50", "/95"}, "%.3f");
  acceptanceCells(out, test, "", {"/monte_carlo/trials"}, "%.0f");
  out << "</tr>\n</table>\n";
}

/// The plan's acceptance test predicted: its figure (acceptance_report.hpp, added by the
/// caller) and its figures from `acceptance_json`.
void writeAcceptance(std::ostream& out, const ReportInput& in,
                     const std::vector<ReportFigure>& figures) {
  const bool drawn = std::any_of(figures.begin(), figures.end(), [](const ReportFigure& f) {
    return f.name.starts_with("acceptance");
  });
  if (!drawn && !in.acceptance_json) return;
  out << "<h2>Acceptance test predicted</h2>\n";
  writeFigures(out, figures, "acceptance");
  if (!in.acceptance_json) return;
  if (in.acceptance_json->value("test", "") == "iso9283") {
    writePoseTest(out, *in.acceptance_json);
  } else {
    writeLengthTestSummary(out, *in.acceptance_json);
  }
}

std::vector<ReportFigure> reportFigures(const ReportInput& in) {
  const Plan& plan = in.plan;
  const std::vector<Eigen::MatrixXd>& features = in.evaluation.placed_features;
  std::vector<ReportFigure> figures;
  const bool spatial = plan.machine.dimension() == 3;
  const std::string layout_caption =
      reachAnnulus(plan.machine)
          ? "Artifact placements (numbered from 0, as in the plan file and every table), each "
            "feature (circle) and each reading's probe position (cross) with the arm's links "
            "faint, inside the reach annulus."
          : "Artifact placements (numbered from 0, as in the plan file and every table), each "
            "feature (circle) and each reading's probe position (cross); grey: where the "
            "workspace samples lie.";
  figures.push_back({"layout", layout_caption, layoutPlot(in, features, View::Plan).render()});
  if (spatial) {
    figures.push_back(
        {"layout-side", layout_caption, layoutPlot(in, features, View::Side).render()});
  }
  if (in.calibration_json)
    figures.push_back(residualFigure(*in.calibration_json, in.flag_threshold));
  if (!in.evaluation.identifiable() || !in.evaluation.tip) return figures;
  if (in.evaluation_json.contains("profile")) figures.push_back(profileFigure(in));
  std::vector<double> totals_um = in.evaluation.workspace_total;
  for (double& s : totals_um) s *= 1e3;
  figures.push_back(tipMapFigure(in, totals_um, features, View::Plan));
  if (spatial) figures.push_back(tipMapFigure(in, totals_um, features, View::Side));
  if (in.evaluation_json.contains("correlation")) figures.push_back(correlationFigure(in));
  return figures;
}

std::string htmlReport(const ReportInput& in, const std::vector<ReportFigure>& figures) {
  const json& ev = in.evaluation_json;
  std::ostringstream out;
  writeHead(out, in.plan);
  writeVerdict(out, ev);
  out << "<h2>Layout</h2>\n";
  writeFigures(out, figures, "layout");
  writeDesign(out, in);
  writeParameters(out, ev);
  writeLocationErrors(out, ev, "");
  if (!in.evaluation.identifiable()) {
    out << "<p>No uncertainties: the plan does not identify every calibrated parameter.</p>\n";
  }
  writeFigures(out, figures, "correlation");
  if (ev.contains("tip")) out << "<h2>Tip uncertainty</h2>\n";
  writeTipSummary(out, in.plan, ev);
  writeFigures(out, figures, "tip");
  writeProfileTable(out, ev);
  writeCalibration(out, in, figures);
  // A Cartesian CMM's error functions along its axes (cartesian_report.hpp, added by the caller).
  if (std::any_of(figures.begin(), figures.end(),
                  [](const ReportFigure& f) { return f.name.starts_with("error-functions"); })) {
    out << "<h2>Error functions</h2>\n";
    writeFigures(out, figures, "error-functions");
  }
  writeAcceptance(out, in, figures);
  writeProcedure(out, in);
  out << "</body>\n</html>\n";
  return out.str();
}

}  // namespace artcal
