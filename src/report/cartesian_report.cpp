#include "artcal/report/cartesian_report.hpp"
#include "artcal/report/text_format.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <sstream>

#include "artcal/report/svg.hpp"

namespace artcal {

namespace {

constexpr double kUmPerMm = 1000.0;
constexpr double kUmPerMPerRad = 1e6;

// Table value: um for translations, um/m for rotations (internal mm, rad).
double tableValue(bool rotation, double internal) {
  return internal * (rotation ? kUmPerMPerRad : kUmPerMm);
}
// JSON value: mm for translations, um/m for rotations (the parameters' file units).
double fileValue(bool rotation, double internal) {
  return rotation ? internal * kUmPerMPerRad : internal;
}

using report_text::format;

std::string axisName(const Eigen::Vector3d& axis) {
  for (int a = 0; a < 3; ++a) {
    if (std::abs(std::abs(axis[a]) - 1.0) < 1e-9)
      return std::string(axis[a] > 0 ? "+" : "-") + "xyz"[a];
  }
  return "[" + format("%.3f", axis[0]) + ", " + format("%.3f", axis[1]) + ", " +
         format("%.3f", axis[2]) + "]";
}

// The three functions of one plot differ by line style and marker shape (greyscale printing).
constexpr svg::Dash kDashes[] = {svg::Dash::Solid, svg::Dash::Dashed, svg::Dash::Dotted};
constexpr svg::Shape kShapes[] = {svg::Shape::Circle, svg::Shape::Square, svg::Shape::Triangle};

std::string joined(const std::vector<double>& values) {
  std::string out;
  for (const double v : values) {
    if (!out.empty()) out += ' ';
    out += format("%.17g", v);
  }
  return out;
}

// One curve of a function: polyline through (position, value) with its numbers as attributes.
void drawCurve(svg::Plot& plot, const ErrorFunctionProfile& f, const std::vector<double>& position,
               const std::vector<double>& value, const char* curve, const svg::Style& style,
               const std::string& legend) {
  std::vector<Eigen::Vector2d> points;
  for (std::size_t i = 0; i < position.size(); ++i) points.emplace_back(position[i], value[i]);
  plot.polyline(points, style, legend,
                {{"data-function", f.name},
                 {"data-curve", curve},
                 {"data-position", joined(position)},
                 {"data-value", joined(value)}});
}

// e(u) +- u_e(u) of the translations (rotations) of one axis, table units.
svg::Plot bandPlot(const CartesianAxis& axis, const std::vector<ErrorFunctionProfile>& functions,
                   bool rotations, bool calibrated) {
  const std::string unit = std::string(report_text::kMicroSign) + (rotations ? "m/m" : "m");
  svg::Plot plot("error-functions-" + axis.name + (rotations ? "-rotations" : "-translations"),
                 std::string(calibrated ? "Calibrated " : "Predicted u of ") + "axis " + axis.name +
                     (rotations ? " rotations" : " translations"),
                 axis.name + " reading / mm", (calibrated ? "e(u) +- u / " : "+- u / ") + unit);
  int shown = 0;
  for (const ErrorFunctionProfile& f : functions) {
    if (f.rotation != rotations) continue;
    const int k = shown++;
    std::vector<double> centre, lower, upper;
    for (std::size_t i = 0; i < f.position.size(); ++i) {
      centre.push_back(tableValue(f.rotation, f.value[i]));
      lower.push_back(centre.back() - tableValue(f.rotation, f.u[i]));
      upper.push_back(centre.back() + tableValue(f.rotation, f.u[i]));
    }
    svg::Style style;
    style.dash = kDashes[k];
    style.width = 1.2;
    const std::string legend = f.name + " (" + f.meaning + ")";
    drawCurve(plot, f, f.position, lower, "lower", style, legend);
    drawCurve(plot, f, f.position, upper, "upper", style, {});
    if (calibrated) {
      svg::Style thick = style;
      thick.width = 2.0;
      drawCurve(plot, f, f.position, centre, "centre", thick, {});
      for (std::size_t i = 0; i < f.position.size(); ++i) {
        svg::Style mark;
        mark.fill = "#ffffff";
        plot.marker({f.position[i], centre[i]}, kShapes[k], 4.0, mark);
      }
    }
  }
  return plot;
}

// (estimate - truth) / u_e of every function of one axis; points where u_e vanishes are left out.
svg::Plot recoveryPlot(const CartesianAxis& axis, const std::vector<ErrorFunctionProfile>& estimate,
                       const std::vector<ErrorFunctionProfile>& truth) {
  svg::Plot plot("error-functions-" + axis.name + "-recovery",
                 "Axis " + axis.name + ": estimate minus truth in standard uncertainties",
                 axis.name + " reading / mm", "(estimate - truth) / u");
  int shown = 0;
  for (std::size_t j = 0; j < estimate.size(); ++j) {
    const ErrorFunctionProfile& f = estimate[j];
    const double largest = *std::max_element(f.u.begin(), f.u.end());
    if (!(largest > 0.0)) continue;  // no calibrated degree
    const int k = shown++;
    std::vector<double> position, ratio;
    for (std::size_t i = 0; i < f.position.size(); ++i) {
      if (f.u[i] <= 1e-9 * largest) continue;
      position.push_back(f.position[i]);
      ratio.push_back((f.value[i] - truth[j].value[i]) / f.u[i]);
    }
    svg::Style style;
    style.dash = kDashes[k % 3];
    style.width = f.rotation ? 1.2 : 2.0;
    drawCurve(plot, f, position, ratio, "recovery", style, f.name);
  }
  svg::Style limit;
  limit.stroke = "#777777";
  limit.dash = svg::Dash::Dashed;
  limit.width = 1.0;
  for (const double y : {-3.0, 3.0}) {
    plot.polyline({{axis.range[0], y}, {axis.range[1], y}}, limit, y > 0 ? "+-3 u" : "");
  }
  return plot;
}

}  // namespace

nlohmann::json cartesianAnswersToJson(const Plan& plan, const CartesianAnswers& answers) {
  nlohmann::json out = nlohmann::json::object();
  if (!axisErrorFunctionsOf(plan)) return out;
  nlohmann::json absorbed = nlohmann::json::array();
  for (std::size_t r = 0; r < answers.absorbed.size(); ++r) {
    const AbsorbedRotation& rotation = answers.absorbed[r];
    absorbed.push_back({{"axis", {rotation.axis[0], rotation.axis[1], rotation.axis[2]}},
                        {"involves", rotation.involves},
                        {"held", answers.held_by_frame[r]}});
  }
  out["frame_rotations_absorbed"] = absorbed;
  nlohmann::json unseparated = nlohmann::json::array();
  for (const auto& f : answers.unseparated) {
    unseparated.push_back(
        {{"function", f.function}, {"meaning", f.meaning}, {"degrees", f.degrees}});
  }
  out["unseparated_functions"] = unseparated;
  if (!answers.profiles.empty()) {
    nlohmann::json functions = nlohmann::json::array();
    for (const ErrorFunctionProfile& f : answers.profiles) {
      nlohmann::json profile = nlohmann::json::array();
      for (std::size_t i = 0; i < f.position.size(); ++i) {
        profile.push_back({{"position", f.position[i]},
                           {"value", fileValue(f.rotation, f.value[i])},
                           {"u", fileValue(f.rotation, f.u[i])}});
      }
      functions.push_back({{"name", f.name},
                           {"meaning", f.meaning},
                           {"unit", f.rotation ? "um/m" : "mm"},
                           {"calibrated_degrees", f.calibrated_degrees},
                           {"fixed_degrees", f.fixed_degrees},
                           {"profile", profile}});
    }
    out["error_functions"] = functions;
  }
  return out;
}

std::string cartesianAnswersTable(const Plan& plan, const CartesianAnswers& answers) {
  const AxisErrorFunctions* cmm = axisErrorFunctionsOf(plan);
  if (!cmm) return {};
  std::ostringstream out;
  out << "\nFrame rotations the placements absorb (any artifact calibration; not a plan defect)\n";
  if (answers.absorbed.empty()) out << "  none: the styli's offsets fix the frame's rotations\n";
  for (std::size_t r = 0; r < answers.absorbed.size(); ++r) {
    const AbsorbedRotation& rotation = answers.absorbed[r];
    out << "  about " << axisName(rotation.axis) << ": squareness terms";
    for (const std::string& name : rotation.involves) out << ' ' << name;
    out << " move together";
    if (!answers.held_by_frame[r].empty()) out << "; " << answers.held_by_frame[r] << " held at 0";
    out << '\n';
  }
  out << "Error functions this plan leaves unseparated\n";
  if (answers.unseparated.empty()) out << "  none\n";
  for (const auto& f : answers.unseparated) {
    out << "  " << f.function << " (" << f.meaning << "), degree";
    if (f.degrees.size() > 1) out << 's';
    for (std::size_t i = 0; i < f.degrees.size(); ++i) out << (i ? ", " : " ") << f.degrees[i];
    out << '\n';
  }
  if (answers.profiles.empty()) return out.str();
  out << "\nError functions: predicted u along each axis (um; rotations um/m)\n"
      << "  function  meaning                 degrees   at start    at mid    at end   largest\n";
  for (const ErrorFunctionProfile& f : answers.profiles) {
    std::string degrees;
    for (int n : f.calibrated_degrees) {
      if (!degrees.empty()) degrees += ',';
      degrees += std::to_string(n);
    }
    if (degrees.empty()) degrees = "-";
    const std::size_t mid = f.u.size() / 2;
    const double largest = *std::max_element(f.u.begin(), f.u.end());
    char line[160];
    std::snprintf(line, sizeof line, "  %-8s  %-22s  %-7s %9.3f %9.3f %9.3f %9.3f\n",
                  f.name.c_str(), f.meaning.c_str(), degrees.c_str(),
                  tableValue(f.rotation, f.u.front()), tableValue(f.rotation, f.u[mid]),
                  tableValue(f.rotation, f.u.back()), tableValue(f.rotation, largest));
    out << line;
  }
  return out.str();
}

std::vector<ReportFigure> errorFunctionFigures(const Plan& plan, const ErrorFunctionBands& bands) {
  std::vector<ReportFigure> figures;
  const AxisErrorFunctions* cmm = axisErrorFunctionsOf(plan);
  if (!cmm || bands.profiles.empty()) return figures;
  const bool calibrated = bands.calibrated;
  const std::vector<ErrorFunctionProfile>& profiles = bands.profiles;
  const std::vector<ErrorFunctionProfile>& truths = bands.truth;
  const bool truth = !truths.empty();
  const std::string band = calibrated
                               ? "the calibrated estimate e(u) (markers) between e - u and e + u"
                               : "the band +- u of the predicted standard uncertainty";
  for (int k = 0; k < static_cast<int>(cmm->axes().size()); ++k) {
    const CartesianAxis& axis = cmm->axes()[static_cast<std::size_t>(k)];
    const auto first = static_cast<std::ptrdiff_t>(k * kAxisErrorCount);
    const std::vector<ErrorFunctionProfile> functions(profiles.begin() + first,
                                                      profiles.begin() + first + kAxisErrorCount);
    for (const bool rotations : {false, true}) {
      const std::string name =
          "error-functions-" + axis.name + (rotations ? "-rotations" : "-translations");
      figures.push_back({name,
                         "Axis " + axis.name +
                             (rotations ? " rotations (um/m)" : " translations (um)") +
                             " along the axis: " + band + " of each error function.",
                         bandPlot(axis, functions, rotations, calibrated).render()});
    }
    if (truth) {
      const std::vector<ErrorFunctionProfile> true_functions(
          truths.begin() + first, truths.begin() + first + kAxisErrorCount);
      figures.push_back({"error-functions-" + axis.name + "-recovery",
                         "Axis " + axis.name +
                             ": the calibrated error functions minus those of the simulated "
                             "machine, in standard uncertainties (within +-3 where the "
                             "calibration recovers them).",
                         recoveryPlot(axis, functions, true_functions).render()});
    }
  }
  return figures;
}

}  // namespace artcal
