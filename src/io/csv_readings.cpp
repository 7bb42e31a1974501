#include "artcal/io/csv_readings.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>

#include "artcal/core/error.hpp"
#include "artcal/io/plan_io.hpp"

namespace artcal {

namespace {

std::string_view trimmed(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r");
  return text.substr(first, last - first + 1);
}

std::vector<std::string_view> splitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    fields.push_back(trimmed(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) return fields;
    start = comma + 1;
  }
}

/// The whole field as a number (a leading '+' allowed), or std::nullopt.
std::optional<double> parseNumber(std::string_view field) {
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  double value = 0.0;
  const char* end = field.data() + field.size();
  const auto [ptr, ec] = std::from_chars(field.data(), end, value);
  if (ec != std::errc() || ptr != end || field.empty()) return std::nullopt;
  return value;
}

/// A field as a message shows it: at most 40 characters, control bytes as '?'.
std::string shown(std::string_view field) {
  constexpr std::size_t kShown = 40;
  std::string out(field.substr(0, kShown));
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  return field.size() > kShown ? out + "..." : out;
}

}  // namespace

std::optional<ReadingUnits> readingUnitsFromName(const std::string& name) {
  ReadingUnits units;
  // "ANGLE+LENGTH": both units stated, e.g. ROS's rad and m.
  if (const auto plus = name.find('+'); plus != std::string::npos) {
    const std::string angle = name.substr(0, plus), length = name.substr(plus + 1);
    if ((angle != "deg" && angle != "rad") || (length != "mm" && length != "m"))
      return std::nullopt;
    units.angle_to_rad = angle == "rad" ? 1.0 : kDegree;
    units.length_to_mm = length == "m" ? 1000.0 : 1.0;
    return units;
  }
  if (name == "deg" || name == "mm") return units;
  if (name == "rad") {
    units.angle_to_rad = 1.0;
    return units;
  }
  if (name == "m") {
    units.length_to_mm = 1000.0;
    return units;
  }
  return std::nullopt;
}

std::vector<Eigen::VectorXd> readJointCsv(const std::string& path,
                                          const std::vector<JointKind>& kinds,
                                          const ReadingUnits& units, std::vector<long>* lines) {
  const std::string text = readInputFile(path);
  const auto joints = kinds.size();
  std::vector<Eigen::VectorXd> rows;
  std::string_view rest(text);
  bool first_content = true;
  for (long line_number = 1; !rest.empty(); ++line_number) {
    const auto newline = rest.find('\n');
    const std::string_view line = trimmed(rest.substr(0, newline));
    rest = newline == std::string_view::npos ? std::string_view{} : rest.substr(newline + 1);
    if (line.empty()) continue;
    const std::string where = "line " + std::to_string(line_number);
    auto fail = [&](const std::string& message) { throw InputError(path, where, message); };
    // Counted before splitting: a line of 200 MB would otherwise become gigabytes of fields.
    const auto count = static_cast<std::size_t>(std::count(line.begin(), line.end(), ',')) + 1;
    if (count != joints) {
      fail("expected " + std::to_string(joints) + " readings, got " + std::to_string(count));
    }
    const std::vector<std::string_view> fields = splitFields(line);
    std::vector<std::optional<double>> values;
    for (const std::string_view field : fields) values.push_back(parseNumber(field));
    const bool header =
        first_content && std::none_of(values.begin(), values.end(),
                                      [](const std::optional<double>& v) { return v.has_value(); });
    first_content = false;
    if (header) continue;  // joint names
    if (rows.size() >= kMaxCsvRows) fail("more than " + std::to_string(kMaxCsvRows) + " rows");
    Eigen::VectorXd q(static_cast<int>(joints));
    for (std::size_t i = 0; i < joints; ++i) {
      if (!values[i])
        fail("column " + std::to_string(i + 1) + ": not a number: \"" + shown(fields[i]) + "\"");
      if (!std::isfinite(*values[i]))
        fail("column " + std::to_string(i + 1) + ": expected a finite number");
      const double scale =
          kinds[i] == JointKind::Revolute ? units.angle_to_rad : units.length_to_mm;
      const double converted = *values[i] * scale;
      // A finite reading can overflow in conversion (1e306 m is inf mm): refused, not passed on.
      if (!std::isfinite(converted))
        fail("column " + std::to_string(i + 1) + ": \"" + shown(fields[i]) +
             "\" is too large for a joint reading; check the column's unit");
      q[static_cast<int>(i)] = converted;
    }
    rows.push_back(std::move(q));
    if (lines) lines->push_back(line_number);
  }
  if (rows.empty()) throw InputError(path, "", "no readings");
  return rows;
}

}  // namespace artcal
