#include "artcal/io/csv_readings.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>

#include "artcal/core/error.hpp"
#include "artcal/io/json_node.hpp"
#include "artcal/io/plan_io.hpp"

namespace artcal {

namespace {

std::string_view trimmed(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r");
  return text.substr(first, last - first + 1);
}

/// A text's non-empty lines, each trimmed, with its number from 1 (blank lines counted, as an
/// editor numbers them): `for (std::string_view line; lines.next(number, line);)`.
class NumberedLines {
 public:
  explicit NumberedLines(std::string_view text) : rest_(text) {}
  bool next(long& number, std::string_view& line) {
    while (!rest_.empty()) {
      const auto newline = rest_.find('\n');
      line = trimmed(rest_.substr(0, newline));
      rest_ = newline == std::string_view::npos ? std::string_view{} : rest_.substr(newline + 1);
      number = ++number_;
      if (!line.empty()) return true;
    }
    return false;
  }

 private:
  std::string_view rest_;
  long number_ = 0;
};

/// The fields of `line` split at `separator`, each without its surrounding blanks and, when
/// quoted ("j1"), without its quotes (a separator inside the quotes is the field's). `bad_quote`,
/// when given, is set to the field (from 0) whose opening quote is not closed, or to -1.
std::vector<std::string_view> splitFields(std::string_view line, char separator = ',',
                                          int* bad_quote = nullptr) {
  std::vector<std::string_view> fields;
  if (bad_quote) *bad_quote = -1;
  std::size_t start = 0;
  while (true) {
    std::size_t at = start;
    while (at < line.size() && (line[at] == ' ' || line[at] == '\t') && line[at] != separator) ++at;
    if (at < line.size() && line[at] == '"') {
      const auto close = line.find('"', at + 1);
      if (close == std::string_view::npos) {
        if (bad_quote && *bad_quote < 0) *bad_quote = static_cast<int>(fields.size());
        fields.push_back(trimmed(line.substr(at + 1)));
        return fields;
      }
      fields.push_back(line.substr(at + 1, close - at - 1));
      const auto next = line.find(separator, close + 1);
      if (!trimmed(line.substr(close + 1, next - close - 1)).empty() && bad_quote && *bad_quote < 0)
        *bad_quote = static_cast<int>(fields.size()) - 1;
      if (next == std::string_view::npos) return fields;
      start = next + 1;
      continue;
    }
    const auto next = line.find(separator, start);
    fields.push_back(trimmed(line.substr(start, next - start)));
    if (next == std::string_view::npos) return fields;
    start = next + 1;
  }
}

/// True when every ',' of `line` stands between two digits (a decimal comma: "1,5").
bool commasAreDecimal(std::string_view line) {
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (line[i] != ',') continue;
    if (i == 0 || i + 1 == line.size() || !std::isdigit(static_cast<unsigned char>(line[i - 1])) ||
        !std::isdigit(static_cast<unsigned char>(line[i + 1])))
      return false;
  }
  return true;
}

/// The whole field as a number (a leading '+' allowed), or std::nullopt. With `decimal_comma`
/// (a file separated by ';' or tabs), one ',' in the field is its decimal point ("1,5").
std::optional<double> parseNumber(std::string_view field, bool decimal_comma = false) {
  std::string copy;
  if (decimal_comma && field.find(',') != std::string_view::npos) {
    if (field.find('.') != std::string_view::npos ||
        std::count(field.begin(), field.end(), ',') != 1)
      return std::nullopt;
    copy = std::string(field);
    copy[copy.find(',')] = '.';
    field = copy;
  }
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

CsvDialect csvDialect(std::string_view first_line) {
  if (first_line.find(';') != std::string_view::npos) return {';'};
  const bool tab = first_line.find('\t') != std::string_view::npos;
  if (tab && commasAreDecimal(first_line)) return {'\t'};
  return {','};
}

std::string CsvDialect::name() const {
  return separator == ';' ? "';'" : separator == '\t' ? "tabs" : "','";
}

std::vector<std::string_view> csvFields(std::string_view line, CsvDialect dialect, int* bad_quote) {
  return splitFields(line, dialect.separator, bad_quote);
}

std::optional<double> csvNumber(std::string_view field, CsvDialect dialect) {
  return parseNumber(field, dialect.separator != ',');
}

std::string separatorHint(std::string_view line, CsvDialect dialect) {
  std::string seen;
  for (const char c : {',', ';', '\t', '|'}) {
    if (c == dialect.separator) continue;
    const auto n = std::count(line.begin(), line.end(), c);
    if (n == 0 || (c == ',' && dialect.separator != ',' && commasAreDecimal(line))) continue;
    // Appended piece by piece: GCC 12's -Wrestrict false positive on "'" + std::string(...).
    if (!seen.empty()) seen += " and ";
    seen += std::to_string(n);
    seen += ' ';
    if (c == '\t') {
      seen += "tab(s)";
    } else {
      seen += '\'';
      seen += c;
      seen += '\'';
    }
  }
  if (seen.empty()) return {};
  return " (the file's fields are split at " + dialect.name() +
         ", as its first line; this line holds " + seen +
         ": one separator per file, and with ';' or tabs a ',' is a decimal comma)";
}

std::size_t headerShift(const std::vector<std::string_view>& header,
                        const std::vector<std::string_view>& row, const std::vector<int>& selected,
                        CsvDialect dialect) {
  auto number = [&](std::size_t at) { return at < row.size() && csvNumber(row[at], dialect); };
  auto numbers = [&](std::size_t shift) {
    for (const int f : selected)
      if (f >= 0 && !number(static_cast<std::size_t>(f) + shift)) return false;
    return true;
  };
  // The header's names over fields that are not numbers, the names shifted by `shift`.
  auto namesOverText = [&](std::size_t shift) {
    std::size_t count = 0;
    for (std::size_t f = 0; f < header.size(); ++f)
      if (!header[f].empty() && !number(f + shift)) ++count;
    return count;
  };
  std::size_t named = header.size();
  while (named > 0 && header[named - 1].empty()) --named;
  if (named >= row.size()) return 0;
  const std::size_t shift = row.size() - named;
  if (!numbers(shift)) return 0;
  if (header.size() != row.size()) return numbers(0) ? 0 : shift;
  // As wide as the row and ending in `shift` empty names: names written left of their values (a
  // peer's export) only where they stand over fewer text fields so; a trailing index column (as
  // pandas writes it) is a field of its own, the names over their values.
  return namesOverText(shift) < namesOverText(0) ? shift : 0;
}

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

std::vector<CsvColumn> parseCsvColumns(const Node& columns, std::size_t count) {
  const std::size_t n = columns.arraySize(count, count);
  std::vector<CsvColumn> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Node c = columns[i];
    if (c.value().is_number()) {
      out[i].held = c.number();
      continue;
    }
    const std::string name = c.string();
    if (name.empty()) c.fail("expected a column's name, \"#k\" or a held value");
    if (name.size() > 1 && name.size() < 8 && name[0] == '#' &&
        std::all_of(name.begin() + 1, name.end(),
                    [](unsigned char ch) { return std::isdigit(ch); })) {
      const int k = std::stoi(name.substr(1));
      if (k < 1) c.fail("column positions count from #1");
      out[i].index = k - 1;
    } else {
      out[i].name = name;
    }
  }
  return out;
}

namespace {

/// Each selected reading's field index in a row (-1: held), from the header line `header` when a
/// column is selected by name; InputError naming the file when a name is missing or repeated.
std::vector<int> selectedFields(const std::string& path, const std::vector<CsvColumn>& columns,
                                const std::vector<std::string_view>& fields, std::size_t& width) {
  width = fields.size();
  std::vector<int> out;
  for (const CsvColumn& column : columns) {
    if (column.held) {
      out.push_back(-1);
    } else if (column.name.empty()) {
      if (static_cast<std::size_t>(column.index) >= fields.size()) {
        throw InputError(path, "line 1",
                         "column #" + std::to_string(column.index + 1) + ": the header has " +
                             std::to_string(fields.size()) + " columns");
      }
      out.push_back(column.index);
    } else {
      const auto found = std::find(fields.begin(), fields.end(), column.name);
      if (found == fields.end()) {
        std::string names;
        for (const std::string_view field : fields)
          names += (names.empty() ? "" : ", ") + shown(field);
        throw InputError(
            path, "line 1",
            "no column named \"" + shown(column.name) + "\" in the header (" + shown(names) + ")");
      }
      if (std::find(found + 1, fields.end(), column.name) != fields.end())
        throw InputError(path, "line 1", "two columns named \"" + shown(column.name) + "\"");
      out.push_back(static_cast<int>(found - fields.begin()));
    }
  }
  return out;
}

}  // namespace

std::vector<Eigen::VectorXd> readJointCsv(const std::string& path,
                                          const std::vector<JointKind>& kinds,
                                          const ReadingUnits& units, std::vector<long>* lines,
                                          const std::vector<CsvColumn>* columns,
                                          CsvDropouts* dropouts) {
  const std::string text = readInputFile(path);
  const auto joints = kinds.size();
  const bool by_name = columns && std::any_of(columns->begin(), columns->end(),
                                              [](const CsvColumn& c) { return !c.name.empty(); });
  // The field each reading takes (identity without `columns`) and how many fields a row has.
  std::vector<int> field_of(joints);
  for (std::size_t i = 0; i < joints; ++i) field_of[i] = static_cast<int>(i);
  std::size_t width = joints;
  if (columns) {
    width = 0;
    for (std::size_t i = 0; i < joints; ++i) {
      const CsvColumn& c = (*columns)[i];
      field_of[i] = c.held ? -1 : c.index;
      if (!c.held && c.name.empty()) width = std::max(width, static_cast<std::size_t>(c.index) + 1);
    }
  }
  auto column_name = [&](std::size_t i) {
    std::string out = "column " + std::to_string(field_of[i] + 1);
    if (by_name && !(*columns)[i].name.empty()) out += " (\"" + shown((*columns)[i].name) + "\")";
    return out;
  };
  std::vector<Eigen::VectorXd> rows;
  NumberedLines lines_of(text);
  bool first_content = true;
  bool aligned = false;  // the header's names placed on the first row's fields
  CsvDialect dialect;    // read from the first line
  std::string header_line;
  long line_number = 0;
  for (std::string_view line; lines_of.next(line_number, line);) {
    const std::string where = "line " + std::to_string(line_number);
    auto fail = [&](const std::string& message) { throw InputError(path, where, message); };
    if (first_content) dialect = csvDialect(line);
    // Split with the file's separator; a quote opened and not closed is named.
    auto split = [&](std::string_view text_line) {
      int bad_quote = -1;
      std::vector<std::string_view> out = splitFields(text_line, dialect.separator, &bad_quote);
      if (bad_quote >= 0) {
        fail("column " + std::to_string(bad_quote + 1) +
             ": a quoted field whose closing quote is missing or followed by more text (\"" +
             shown(out[static_cast<std::size_t>(bad_quote)]) +
             "...\"): quote whole fields, \"j1\",\"j2\", or none");
      }
      return out;
    };
    if (by_name && first_content) {  // the header naming the columns
      if (line.size() > 100'000) fail("a header line longer than 100000 characters");
      field_of = selectedFields(path, *columns, split(line), width);
      header_line = std::string(line);
      first_content = false;
      continue;
    }
    // Counted before splitting: a line of 200 MB would otherwise become gigabytes of fields.
    std::size_t count =
        static_cast<std::size_t>(std::count(line.begin(), line.end(), dialect.separator)) + 1;
    std::vector<std::string_view> fields;
    if (count <= kMaxCsvFields) {
      fields = split(line);
      count = fields.size();  // a separator inside quotes is its field's
    }
    if (by_name && !aligned && count <= kMaxCsvFields) {
      // A header that names its rows' last fields (an export that left its leading label fields
      // unnamed; plan-format.md, "Columns by name").
      const std::size_t shift = headerShift(split(header_line), fields, field_of, dialect);
      for (int& f : field_of)
        if (f >= 0) f += static_cast<int>(shift);
      if (shift > 0) width = count;
    }
    aligned = true;
    if (!columns && count != joints) {
      fail("expected " + std::to_string(joints) + " readings, got " + std::to_string(count) +
           separatorHint(line, dialect));
    }
    if (columns && (by_name ? count != width : count < width)) {
      fail("expected " + std::to_string(width) + " fields" +
           (by_name ? std::string(" (as the header)") : std::string()) + ", got " +
           std::to_string(count) + separatorHint(line, dialect));
    }
    std::vector<std::optional<double>> values;
    for (const std::string_view field : fields) values.push_back(csvNumber(field, dialect));
    const bool header =
        first_content && std::none_of(values.begin(), values.end(),
                                      [](const std::optional<double>& v) { return v.has_value(); });
    first_content = false;
    if (header) continue;  // joint names
    if (rows.size() >= kMaxCsvRows) fail("more than " + std::to_string(kMaxCsvRows) + " rows");
    if (dropouts && dropouts->first < joints) {
      // Missing: an empty field or NaN (exports write either for a marker not seen).
      auto missing = [&](std::size_t i) {
        const int f = field_of[i];
        if (f < 0) return false;
        const auto& v = values[static_cast<std::size_t>(f)];
        return fields[static_cast<std::size_t>(f)].empty() || (v && std::isnan(*v));
      };
      bool all = true;
      for (std::size_t i = dropouts->first; i < joints; ++i) all = all && missing(i);
      if (all) {
        dropouts->lines.push_back(line_number);
        continue;
      }
    }
    Eigen::VectorXd q(static_cast<int>(joints));
    for (std::size_t i = 0; i < joints; ++i) {
      const int f = field_of[i];
      const std::optional<double> value =
          f < 0 ? (*columns)[i].held : values[static_cast<std::size_t>(f)];
      const std::string_view field =
          f < 0 ? std::string_view() : fields[static_cast<std::size_t>(f)];
      if (!value && f >= 0 && field.empty()) {
        fail(column_name(i) + ": empty" +
             (dropouts && i >= dropouts->first
                  ? std::string(" while the row's other measured coordinates are given: a "
                                "marker not seen leaves all its cells empty")
                  : std::string()));
      }
      if (!value) fail(column_name(i) + ": not a number: \"" + shown(field) + "\"");
      if (!std::isfinite(*value)) fail(column_name(i) + ": expected a finite number");
      const double scale =
          kinds[i] == JointKind::Revolute ? units.angle_to_rad : units.length_to_mm;
      const double converted = *value * scale;
      // A finite reading can overflow in conversion (1e306 m is inf mm): refused, not passed on.
      if (!std::isfinite(converted))
        fail(column_name(i) + ": \"" + shown(field) +
             "\" is too large for a joint reading; check the column's unit");
      q[static_cast<int>(i)] = converted;
    }
    rows.push_back(std::move(q));
    if (lines) lines->push_back(line_number);
  }
  if (rows.empty()) throw InputError(path, "", "no readings");
  return rows;
}

std::vector<std::pair<long, std::string>> readCsvColumn(const std::string& path,
                                                        const std::string& column) {
  const std::string text = readInputFile(path);
  std::vector<std::pair<long, std::string>> out;
  NumberedLines lines_of(text);
  CsvDialect dialect;
  int field = -1;
  long line_number = 0;
  for (std::string_view line; lines_of.next(line_number, line);) {
    const std::string where = "line " + std::to_string(line_number);
    if (field < 0) {  // the header
      dialect = csvDialect(line);
      const std::vector<std::string_view> fields = splitFields(line, dialect.separator, nullptr);
      const auto found = std::find(fields.begin(), fields.end(), column);
      if (found == fields.end())
        throw InputError(path, where, "no column named \"" + shown(column) + "\" in the header");
      field = static_cast<int>(found - fields.begin());
      continue;
    }
    const std::vector<std::string_view> fields = splitFields(line, dialect.separator, nullptr);
    if (static_cast<std::size_t>(field) >= fields.size())
      throw InputError(path, where, "no field in column \"" + shown(column) + "\"");
    out.emplace_back(line_number, std::string(fields[static_cast<std::size_t>(field)]));
  }
  if (field < 0) throw InputError(path, "", "empty file: no header");
  return out;
}

}  // namespace artcal
