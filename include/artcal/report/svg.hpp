#pragma once
// A small SVG plotting layer for the report (html_report.hpp): a 2-D plot with axes (units,
// ticks, grid), a legend, polylines, circles, markers and filled cells, and a matrix heat map.
// Geometry is given in data coordinates; the plot maps it to pixels when rendered. Every text
// that reaches the SVG is escaped, so the output is well-formed XML.
//
// Colours are meant to survive greyscale printing: the sequential map is viridis (its
// luminance rises monotonically), and series differ by line style (solid, dashed, dotted) and
// marker shape, not by hue alone.

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace artcal::svg {

/// Text escaped for XML content and attribute values (& < > " ').
std::string escape(std::string_view text);

/// A coordinate in pixels, one decimal: compact and exact enough on screen and paper.
std::string pixel(double value);

/// Tick values covering [lo, hi]: steps of 1, 2 or 5 times a power of ten, about `target` ticks.
std::vector<double> niceTicks(double lo, double hi, int target = 6);

/// A tick label with the decimals its step needs ("0.5", "100", "-2.25").
std::string tickLabel(double value, double step);

/// Viridis colour of t in [0, 1] (clamped), as "#rrggbb".
std::string viridis(double t);

enum class Dash { Solid, Dashed, Dotted };
enum class Shape { Circle, Square, Triangle, Diamond, Cross };

struct Style {
  std::string stroke = "#000000";
  std::string fill = "none";
  Dash dash = Dash::Solid;
  double width = 1.5;    ///< px
  double opacity = 1.0;  ///< of the whole element
};

/// Extra attributes of an element, e.g. {"data-field", "/tip/worst/total"}; values are escaped.
using Attributes = std::vector<std::pair<std::string, std::string>>;

class Plot {
 public:
  /// `id` prefixes the SVG ids (clip path), so several plots can share one HTML page.
  Plot(std::string id, std::string title, std::string x_label, std::string y_label,
       double width = 640.0, double height = 420.0);

  /// One unit on x as long as one unit on y (maps, layouts).
  void setEqualAspect(bool equal) { equal_aspect_ = equal; }
  /// Fixed axis ranges; otherwise the data's bounds, padded.
  void setXRange(double lo, double hi) { x_range_ = {lo, hi}; }
  void setYRange(double lo, double hi) { y_range_ = {lo, hi}; }
  /// A viridis colour bar on the right for values in [lo, hi].
  void setColourBar(double lo, double hi, std::string label);

  void polyline(const std::vector<Eigen::Vector2d>& points, const Style& style,
                const std::string& legend = {}, const Attributes& attributes = {});
  void circle(const Eigen::Vector2d& center, double radius, const Style& style,
              const std::string& legend = {});
  /// A marker of fixed pixel size at a data point; `tooltip` becomes its <title>.
  void marker(const Eigen::Vector2d& point, Shape shape, double size, const Style& style,
              const std::string& legend = {}, const Attributes& attributes = {},
              const std::string& tooltip = {});
  /// A filled rectangle between two data corners (heat-map cells).
  void cell(const Eigen::Vector2d& corner_a, const Eigen::Vector2d& corner_b,
            const std::string& fill, const Attributes& attributes = {});
  /// A short text next to a data point.
  void label(const Eigen::Vector2d& point, const std::string& text);

  std::string render() const;

 private:
  struct Frame;  // data -> pixel mapping of one rendering
  using Painter = std::function<void(std::ostream&, const Frame&)>;
  struct LegendEntry {
    std::string text;
    Style style;
    std::optional<Shape> shape;
  };

  void include(const Eigen::Vector2d& point);
  void addLegend(const std::string& text, const Style& style, std::optional<Shape> shape);
  Frame frame() const;
  void renderAxes(std::ostream& out, const Frame& f) const;
  void renderLegend(std::ostream& out, const Frame& f) const;
  void renderColourBar(std::ostream& out, const Frame& f) const;
  int legendRows() const;

  std::string id_, title_, x_label_, y_label_;
  double width_, height_;
  bool equal_aspect_ = false;
  std::optional<std::pair<double, double>> x_range_, y_range_;
  Eigen::Vector2d lo_, hi_;
  bool empty_ = true;
  std::vector<Painter> painters_;
  std::vector<LegendEntry> legend_;
  struct ColourBar {
    double lo, hi;
    std::string label;
  };
  std::optional<ColourBar> colour_bar_;
};

/// A square matrix as a heat map (viridis over [lo, hi]) with row/column labels and each value
/// printed in its cell; cell (i, j) carries data-field = field_prefix + "/i/j" and data-value.
std::string matrixHeatMap(const std::string& id, const std::string& title,
                          const std::vector<std::string>& labels, const Eigen::MatrixXd& values,
                          double lo, double hi, const std::string& field_prefix);

/// The SVG of a marker shape centred at pixel (x, y), for legends and plots.
std::string markerElement(Shape shape, double x, double y, double size, const Style& style);

}  // namespace artcal::svg
