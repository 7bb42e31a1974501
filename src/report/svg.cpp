#include "artcal/report/svg.hpp"
#include "artcal/report/text_format.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace artcal::svg {

namespace {

using report_text::format;

constexpr double kFontSize = 12.0;
constexpr double kLegendRowHeight = 18.0;
constexpr double kLegendSwatch = 30.0;
constexpr double kColourBarSpace = 84.0;

// Rough width of a text in the sans-serif font at kFontSize; enough to lay out legends.
double textWidth(const std::string& text) {
  return 6.6 * static_cast<double>(text.size());
}

std::string dashArray(Dash dash) {
  switch (dash) {
    case Dash::Dashed:
      return " stroke-dasharray=\"8 4\"";
    case Dash::Dotted:
      return " stroke-dasharray=\"1.5 3\"";
    case Dash::Solid:
      break;
  }
  return "";
}

std::string styleAttributes(const Style& style) {
  std::string out = " stroke=\"" + escape(style.stroke) + "\" fill=\"" + escape(style.fill) +
                    "\" stroke-width=\"" + pixel(style.width) + "\"" + dashArray(style.dash);
  if (style.opacity < 1.0) out += " opacity=\"" + format("%.2f", style.opacity) + "\"";
  return out;
}

std::string extraAttributes(const Attributes& attributes) {
  std::string out;
  for (const auto& [name, value] : attributes) out += " " + name + "=\"" + escape(value) + "\"";
  return out;
}

std::pair<double, double> paddedRange(double lo, double hi) {
  if (!(hi > lo)) return {lo - 1.0, hi + 1.0};
  const double pad = 0.05 * (hi - lo);
  return {lo - pad, hi + pad};
}

}  // namespace

std::string escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string pixel(double value) {
  std::string out = format("%.1f", value);
  if (out == "-0.0") out = "0.0";
  if (out.size() > 2 && out.ends_with(".0")) out.resize(out.size() - 2);
  return out;
}

std::vector<double> niceTicks(double lo, double hi, int target) {
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return {};
  const double rough = (hi - lo) / std::max(target, 1);
  const int exponent = static_cast<int>(std::floor(std::log10(rough)));
  // step = factor * 10^exponent; a tick k * step is computed as (k * factor) / 10^-exponent
  // when the exponent is negative, so that 3 * 0.1 prints and compares as 0.3.
  const double power = std::pow(10.0, std::abs(exponent));
  const auto scaled = [&](double units) { return exponent < 0 ? units / power : units * power; };
  double factor = 1.0;
  for (const double f : {1.0, 2.0, 5.0, 10.0}) {
    factor = f;
    if (scaled(f) >= rough) break;
  }
  const double step = scaled(factor);
  std::vector<double> ticks;
  for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; k += 1.0) {
    const double tick = scaled(k * factor);
    ticks.push_back(tick == 0.0 ? 0.0 : tick);
  }
  return ticks;
}

std::string tickLabel(double value, double step) {
  const int decimals =
      step > 0 ? std::clamp(static_cast<int>(std::ceil(-std::log10(step) - 1e-9)), 0, 10) : 0;
  std::string out = format("%.*f", decimals, value);
  if (out.find_first_not_of("-0.") == std::string::npos) out = format("%.*f", decimals, 0.0);
  return out;
}

std::string viridis(double t) {
  static constexpr std::array<std::array<int, 3>, 11> kAnchors = {{{0x44, 0x01, 0x54},
                                                                   {0x48, 0x24, 0x75},
                                                                   {0x41, 0x44, 0x87},
                                                                   {0x35, 0x5f, 0x8d},
                                                                   {0x2a, 0x78, 0x8e},
                                                                   {0x21, 0x91, 0x8c},
                                                                   {0x22, 0xa8, 0x84},
                                                                   {0x44, 0xbf, 0x70},
                                                                   {0x7a, 0xd1, 0x51},
                                                                   {0xbd, 0xdf, 0x26},
                                                                   {0xfd, 0xe7, 0x25}}};
  const double s = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * 10.0;
  const int i = std::min(static_cast<int>(s), 9);
  const double w = s - i;
  std::array<int, 3> rgb{};
  for (int c = 0; c < 3; ++c) {
    rgb[c] = static_cast<int>(
        std::lround((1.0 - w) * kAnchors[i][c] + w * kAnchors[static_cast<std::size_t>(i) + 1][c]));
  }
  return format("#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
}

std::string markerElement(Shape shape, double x, double y, double size, const Style& style) {
  const double h = size / 2.0;
  const std::string attrs = styleAttributes(style);
  switch (shape) {
    case Shape::Circle:
      return "<circle cx=\"" + pixel(x) + "\" cy=\"" + pixel(y) + "\" r=\"" + pixel(h) + "\"" +
             attrs + "/>";
    case Shape::Square:
      return "<rect x=\"" + pixel(x - h) + "\" y=\"" + pixel(y - h) + "\" width=\"" + pixel(size) +
             "\" height=\"" + pixel(size) + "\"" + attrs + "/>";
    case Shape::Triangle:
      return "<polygon points=\"" + pixel(x) + "," + pixel(y - h) + " " + pixel(x + h) + "," +
             pixel(y + h) + " " + pixel(x - h) + "," + pixel(y + h) + "\"" + attrs + "/>";
    case Shape::Diamond:
      return "<polygon points=\"" + pixel(x) + "," + pixel(y - h) + " " + pixel(x + h) + "," +
             pixel(y) + " " + pixel(x) + "," + pixel(y + h) + " " + pixel(x - h) + "," + pixel(y) +
             "\"" + attrs + "/>";
    case Shape::Cross:
      return "<path d=\"M" + pixel(x - h) + " " + pixel(y - h) + "L" + pixel(x + h) + " " +
             pixel(y + h) + "M" + pixel(x - h) + " " + pixel(y + h) + "L" + pixel(x + h) + " " +
             pixel(y - h) + "\"" + attrs + "/>";
  }
  return {};
}

// ---------------------------------------------------------------------------------------------
// Plot

struct Plot::Frame {
  double left, top, width, height;  // plot area, px
  double x_lo, x_hi, y_lo, y_hi;    // data ranges
  double x(double v) const { return left + (v - x_lo) / (x_hi - x_lo) * width; }
  double y(double v) const { return top + height - (v - y_lo) / (y_hi - y_lo) * height; }
  double scaleX() const { return width / (x_hi - x_lo); }
};

Plot::Plot(std::string id, std::string title, std::string x_label, std::string y_label,
           double width, double height)
    : id_(std::move(id)),
      title_(std::move(title)),
      x_label_(std::move(x_label)),
      y_label_(std::move(y_label)),
      width_(width),
      height_(height),
      lo_(0.0, 0.0),
      hi_(0.0, 0.0) {}

void Plot::setColourBar(double lo, double hi, std::string label) {
  colour_bar_ = ColourBar{lo, hi, std::move(label)};
}

void Plot::include(const Eigen::Vector2d& point) {
  if (!point.allFinite()) return;
  if (empty_) {
    lo_ = hi_ = point;
    empty_ = false;
  } else {
    lo_ = lo_.cwiseMin(point);
    hi_ = hi_.cwiseMax(point);
  }
}

void Plot::addLegend(const std::string& text, const Style& style, std::optional<Shape> shape) {
  if (text.empty()) return;
  for (const LegendEntry& entry : legend_) {
    if (entry.text == text) return;
  }
  Style shown = style;
  shown.opacity = std::max(style.opacity, 0.6);
  legend_.push_back({text, shown, shape});
}

void Plot::polyline(const std::vector<Eigen::Vector2d>& points, const Style& style,
                    const std::string& legend, const Attributes& attributes) {
  if (points.size() < 2) return;
  for (const auto& p : points) include(p);
  addLegend(legend, style, std::nullopt);
  painters_.push_back([points, style, attributes](std::ostream& out, const Frame& f) {
    out << "<polyline points=\"";
    for (std::size_t i = 0; i < points.size(); ++i) {
      out << (i ? " " : "") << pixel(f.x(points[i].x())) << "," << pixel(f.y(points[i].y()));
    }
    out << "\"" << styleAttributes(style) << extraAttributes(attributes)
        << " stroke-linejoin=\"round\" stroke-linecap=\"round\"/>\n";
  });
}

void Plot::circle(const Eigen::Vector2d& center, double radius, const Style& style,
                  const std::string& legend) {
  include(center - Eigen::Vector2d::Constant(radius));
  include(center + Eigen::Vector2d::Constant(radius));
  addLegend(legend, style, std::nullopt);
  painters_.push_back([center, radius, style](std::ostream& out, const Frame& f) {
    out << "<circle cx=\"" << pixel(f.x(center.x())) << "\" cy=\"" << pixel(f.y(center.y()))
        << "\" r=\"" << pixel(radius * f.scaleX()) << "\"" << styleAttributes(style) << "/>\n";
  });
}

void Plot::marker(const Eigen::Vector2d& point, Shape shape, double size, const Style& style,
                  const std::string& legend, const Attributes& attributes,
                  const std::string& tooltip) {
  include(point);
  addLegend(legend, style, shape);
  painters_.push_back([point, shape, size, style, attributes, tooltip](std::ostream& out,
                                                                       const Frame& f) {
    const std::string element = markerElement(shape, f.x(point.x()), f.y(point.y()), size, style);
    if (attributes.empty() && tooltip.empty()) {
      out << element << "\n";
      return;
    }
    out << "<g" << extraAttributes(attributes) << ">";
    if (!tooltip.empty()) out << "<title>" << escape(tooltip) << "</title>";
    out << element << "</g>\n";
  });
}

void Plot::cell(const Eigen::Vector2d& corner_a, const Eigen::Vector2d& corner_b,
                const std::string& fill, const Attributes& attributes) {
  include(corner_a);
  include(corner_b);
  painters_.push_back([corner_a, corner_b, fill, attributes](std::ostream& out, const Frame& f) {
    const double x0 = std::min(f.x(corner_a.x()), f.x(corner_b.x()));
    const double x1 = std::max(f.x(corner_a.x()), f.x(corner_b.x()));
    const double y0 = std::min(f.y(corner_a.y()), f.y(corner_b.y()));
    const double y1 = std::max(f.y(corner_a.y()), f.y(corner_b.y()));
    // A hair wider than the cell so that anti-aliasing leaves no seams between cells.
    out << "<rect x=\"" << pixel(x0) << "\" y=\"" << pixel(y0) << "\" width=\""
        << pixel(x1 - x0 + 0.4) << "\" height=\"" << pixel(y1 - y0 + 0.4) << "\" fill=\""
        << escape(fill) << "\"" << extraAttributes(attributes) << "/>\n";
  });
}

void Plot::label(const Eigen::Vector2d& point, const std::string& text) {
  include(point);
  painters_.push_back([point, text](std::ostream& out, const Frame& f) {
    // Above and right of the point, or below / left of it where that would leave the frame.
    const double width = textWidth(text) * 11.0 / kFontSize;
    double x = f.x(point.x()) + 7, y = f.y(point.y()) - 7;
    if (y - 11.0 < f.top) y = f.y(point.y()) + 17;
    if (x + width > f.left + f.width) x = f.x(point.x()) - 7 - width;
    out << "<text x=\"" << pixel(x) << "\" y=\"" << pixel(y)
        << "\" font-size=\"11\" stroke=\"#ffffff\" stroke-width=\"3\" paint-order=\"stroke\">"
        << escape(text) << "</text>\n";
  });
}

int Plot::legendRows() const {
  if (legend_.empty()) return 0;
  const double available = width_ - 70.0 - 16.0;
  int rows = 1;
  double x = 0.0;
  for (const LegendEntry& entry : legend_) {
    const double w = kLegendSwatch + 8.0 + textWidth(entry.text) + 18.0;
    if (x > 0.0 && x + w > available) {
      ++rows;
      x = 0.0;
    }
    x += w;
  }
  return rows;
}

Plot::Frame Plot::frame() const {
  Frame f{};
  f.left = 70.0;
  f.top = 34.0;
  const double right = 16.0 + (colour_bar_ ? kColourBarSpace : 0.0);
  const double bottom = 46.0 + kLegendRowHeight * legendRows() + (legend_.empty() ? 0.0 : 8.0);
  f.width = width_ - f.left - right;
  f.height = height_ - f.top - bottom;
  auto [x_lo, x_hi] = x_range_ ? *x_range_ : paddedRange(lo_.x(), hi_.x());
  auto [y_lo, y_hi] = y_range_ ? *y_range_ : paddedRange(lo_.y(), hi_.y());
  if (equal_aspect_) {
    // One scale for both axes: widen the range with slack around its centre.
    const double scale = std::min(f.width / (x_hi - x_lo), f.height / (y_hi - y_lo));
    const double x_mid = 0.5 * (x_lo + x_hi), y_mid = 0.5 * (y_lo + y_hi);
    x_lo = x_mid - 0.5 * f.width / scale;
    x_hi = x_mid + 0.5 * f.width / scale;
    y_lo = y_mid - 0.5 * f.height / scale;
    y_hi = y_mid + 0.5 * f.height / scale;
  }
  f.x_lo = x_lo;
  f.x_hi = x_hi;
  f.y_lo = y_lo;
  f.y_hi = y_hi;
  return f;
}

void Plot::renderAxes(std::ostream& out, const Frame& f) const {
  const std::vector<double> x_ticks = niceTicks(f.x_lo, f.x_hi, 7);
  const std::vector<double> y_ticks = niceTicks(f.y_lo, f.y_hi, 6);
  const double x_step = x_ticks.size() > 1 ? x_ticks[1] - x_ticks[0] : 1.0;
  const double y_step = y_ticks.size() > 1 ? y_ticks[1] - y_ticks[0] : 1.0;
  const double bottom = f.top + f.height;
  out << "<g stroke=\"#d0d0d0\" stroke-width=\"0.6\">\n";
  for (const double t : x_ticks) {
    out << "<line x1=\"" << pixel(f.x(t)) << "\" y1=\"" << pixel(f.top) << "\" x2=\""
        << pixel(f.x(t)) << "\" y2=\"" << pixel(bottom) << "\"/>\n";
  }
  for (const double t : y_ticks) {
    out << "<line x1=\"" << pixel(f.left) << "\" y1=\"" << pixel(f.y(t)) << "\" x2=\""
        << pixel(f.left + f.width) << "\" y2=\"" << pixel(f.y(t)) << "\"/>\n";
  }
  out << "</g>\n<g stroke=\"#000000\" stroke-width=\"1\">\n";
  for (const double t : x_ticks) {
    out << "<line x1=\"" << pixel(f.x(t)) << "\" y1=\"" << pixel(bottom) << "\" x2=\""
        << pixel(f.x(t)) << "\" y2=\"" << pixel(bottom + 5) << "\"/>\n";
  }
  for (const double t : y_ticks) {
    out << "<line x1=\"" << pixel(f.left - 5) << "\" y1=\"" << pixel(f.y(t)) << "\" x2=\""
        << pixel(f.left) << "\" y2=\"" << pixel(f.y(t)) << "\"/>\n";
  }
  out << "</g>\n<g font-size=\"11\" fill=\"#000000\">\n";
  for (const double t : x_ticks) {
    out << "<text x=\"" << pixel(f.x(t)) << "\" y=\"" << pixel(bottom + 17)
        << "\" text-anchor=\"middle\">" << escape(tickLabel(t, x_step)) << "</text>\n";
  }
  for (const double t : y_ticks) {
    out << "<text x=\"" << pixel(f.left - 8) << "\" y=\"" << pixel(f.y(t) + 4)
        << "\" text-anchor=\"end\">" << escape(tickLabel(t, y_step)) << "</text>\n";
  }
  out << "</g>\n";
  out << "<text x=\"" << pixel(f.left + f.width / 2) << "\" y=\"" << pixel(bottom + 35)
      << "\" text-anchor=\"middle\">" << escape(x_label_) << "</text>\n";
  const double y_mid = f.top + f.height / 2;
  out << "<text x=\"16\" y=\"" << pixel(y_mid)
      << "\" text-anchor=\"middle\" transform=\"rotate(-90 16 " << pixel(y_mid) << ")\">"
      << escape(y_label_) << "</text>\n";
  out << "<rect x=\"" << pixel(f.left) << "\" y=\"" << pixel(f.top) << "\" width=\""
      << pixel(f.width) << "\" height=\"" << pixel(f.height)
      << "\" fill=\"none\" stroke=\"#000000\" stroke-width=\"1\"/>\n";
}

void Plot::renderLegend(std::ostream& out, const Frame& f) const {
  if (legend_.empty()) return;
  const double available = width_ - f.left - 16.0;
  double x = 0.0, y = f.top + f.height + 50.0;
  out << "<g class=\"legend\" font-size=\"11\">\n";
  for (const LegendEntry& entry : legend_) {
    const double w = kLegendSwatch + 8.0 + textWidth(entry.text) + 18.0;
    if (x > 0.0 && x + w > available) {
      x = 0.0;
      y += kLegendRowHeight;
    }
    const double x0 = f.left + x;
    if (entry.shape) {
      out << markerElement(*entry.shape, x0 + kLegendSwatch / 2, y, 8.0, entry.style) << "\n";
    } else {
      Style line = entry.style;
      line.width = std::max(line.width, 1.2);
      out << "<line x1=\"" << pixel(x0) << "\" y1=\"" << pixel(y) << "\" x2=\""
          << pixel(x0 + kLegendSwatch) << "\" y2=\"" << pixel(y) << "\"" << styleAttributes(line)
          << "/>\n";
    }
    out << "<text x=\"" << pixel(x0 + kLegendSwatch + 6) << "\" y=\"" << pixel(y + 4) << "\">"
        << escape(entry.text) << "</text>\n";
    x += w;
  }
  out << "</g>\n";
}

void Plot::renderColourBar(std::ostream& out, const Frame& f) const {
  if (!colour_bar_) return;
  const double x = f.left + f.width + 18.0, w = 14.0;
  constexpr int kSteps = 48;
  const double h = f.height / kSteps;
  out << "<g class=\"colour-bar\">\n";
  for (int s = 0; s < kSteps; ++s) {
    const double t = (s + 0.5) / kSteps;
    out << "<rect x=\"" << pixel(x) << "\" y=\"" << pixel(f.top + f.height - (s + 1) * h)
        << "\" width=\"" << pixel(w) << "\" height=\"" << pixel(h + 0.4) << "\" fill=\""
        << viridis(t) << "\"/>\n";
  }
  out << "<rect x=\"" << pixel(x) << "\" y=\"" << pixel(f.top) << "\" width=\"" << pixel(w)
      << "\" height=\"" << pixel(f.height) << "\" fill=\"none\" stroke=\"#000000\"/>\n";
  const double lo = colour_bar_->lo, hi = colour_bar_->hi > lo ? colour_bar_->hi : lo + 1.0;
  const std::vector<double> ticks = niceTicks(lo, hi, 5);
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
  for (const double t : ticks) {
    const double y = f.top + f.height - (t - lo) / (hi - lo) * f.height;
    out << "<line x1=\"" << pixel(x + w) << "\" y1=\"" << pixel(y) << "\" x2=\"" << pixel(x + w + 4)
        << "\" y2=\"" << pixel(y) << "\" stroke=\"#000000\"/>\n<text x=\"" << pixel(x + w + 6)
        << "\" y=\"" << pixel(y + 4) << "\" font-size=\"11\">" << escape(tickLabel(t, step))
        << "</text>\n";
  }
  const double lx = x + w + 52.0, ly = f.top + f.height / 2;
  out << "<text x=\"" << pixel(lx) << "\" y=\"" << pixel(ly)
      << "\" text-anchor=\"middle\" transform=\"rotate(-90 " << pixel(lx) << " " << pixel(ly)
      << ")\">" << escape(colour_bar_->label) << "</text>\n</g>\n";
}

std::string Plot::render() const {
  const Frame f = frame();
  std::ostringstream out;
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << pixel(width_) << "\" height=\""
      << pixel(height_) << "\" viewBox=\"0 0 " << pixel(width_) << " " << pixel(height_)
      << "\" font-family=\"sans-serif\" font-size=\"" << pixel(kFontSize) << "\" id=\""
      << escape(id_) << "\">\n<title>" << escape(title_) << "</title>\n";
  out << "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
  out << "<text x=\"" << pixel(width_ / 2) << "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\" "
      << "font-weight=\"bold\">" << escape(title_) << "</text>\n";
  out << "<defs><clipPath id=\"" << escape(id_) << "-clip\"><rect x=\"" << pixel(f.left)
      << "\" y=\"" << pixel(f.top) << "\" width=\"" << pixel(f.width) << "\" height=\""
      << pixel(f.height) << "\"/></clipPath></defs>\n";
  renderAxes(out, f);
  out << "<g clip-path=\"url(#" << escape(id_) << "-clip)\">\n";
  for (const Painter& paint : painters_) paint(out, f);
  out << "</g>\n";
  renderLegend(out, f);
  renderColourBar(out, f);
  out << "</svg>\n";
  return out.str();
}

// ---------------------------------------------------------------------------------------------
// Heat map of a matrix

std::string matrixHeatMap(const std::string& id, const std::string& title,
                          const std::vector<std::string>& labels, const Eigen::MatrixXd& values,
                          double lo, double hi, const std::string& field_prefix) {
  const int n = static_cast<int>(values.rows());
  std::size_t longest = 4;
  for (const std::string& l : labels) longest = std::max(longest, l.size());
  const double cell = std::clamp(460.0 / std::max(n, 1), 14.0, 64.0);
  const double label_space = 6.6 * static_cast<double>(longest) + 10.0;
  const double left = label_space, top = 30.0 + label_space * 0.75;
  const double width = left + cell * n + 24.0 + kColourBarSpace;
  const double height = top + cell * n + 16.0;
  // Values are printed where they matter, |r| >= 0.5 off the diagonal, one decimal in cells
  // under 24 px: at 21 parameters and more, 21 x 21 values at 6 px could not be read.
  const double font = std::clamp(cell * 0.42, 8.0, 11.0);
  const char* value_format = cell < 24.0 ? "%.1f" : "%.2f";
  std::ostringstream out;
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << pixel(width) << "\" height=\""
      << pixel(height) << "\" viewBox=\"0 0 " << pixel(width) << " " << pixel(height)
      << "\" font-family=\"sans-serif\" font-size=\"11\" id=\"" << escape(id) << "\">\n<title>"
      << escape(title) << "</title>\n<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
  out << "<text x=\"" << pixel(width / 2) << "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\" "
      << "font-weight=\"bold\">" << escape(title) << "</text>\n";
  for (int i = 0; i < n; ++i) {
    const std::string text = i < static_cast<int>(labels.size()) ? labels[i] : "";
    const double yc = top + (i + 0.5) * cell, xc = left + (i + 0.5) * cell;
    out << "<text x=\"" << pixel(left - 5) << "\" y=\"" << pixel(yc + 4)
        << "\" text-anchor=\"end\">" << escape(text) << "</text>\n";
    out << "<text x=\"" << pixel(xc + 4) << "\" y=\"" << pixel(top - 5)
        << "\" transform=\"rotate(-45 " << pixel(xc + 4) << " " << pixel(top - 5) << ")\">"
        << escape(text) << "</text>\n";
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double v = values(i, j);
      const double t = (v - lo) / (hi - lo);
      const double x = left + j * cell, y = top + i * cell;
      out << "<g data-field=\"" << escape(field_prefix) << "/" << i << "/" << j
          << "\" data-value=\"" << format("%.17g", v) << "\"><rect x=\"" << pixel(x) << "\" y=\""
          << pixel(y) << "\" width=\"" << pixel(cell) << "\" height=\"" << pixel(cell)
          << "\" fill=\"" << viridis(t) << "\" stroke=\"#ffffff\" stroke-width=\"0.5\"/>";
      if (i != j && std::abs(v) >= 0.5) {
        out << "<text x=\"" << pixel(x + cell / 2) << "\" y=\"" << pixel(y + cell / 2 + font * 0.35)
            << "\" text-anchor=\"middle\" font-size=\"" << pixel(font) << "\" fill=\""
            << (t < 0.55 ? "#ffffff" : "#000000") << "\">" << escape(format(value_format, v))
            << "</text>";
      }
      out << "</g>\n";
    }
  }
  // Colour bar.
  const double bx = left + cell * n + 24.0, bh = cell * n;
  constexpr int kSteps = 48;
  for (int s = 0; s < kSteps; ++s) {
    out << "<rect x=\"" << pixel(bx) << "\" y=\"" << pixel(top + bh - (s + 1) * bh / kSteps)
        << "\" width=\"14\" height=\"" << pixel(bh / kSteps + 0.4) << "\" fill=\""
        << viridis((s + 0.5) / kSteps) << "\"/>\n";
  }
  out << "<rect x=\"" << pixel(bx) << "\" y=\"" << pixel(top) << "\" width=\"14\" height=\""
      << pixel(bh) << "\" fill=\"none\" stroke=\"#000000\"/>\n";
  const std::vector<double> ticks = niceTicks(lo, hi, 4);
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
  for (const double t : ticks) {
    const double y = top + bh - (t - lo) / (hi - lo) * bh;
    out << "<text x=\"" << pixel(bx + 20) << "\" y=\"" << pixel(y + 4) << "\">"
        << escape(tickLabel(t, step)) << "</text>\n";
  }
  out << "</svg>\n";
  return out.str();
}

}  // namespace artcal::svg
