#include "artcal/report/sweep_report.hpp"
#include "artcal/report/text_format.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "artcal/report/report.hpp"
#include "artcal/report/svg.hpp"

namespace artcal {

using nlohmann::json;

namespace {

using report_text::fixed;

/// A table cell: a number of the summary in display units, or "-" for null.
std::string cell(const json& value, double scale, int decimals, int width) {
  std::string text = value.is_number() ? fixed(value.get<double>() * scale, decimals) : "-";
  return std::string(text.size() < static_cast<std::size_t>(width) ? width - text.size() : 1, ' ') +
         text;
}

/// Lengths shown in um, angles and coefficients in their own unit.
std::string displayUnit(const std::string& unit) {
  return unit == "mm" ? "um" : unit;
}
double displayScale(const std::string& unit) {
  return unit == "mm" ? 1e3 : 1.0;
}

}  // namespace

json sweepSummaryToJson(const Plan& spec, const PlacementSweep& sweep,
                        const std::vector<SweepLine>& lines, std::optional<double> target) {
  json parameters = json::array();
  for (int k = 0; k < spec.machine.calibratedCount(); ++k) {
    const ParameterInfo& info = spec.machine.calibratedInfo(k);
    parameters.push_back({{"name", info.name}, {"unit", std::string(unitName(info.quantity))}});
  }
  json counts = json::array();
  for (const SweepLine& line : lines) {
    const SweepPoint& point = *line.point;
    json row = {{"placements", point.placements},
                {"plan", line.file.empty() ? json(nullptr) : json(line.file)},
                {"value", finiteOrNull(point.value)},
                {"fresh", finiteOrNull(point.fresh)},
                {"extended", point.extended},
                {"seconds", point.seconds},
                {"message", point.message.empty() ? json(nullptr) : json(point.message)}};
    const json& ev = line.evaluation;
    const bool has_tip = ev.is_object() && ev.contains("tip");
    row["tip_worst"] = has_tip ? ev["tip"]["worst"]["total"] : json(nullptr);
    row["tip_mean"] = has_tip ? ev["tip"]["mean"] : json(nullptr);
    json u = json::array();
    if (ev.is_object() && ev.contains("parameters")) {
      for (const json& p : ev["parameters"]) u.push_back(p.contains("u") ? p["u"] : json(nullptr));
    }
    row["u"] = u;
    counts.push_back(row);
  }
  return {
      {"spec", spec.name},
      {"criterion", criterionName(spec.design->criterion)},
      {"unit", "mm"},
      {"target_tip", target ? json(*target) : json(nullptr)},
      {"smallest_reaching",
       sweep.first_reaching ? json(sweep.points[*sweep.first_reaching].placements) : json(nullptr)},
      {"parameters", parameters},
      {"counts", counts}};
}

std::string sweepSummaryTable(const json& summary) {
  std::ostringstream out;
  out << "artcal optimize --placements: " << summary.at("spec").get<std::string>() << ", criterion "
      << summary.at("criterion").get<std::string>() << " (G)\n\n";
  out << "     m         G um    mean S um";
  for (const json& p : summary.at("parameters")) {
    const std::string head = "u(" + p.at("name").get<std::string>() + ") " +
                             displayUnit(p.at("unit").get<std::string>());
    out << std::string(head.size() < 14 ? 14 - head.size() : 1, ' ') << head;
  }
  out << "   from\n";
  for (const json& row : summary.at("counts")) {
    out << cell(row.at("placements"), 1, 0, 6) << cell(row.at("value"), 1e3, 3, 13)
        << cell(row.at("tip_mean"), 1e3, 3, 13);
    for (std::size_t k = 0; k < row.at("u").size(); ++k) {
      const std::string unit = summary["parameters"][k].at("unit").get<std::string>();
      out << cell(row["u"][k], displayScale(unit), unit == "mm" ? 3 : 6, 14);
    }
    out << "   "
        << (row.at("value").is_null()        ? "no design"
            : row.at("extended").get<bool>() ? "m-1 + 1"
                                             : "fresh")
        << "\n";
  }
  if (!summary.at("target_tip").is_null()) {
    out << "\ntarget G <= " << fixed(summary["target_tip"].get<double>() * 1e3, 3) << " um: ";
    if (summary.at("smallest_reaching").is_null()) {
      out << "no count in this range reaches it\n";
    } else {
      out << "reached with m = " << summary["smallest_reaching"].get<int>() << " placements\n";
    }
  }
  return out.str();
}

std::string sweepFigure(const json& summary) {
  svg::Plot plot("placements-sweep", "Criterion G and mean S against the number of placements",
                 "placements m", "um");
  std::vector<Eigen::Vector2d> g, mean;
  for (const json& row : summary.at("counts")) {
    const double m = row.at("placements").get<double>();
    if (row.at("value").is_number()) g.emplace_back(m, row["value"].get<double>() * 1e3);
    if (row.at("tip_mean").is_number()) mean.emplace_back(m, row["tip_mean"].get<double>() * 1e3);
  }
  svg::Style solid;
  solid.width = 2.0;
  svg::Style dashed = solid;
  dashed.dash = svg::Dash::Dashed;
  plot.polyline(g, solid, "G (" + summary.at("criterion").get<std::string>() + ")");
  for (const Eigen::Vector2d& p : g) plot.marker(p, svg::Shape::Circle, 6.0, solid);
  plot.polyline(mean, dashed, "mean S");
  for (const Eigen::Vector2d& p : mean) plot.marker(p, svg::Shape::Square, 6.0, dashed);
  if (!summary.at("target_tip").is_null() && !g.empty()) {
    svg::Style dotted = solid;
    dotted.dash = svg::Dash::Dotted;
    const double t = summary["target_tip"].get<double>() * 1e3;
    plot.polyline({{g.front().x(), t}, {g.back().x(), t}}, dotted, "target");
  }
  double top = 0.0;  // G >= mean S: the axis from 0 to the largest G
  for (const auto& p : g) top = std::max(top, p.y());
  plot.setYRange(0.0, std::max(top * 1.05, 1e-9));
  return plot.render();
}

}  // namespace artcal
