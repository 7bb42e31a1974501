// The "Procedure" section of the HTML report (procedure.hpp): one block per placement, in
// measuring order, with the pose, the table of readings with their target joints and a drawing
// of the mechanism in each posture (Mechanism::skeleton; planar: one view, 3-D: plan, side and
// oblique views).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "artcal/report/procedure.hpp"
#include "artcal/report/report.hpp"
#include "artcal/report/svg.hpp"

namespace artcal {

namespace {

enum class ProcedureView { Plan, Side, Oblique };

/// Beyond this many placements the procedure has tables only: drawings of every posture of a
/// thousand placements would make the page tens of megabytes (docs/report.md).
constexpr std::size_t kMaxDrawnPlacements = 60;

/// Projection of a machine point: plan (x, y), side (x, z), or an oblique view from the
/// (+x, -y, +z) side (isometric axes: x and y at -/+30 deg from the horizontal, z up).
Eigen::Vector2d projectPoint(const Eigen::VectorXd& x, ProcedureView view) {
  if (x.size() < 3 || view == ProcedureView::Plan) return {x[0], x[1]};
  if (view == ProcedureView::Side) return {x[0], x[2]};
  const double c = std::cos(kDegree * 30.0), s = std::sin(kDegree * 30.0);
  return {c * (x[0] + x[1]), x[2] + s * (x[1] - x[0])};
}

const char* viewTitle(ProcedureView view) {
  switch (view) {
    case ProcedureView::Plan:
      return "plan (XY)";
    case ProcedureView::Side:
      return "side (XZ)";
    case ProcedureView::Oblique:
      return "oblique";
  }
  return "";
}

std::string number(double value, int decimals) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

svg::Style postureStyle(int posture, double opacity) {
  static const svg::Dash dashes[] = {svg::Dash::Solid, svg::Dash::Dashed, svg::Dash::Dotted};
  svg::Style style;
  style.stroke = posture % 2 ? "#3b528b" : "#000000";
  style.dash = dashes[posture % 3];
  style.width = 1.4;
  style.opacity = opacity;
  return style;
}

/// One view of one placement: the mechanism in each reading's posture, the probe positions
/// (crosses) and the placed features (circles, numbered).
std::string placementView(const Plan& plan, const ProcedurePlacement& placement, std::size_t j,
                          ProcedureView view, double size, bool legend) {
  // Small views share one legend below them (viewLegend): a legend of each would be as tall as
  // its plot.
  auto named = [legend](const std::string& text) { return legend ? text : std::string(); };
  const Machine& machine = plan.machine;
  const bool spatial = machine.dimension() == 3;
  const std::string title = "Placement " + placementLabel(plan.placements, j) +
                            (spatial ? std::string(", ") + viewTitle(view) : std::string());
  const char* x_label = view == ProcedureView::Oblique ? "oblique u / mm" : "x / mm";
  const char* y_label = view == ProcedureView::Plan   ? "y / mm"
                        : view == ProcedureView::Side ? "z / mm"
                                                      : "oblique v / mm";
  svg::Plot plot("procedure-" + std::to_string(j) + "-" + std::string(viewTitle(view)).substr(0, 4),
                 title, x_label, y_label, size, size);
  plot.setEqualAspect(true);
  svg::Style base;
  base.fill = "#000000";
  plot.marker(projectPoint(Eigen::Vector3d::Zero().head(machine.dimension()), view),
              svg::Shape::Square, 8.0, base, named("machine origin"));
  const double opacity = std::clamp(std::sqrt(6.0 / placement.readings.size()), 0.25, 1.0);
  for (const ProcedureReading& r : placement.readings) {
    const std::vector<Eigen::VectorXd> skeleton =
        machine.mechanism->skeleton(machine.nominal, r.target);
    std::vector<Eigen::Vector2d> points;
    for (const Eigen::VectorXd& point : skeleton) points.push_back(projectPoint(point, view));
    plot.polyline(points, postureStyle(r.posture, opacity),
                  named("posture " + std::to_string(r.posture)));
    svg::Style probe;
    plot.marker(projectPoint(r.position, view), svg::Shape::Cross, 6.0, probe, named("probe"));
  }
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  const Eigen::MatrixXd& features = placement.features;
  std::vector<Eigen::Vector2d> outline;
  svg::Style ball;
  ball.stroke = "#21918c";
  ball.width = 2.0;
  for (int i = 0; i < features.cols(); ++i) {
    const Eigen::Vector2d at = projectPoint(features.col(i), view);
    outline.push_back(at);
    plot.marker(at, svg::Shape::Circle, 9.0, ball, named("feature"));
    // At most about 12 numbers, so that they do not overlap on a large plate: every k-th, and
    // the last one, which tells the count.
    const int stride = static_cast<int>((features.cols() + 11) / 12);
    if (i % stride == 0 || i == features.cols() - 1) plot.label(at, std::to_string(i));
  }
  if (artifact.kind().drawn_as_line) plot.polyline(outline, ball);
  return plot.render();
}

/// The legend the small views share, in the views' own styles: the postures drawn, the probe,
/// the features and the machine origin.
std::string viewLegend(const ProcedurePlacement& placement) {
  int postures = 0;
  for (const ProcedureReading& r : placement.readings) postures = std::max(postures, r.posture + 1);
  std::ostringstream out;
  out << "<p class=\"view-legend\">";
  for (int k = 0; k < std::min(postures, 6); ++k) {
    const svg::Style style = postureStyle(k, 1.0);
    const char* dash = style.dash == svg::Dash::Dashed   ? " stroke-dasharray=\"8 4\""
                       : style.dash == svg::Dash::Dotted ? " stroke-dasharray=\"1.5 3\""
                                                         : "";
    out << "<svg width=\"28\" height=\"10\"><line x1=\"1\" y1=\"5\" x2=\"27\" y2=\"5\" stroke=\""
        << style.stroke << "\" stroke-width=\"1.6\"" << dash << "/></svg> posture " << k
        << " &#160; ";
  }
  if (postures > 6) out << "(the styles repeat every 6 postures) &#160; ";
  out << "&#215; probe &#160; <span style=\"color:#21918c\">&#9675;</span> feature (numbered) "
         "&#160; &#9632; machine origin</p>\n";
  return out.str();
}

void writeReadingsTable(std::ostream& out, const Plan& plan, const ProcedurePlacement& placement) {
  const Machine& machine = plan.machine;
  const bool styli = machine.mechanism->stylusCount() > 1;
  static const char* axes[] = {"x", "y", "z"};
  out << "<table class=\"procedure\">\n<tr><th>reading</th><th>feature</th><th>posture</th>"
      << (styli ? "<th>stylus</th>" : "");
  for (int d = 0; d < machine.dimension(); ++d) out << "<th>" << axes[d] << " / mm</th>";
  for (int i = 0; i < machine.jointCount(); ++i) {
    out << "<th>" << jointLabel(*machine.mechanism, i) << " / "
        << unitName(jointQuantity(machine.mechanism->jointKind(i))) << "</th>";
  }
  out << "</tr>\n";
  for (std::size_t k = 0; k < placement.readings.size(); ++k) {
    const ProcedureReading& r = placement.readings[k];
    out << "<tr><td class=\"num\">" << k << "</td><td class=\"num\">" << r.feature
        << "</td><td class=\"num\">" << r.posture << "</td>";
    if (styli) out << "<td class=\"num\">" << r.stylus << "</td>";
    for (int d = 0; d < r.position.size(); ++d) {
      out << "<td class=\"num\">" << number(r.position[d], 3) << "</td>";
    }
    for (const double value : jointsToFile(machine, r.target)) {
      out << "<td class=\"num\">" << number(value, 4) << "</td>";
    }
    out << "</tr>\n";
  }
  out << "</table>\n";
}

std::string poseLine(const Plan& plan, const ProcedurePlacement& placement) {
  const Pose& pose = placement.pose;
  std::string out = "centre (";
  for (int d = 0; d < pose.center.size(); ++d) out += (d ? ", " : "") + number(pose.center[d], 3);
  out += ") mm";
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  if (artifact.translatesOnly()) {  // a sphere or a table ball: its centre is all there is
    out += std::string(" (") + artifact.kind().centre + " in the workpiece frame)";
  } else if (plan.machine.dimension() == 2) {
    out += ", angle " + number(radToDeg(pose.angle), 3) + " deg";
  } else {
    const Eigen::Vector3d d = pose.direction.normalized();
    out += ", direction (" + number(d.x(), 4) + ", " + number(d.y(), 4) + ", " + number(d.z(), 4) +
           "), roll " + number(radToDeg(pose.roll), 3) + " deg";
  }
  return out + (placement.pose_from_plan ? "" : " (fitted to the readings)");
}

}  // namespace

std::string procedureHtml(const Plan& plan, const Procedure& procedure) {
  std::ostringstream out;
  const bool spatial = plan.machine.dimension() == 3;
  const bool drawn =
      !plan.placements.empty() && !plan.placements[0].measurements.empty() &&
      !plan.machine.mechanism
           ->skeleton(plan.machine.nominal, plan.placements[0].measurements[0].joints)
           .empty();
  const bool draw = procedure.placements.size() <= kMaxDrawnPlacements;
  out << "<h2>Procedure</h2>\n<p>The placements in measuring order. For each: where the artifact "
         "goes (its centre in the machine frame, "
      << (spatial ? "its X axis direction and its roll about it" : "the direction of its X axis")
      << "), and for each reading the feature, the posture (the k-th reading of that feature, "
         "from 0) and the target joint values on the nominal machine. "
      << (!draw   ? "No drawings: more than 60 placements (tables only)."
          : drawn ? "The drawings show the mechanism in each posture (line style by posture), "
                    "each probe position (cross) and the artifact's features (circles, numbered)."
                  : "The drawings show each probe position (cross) and the artifact's features "
                    "(circles, numbered); this model has no drawing of its links.")
      << " Same as <code>artcal procedure</code>.</p>\n";
  for (std::size_t j = 0; j < procedure.placements.size(); ++j) {
    const ProcedurePlacement& placement = procedure.placements[j];
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    out << "<section class=\"placement\">\n<h3>Placement "
        << svg::escape(placementLabel(plan.placements, j)) << ": " << svg::escape(artifact.id)
        << " (" << artifactTypeName(artifact) << ")</h3>\n"
        << "<p>" << svg::escape(poseLine(plan, placement)) << "</p>\n";
    if (draw) {
      out << "<div class=\"views\">\n";
      if (spatial) {
        for (const ProcedureView view :
             {ProcedureView::Plan, ProcedureView::Side, ProcedureView::Oblique}) {
          out << placementView(plan, placement, j, view, 300.0, false);
        }
      } else {
        out << placementView(plan, placement, j, ProcedureView::Plan, 360.0, true);
      }
      out << "</div>\n";
      if (spatial) out << viewLegend(placement);
    }
    writeReadingsTable(out, plan, placement);
    out << "</section>\n";
  }
  return out.str();
}

}  // namespace artcal
