#include "artcal/io/readings_import.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <string_view>
#include <vector>

#include "artcal/core/error.hpp"
#include "artcal/io/csv_readings.hpp"
#include "artcal/io/json_node.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/urdf.hpp"

namespace artcal {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// A number as a message shows it: its shortest form that reads back to it ("10", "0.5").
std::string formatShortest(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.15g", value);
  return text;
}

// ------------------------------------------------------------------ the folder walk

/// Every entry of a folder the import reads is read once or refused naming it (docs/hardening.md,
/// "Hardening III"): nothing is skipped without a word.

/// A name ending in .csv, in any case.
bool csvName(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".csv";
}

bool validUtf8(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    const std::size_t length = c < 0x80           ? 1
                               : (c >> 5) == 0x6  ? 2
                               : (c >> 4) == 0xE  ? 3
                               : (c >> 3) == 0x1E ? 4
                                                  : 0;
    if (length == 0 || i + length > text.size()) return false;
    for (std::size_t k = 1; k < length; ++k)
      if ((static_cast<unsigned char>(text[i + k]) >> 6) != 0x2) return false;
    i += length;
  }
  return true;
}

/// A name with its bytes beyond ASCII shown as \xNN (a message must be valid UTF-8 itself).
std::string printableName(const std::string& name) {
  std::string out;
  for (const char c : name) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte < 0x7F) {
      out += c;
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", byte);
      out += hex;
    }
  }
  return out;
}

const char* kindOf(fs::file_type type) {
  switch (type) {
    case fs::file_type::directory:
      return "a directory";
    case fs::file_type::fifo:
      return "a FIFO";
    case fs::file_type::block:
    case fs::file_type::character:
      return "a device";
    case fs::file_type::socket:
      return "a socket";
    default:
      return "not a regular file";
  }
}

struct FolderEntry {
  fs::path path;
  bool directory = false;  ///< a folder (through links)
  bool regular = false;    ///< a regular file (through links)
};

/// The entries of `folder`, links followed, in name order. Refused, naming the entry: a name that
/// is not valid UTF-8; a link to the folder itself or to a folder above it (a loop); a name ending
/// in .csv that is not a regular file (a directory, a FIFO, a device, a socket, a link to nothing).
std::vector<FolderEntry> folderEntries(const fs::path& folder) {
  std::error_code ec;
  const fs::path here = fs::weakly_canonical(folder, ec);
  std::vector<FolderEntry> out;
  for (const fs::directory_entry& item : fs::directory_iterator(folder)) {
    const fs::path& path = item.path();
    const std::string name = path.filename().string();
    if (!validUtf8(name)) {
      throw InputError((folder / printableName(name)).string(), "",
                       "the file name is not valid UTF-8: rename it (a plan names its CSV files "
                       "in JSON, which is UTF-8)");
    }
    const fs::file_status status = fs::status(path, ec);
    const fs::file_type type = ec ? fs::file_type::not_found : status.type();
    FolderEntry entry{path, type == fs::file_type::directory, type == fs::file_type::regular};
    if (entry.directory && item.is_symlink(ec)) {
      const fs::path target = fs::weakly_canonical(path, ec);
      if (std::mismatch(target.begin(), target.end(), here.begin(), here.end()).first ==
          target.end()) {
        throw InputError(path.string(), "",
                         "a link to " + target.string() +
                             ", the folder itself or one above it: its files would be read twice "
                             "(a loop); remove the link");
      }
    }
    if (csvName(path) && !entry.regular) {
      throw InputError(
          path.string(), "",
          std::string(type == fs::file_type::not_found ? "a link to nothing" : kindOf(type)) +
              ", named like a CSV file of readings: give the file itself (a "
              "regular file), or move it out of " +
              folder.string());
    }
    out.push_back(entry);
  }
  std::sort(out.begin(), out.end(),
            [](const FolderEntry& a, const FolderEntry& b) { return a.path < b.path; });
  return out;
}

/// Refuses the second name of a file read twice (a link to a file or a folder of the import).
void checkEachFileReadOnce(const json& placements, const fs::path& plan_folder) {
  std::map<fs::path, fs::path> seen;
  for (const json& placement : placements) {
    for (const json& entry : placement.at("measurements")) {
      std::error_code ec;
      // Named as the user would: relative to the working folder when under it, else absolute.
      const fs::path absolute =
          (plan_folder / entry.at("csv").get<std::string>()).lexically_normal();
      fs::path file = absolute.lexically_proximate(fs::current_path(ec));
      if (file.empty() || *file.begin() == "..") file = absolute;
      const fs::path real = fs::canonical(file, ec);
      const auto [at, inserted] = seen.emplace(ec ? file : real, file);
      // Several markers of one file: one entry each, the same name.
      if (!inserted && at->second != file) {
        throw InputError(file.string(), "",
                         "is the same file as " + at->second.string() +
                             " (through a link): each file of readings is read once; remove "
                             "the link or the copy");
      }
    }
  }
}

/// The CSV files under DIR (in DIR and its sub-folders) that the plan does not read: said in one
/// warning, never skipped silently.
std::vector<std::string> unreadCsvFiles(const fs::path& dir, const json& placements,
                                        const fs::path& plan_folder) {
  std::set<fs::path> read;
  std::error_code ec;
  for (const json& placement : placements)
    for (const json& entry : placement.at("measurements"))
      read.insert(fs::weakly_canonical(plan_folder / entry.at("csv").get<std::string>(), ec));
  std::vector<std::string> unread;
  const auto note = [&](const FolderEntry& entry) {
    if (entry.regular && csvName(entry.path) && !read.count(fs::weakly_canonical(entry.path, ec)))
      unread.push_back(entry.path.lexically_relative(dir).generic_string());
  };
  for (const FolderEntry& entry : folderEntries(dir)) {
    note(entry);
    if (entry.directory)
      for (const FolderEntry& inner : folderEntries(entry.path)) note(inner);
  }
  if (unread.empty()) return {};
  std::string list;
  for (std::size_t i = 0; i < unread.size() && i < 5; ++i) list += (i ? ", " : "") + unread[i];
  if (unread.size() > 5) list += ", ...";
  return {std::to_string(unread.size()) + " CSV file(s) of " + dir.string() +
          " not read (not a placement's hole_<k>.csv or feature_<k>.csv, or not in a station's "
          "folder): " +
          list};
}

/// One feature file of a placement folder and the unit its readings are in ("" when the layout
/// leaves it to --unit).
struct FeatureFile {
  int feature = 0;
  fs::path path;
  std::string unit;
};

/// `PREFIX<k>.csv` -> k; std::nullopt for any other name.
std::optional<int> featureIndex(const std::string& name, std::string_view prefix) {
  if (!name.starts_with(prefix) || !name.ends_with(".csv")) return std::nullopt;
  const std::string digits =
      name.substr(prefix.size(), name.size() - prefix.size() - std::string_view(".csv").size());
  if (digits.empty() || digits.size() > 4 ||
      !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); })) {
    return std::nullopt;
  }
  return std::stoi(digits);
}

/// The last name of a folder's path, "a/b/" and "a/b" alike.
std::string folderName(const fs::path& folder) {
  const fs::path normal = fs::absolute(folder).lexically_normal();
  return (normal.has_filename() ? normal.filename() : normal.parent_path().filename()).string();
}

/// Columns a CSV header may have (docs/hardening.md, work caps): counted before the header is
/// split, so that a header of 10^8 commas is refused instead of taking gigabytes.
constexpr std::size_t kMaxHeaderColumns = 1024;

/// The first non-blank line of `file` (its header, or its first row).
std::string firstLine(const fs::path& file) {
  const std::string text = readInputFile(file.string());
  std::size_t start = 0;
  while (start < text.size() &&
         (text[start] == '\n' || text[start] == '\r' || text[start] == ' ' || text[start] == '\t'))
    ++start;
  std::string line = text.substr(start, text.find('\n', start) - start);
  const char separator = csvDialect(line).separator;
  if (static_cast<std::size_t>(std::count(line.begin(), line.end(), separator)) >=
      kMaxHeaderColumns) {
    throw InputError(file.string(), "line 1",
                     "more than " + std::to_string(kMaxHeaderColumns) +
                         " columns: a file of readings has one column per joint reading and "
                         "coordinate");
  }
  return line;
}

/// The coordinates an instrument reports per reading: a point's x, y, z; a pose's x, y, z, then
/// its orientation as a rotation vector rx, ry, rz.
constexpr std::size_t kPointColumns = 3;
constexpr std::size_t kPoseColumns = 6;

/// The units a header field may name.
constexpr std::array<const char*, 4> kUnitWords = {"deg", "rad", "mm", "m"};
/// Unit words of other units, refused where they end a field ("A_grad"): never taken for a name.
constexpr std::array<const char*, 14> kOtherUnitWords = {"grad",   "gon",  "mrad", "urad", "arcsec",
                                                         "arcmin", "turn", "rev",  "cm",   "um",
                                                         "dm",     "km",   "in",   "inch"};

/// The word a header field ends with as its unit: after its last ' ', '_', '[' or '(' (the
/// brackets closed at the end); "" when none.
std::string lastWord(std::string field) {
  while (!field.empty() && std::isspace(static_cast<unsigned char>(field.back()))) field.pop_back();
  const bool bracketed = !field.empty() && (field.back() == ']' || field.back() == ')');
  if (bracketed) field.pop_back();
  const auto start = field.find_last_of(bracketed ? "[(" : " _[(\t");
  if (start == std::string::npos) return bracketed ? std::string() : field;
  std::string word = field.substr(start + 1);
  while (!word.empty() && std::isspace(static_cast<unsigned char>(word.front()))) word.erase(0, 1);
  while (!word.empty() && std::isspace(static_cast<unsigned char>(word.back()))) word.pop_back();
  return word;
}

/// The unit a header field names as its last word: "q1_deg", "joint1 [rad]", "z (mm)".
std::optional<std::string> headerUnit(const std::string& field) {
  const std::string word = lastWord(field);
  for (const char* unit : kUnitWords)
    if (word == unit) return word;
  return std::nullopt;
}

/// True when header field `field` names a unit in brackets ("j1 [grad]") or ends with another
/// unit's word ("A_grad"), neither of the units read.
bool namesAnotherUnit(const std::string& field) {
  std::string f = field;
  while (!f.empty() && std::isspace(static_cast<unsigned char>(f.back()))) f.pop_back();
  const std::string word = lastWord(f);
  if (word.empty() || headerUnit(f)) return false;
  if (!f.empty() && (f.back() == ']' || f.back() == ')')) return true;
  std::string lower = word;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return word.size() < f.size() &&
         std::find_if(kOtherUnitWords.begin(), kOtherUnitWords.end(),
                      [&](const char* u) { return lower == u; }) != kOtherUnitWords.end();
}

/// How far right of where the header of `file` puts them its first data row's fields at
/// `selected` (header positions) are (csv_readings.hpp, headerShift), and the row's field count.
std::pair<std::size_t, std::size_t> namedFieldShift(const fs::path& file,
                                                    const std::vector<int>& selected) {
  const std::string text = readInputFile(file.string());
  const std::string header = firstLine(file);
  const CsvDialect dialect = csvDialect(header);
  std::size_t start = text.find(header);
  start = start == std::string::npos ? std::string::npos : text.find('\n', start);
  while (start != std::string::npos && start + 1 < text.size()) {
    const std::size_t end = text.find('\n', start + 1);
    const std::string_view line = std::string_view(text).substr(start + 1, end - start - 1);
    start = end;
    if (line.find_first_not_of(" \t\r") == std::string_view::npos) continue;
    if (static_cast<std::size_t>(std::count(line.begin(), line.end(), dialect.separator)) >=
        kMaxCsvFields)
      return {0, 0};
    const auto row = csvFields(line, dialect);
    return {headerShift(csvFields(header, dialect), row, selected, dialect), row.size()};
  }
  return {0, 0};
}

/// The header's fields of a CSV file (its first line split at its separator, without quotes).
std::vector<std::string> headerFields(const fs::path& file) {
  const std::string header = firstLine(file);
  std::vector<std::string> fields;
  int bad_quote = -1;
  for (const std::string_view field : csvFields(header, csvDialect(header), &bad_quote))
    fields.emplace_back(field);
  if (bad_quote >= 0) {
    throw InputError(file.string(), "line 1",
                     "column " + std::to_string(bad_quote + 1) +
                         ": a quoted field whose closing quote is missing or followed by more "
                         "text: quote whole fields, \"j1\",\"j2\", or none");
  }
  return fields;
}

/// Refuses header field `index` of `fields` when it names a unit that is not read ("j1 [grad]",
/// "A_grad"), naming the column and the units read.
void requireReadUnit(const fs::path& file, const std::vector<std::string>& fields,
                     std::size_t index) {
  if (!namesAnotherUnit(fields[index])) return;
  throw InputError(file.string(), "line 1",
                   "column " + std::to_string(index + 1) + " (\"" + fields[index] + "\"): unit \"" +
                       lastWord(fields[index]) +
                       "\" is not one read: a column's unit is deg, rad, mm or m (its last word: "
                       "j1_deg, j1 [rad]); convert the column, or drop the word and give --unit");
}

/// The reading unit the header fields [first, last) name: one angle unit and one length unit at
/// most ("rad+m" when both differ from deg and mm).
std::string unitOfColumns(const fs::path& file, const std::vector<std::string>& fields,
                          std::size_t first, std::size_t last) {
  std::set<std::string> units;
  for (std::size_t i = first; i < last; ++i) {
    requireReadUnit(file, fields, i);
    const auto unit = headerUnit(fields[i]);
    if (!unit) {
      throw InputError(file.string(), "line 1",
                       "expected a header naming each column's unit (q1_deg, q2_rad, q3_mm, ...), "
                       "or state the unit with --unit");
    }
    units.insert(*unit);
  }
  const bool rad = units.count("rad") > 0, m = units.count("m") > 0;
  if ((rad && units.count("deg")) || (m && units.count("mm"))) {
    throw InputError(file.string(), "line 1",
                     "columns in mixed units: one file takes deg or rad for its angles and mm or "
                     "m for its lengths");
  }
  return rad && m ? "rad+m" : rad ? "rad" : m ? "m" : "deg";
}

/// The joints' unit a header-named file's joint fields name (unitOfColumns over them).
std::string unitOfNamed(const fs::path& file, const std::vector<std::string>& joint_fields) {
  return unitOfColumns(file, joint_fields, 0, joint_fields.size());
}

/// The unit of a general-layout file from its header.
std::string unitFromHeader(const fs::path& file) {
  const std::vector<std::string> fields = headerFields(file);
  return unitOfColumns(file, fields, 0, fields.size());
}

/// The feature files of one folder, by feature index; empty when it holds none.
std::vector<FeatureFile> featureFiles(const fs::path& folder, const std::string& unit) {
  std::map<int, FeatureFile> files;
  for (const FolderEntry& entry : folderEntries(folder)) {
    if (!entry.regular) continue;
    const std::string name = entry.path.filename().string();
    FeatureFile file;
    file.path = entry.path;
    if (const auto k = featureIndex(name, "hole_")) {  // MUKCa: rad, no header
      file.feature = *k;
      file.unit = unit.empty() ? "rad" : unit;
    } else if (const auto f = featureIndex(name, "feature_")) {
      file.feature = *f;
      file.unit = unit;  // "" : the header's (featureEntry)
    } else {
      continue;  // hole_0_pose.csv, notes, ...
    }
    if (!files.emplace(file.feature, file).second) {
      throw InputError(
          file.path.string(), "",
          "feature " + std::to_string(file.feature) + " has two files in " + folder.string());
    }
  }
  std::vector<FeatureFile> out;
  for (auto& [feature, file] : files) out.push_back(std::move(file));
  return out;
}

// ------------------------------------------------------------------ columns named by a header

/// The readings a machine takes per row: their names (empty when the model names none) and
/// kinds.
struct MachineReadings {
  std::vector<std::string> names;
  std::vector<std::string> labels;  ///< the operator's axis letters (a machine tool's X .. C)
  std::vector<JointKind> kinds;
  std::vector<std::string> tips;  ///< a machine with several named tips: their names
};

std::string trimmedField(std::string field) {
  const auto first = field.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  const auto last = field.find_last_not_of(" \t\r");
  return field.substr(first, last - first + 1);
}

/// A header field without its unit word: "panda_joint1 [rad]" -> "panda_joint1", "m1_x_mm" ->
/// "m1_x"; the field itself when it names no unit.
std::string withoutUnit(const std::string& field) {
  std::string f = trimmedField(field);
  if (!headerUnit(f) && !namesAnotherUnit(f)) return f;
  if (!f.empty() && (f.back() == ']' || f.back() == ')')) {
    const auto open = f.find_last_of("[(");
    return trimmedField(f.substr(0, open));
  }
  const auto start = f.find_last_of(" _\t");
  return start == std::string::npos ? f : trimmedField(f.substr(0, start));
}

std::string lowered(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

bool allDigits(const std::string& text) {
  return !text.empty() &&
         std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isdigit(c); });
}

/// The columns a header may name for a marker's orientation: their words and the forms they are
/// read as, the first the default. `rx, ry, rz` are a rotation vector unless --orientation rpy
/// says roll-pitch-yaw; FIGAROH's `phix, phiy, phiz` are roll-pitch-yaw unless --orientation
/// rotation_vector says otherwise.
struct OrientationColumns {
  std::array<const char*, 4> words;
  int count;
  std::array<const char*, 2> forms;  ///< "" : none
};
constexpr std::array<OrientationColumns, 4> kOrientationColumns = {
    {{{"rx", "ry", "rz", ""}, 3, {"rotation_vector", "rpy"}},
     {{"roll", "pitch", "yaw", ""}, 3, {"rpy", ""}},
     {{"qw", "qx", "qy", "qz"}, 4, {"quaternion", ""}},
     {{"phix", "phiy", "phiz", ""}, 3, {"rpy", "rotation_vector"}}}};

/// True when header field `base` (its unit word aside) is coordinate `word` of `marker`:
/// <marker>_<word> (also '.', ' '), or the numbered and axis-first forms mocap tools and FIGAROH
/// write, <word><k> for a marker "k" of digits (x1, phix1) and <word>_<marker> (x_t); `word`
/// alone for the marker "". The word in any case.
bool isMarkerField(const std::string& base, const std::string& marker, const std::string& word) {
  const std::string b = lowered(base);
  if (marker.empty()) return b == word;
  const std::size_t size = marker.size() + word.size();
  auto separator = [](char c) { return c == '_' || c == '.' || c == ' '; };
  if (base.size() == size + 1 && base.starts_with(marker) && separator(base[marker.size()]) &&
      b.substr(marker.size() + 1) == word)
    return true;
  if (base.size() == size + 1 && base.ends_with(marker) && separator(base[word.size()]) &&
      b.substr(0, word.size()) == word)
    return true;
  return allDigits(marker) && base.size() == size && base.ends_with(marker) &&
         b.substr(0, word.size()) == word;
}

/// The fields of `bases` that are coordinate `word` of `marker`.
std::vector<int> markerFields(const std::vector<std::string>& bases, const std::string& marker,
                              const std::string& word) {
  std::vector<int> out;
  for (std::size_t i = 0; i < bases.size(); ++i)
    if (isMarkerField(bases[i], marker, word)) out.push_back(static_cast<int>(i));
  return out;
}

/// The field of coordinate `word` of `marker`, -1 when the header has none; InputError naming
/// the file and both columns when it has two.
int markerField(const fs::path& file, const std::vector<std::string>& fields,
                const std::vector<std::string>& bases, const std::string& marker,
                const std::string& word) {
  const std::vector<int> found = markerFields(bases, marker, word);
  if (found.size() > 1) {
    const auto a = static_cast<std::size_t>(found[0]), b = static_cast<std::size_t>(found[1]);
    throw InputError(file.string(), "line 1",
                     "marker \"" + marker + "\": its " + word + " is named twice, columns " +
                         std::to_string(a + 1) + " (\"" + fields[a] + "\") and " +
                         std::to_string(b + 1) + " (\"" + fields[b] +
                         "\"): keep one column per coordinate (or rename one marker)");
  }
  return found.empty() ? -1 : found.front();
}

/// The markers a header names: every <name> with <name>_x, <name>_y and <name>_z fields (also
/// <name>.x, <name> x; numbered x1, y1, z1; axis first x_<name>; the fields' unit words aside),
/// in the order of their x fields. Fields read as joints are "" in `bases`.
std::vector<std::string> headerMarkers(const std::vector<std::string>& bases) {
  std::vector<std::string> markers;
  for (const std::string& b : bases) {
    std::vector<std::string> candidates;
    const std::string l = lowered(b);
    if (l == "x") candidates.push_back("");
    if (b.size() > 2 && (l.ends_with("_x") || l.ends_with(".x") || l.ends_with(" x")))
      candidates.push_back(b.substr(0, b.size() - 2));
    if (b.size() > 1 && l.front() == 'x' && allDigits(b.substr(1)))
      candidates.push_back(b.substr(1));
    if (b.size() > 2 && l.front() == 'x' && (b[1] == '_' || b[1] == '.' || b[1] == ' '))
      candidates.push_back(b.substr(2));
    for (const std::string& marker : candidates) {
      if (std::find(markers.begin(), markers.end(), marker) != markers.end()) continue;
      if (!markerFields(bases, marker, "y").empty() && !markerFields(bases, marker, "z").empty())
        markers.push_back(marker);
    }
  }
  return markers;
}

/// What a header-named file's CSV entry says: "columns", the joints' "unit" and an instrument's
/// "point_unit", "orientation", "orientation_unit"; the fields it does not read.
struct NamedColumns {
  std::vector<json> entries;  ///< one per marker read (an artifact's file: one)
  std::vector<std::string> ignored;
  std::string note;  ///< a warning: the header names the rows' last fields only
};

/// The one unit word of `fields` (all naming one, or none) of the allowed ones; "" when none
/// names one; InputError naming the file when some do and some do not, or they differ.
std::string commonUnit(const fs::path& file, const std::vector<std::string>& fields,
                       const std::string& what) {
  std::set<std::string> units;
  std::size_t named = 0;
  for (const std::string& f : fields) {
    if (const auto unit = headerUnit(trimmedField(f))) {
      units.insert(*unit);
      ++named;
    }
  }
  if (named == 0) return {};
  if (named != fields.size() || units.size() != 1) {
    throw InputError(file.string(), "line 1",
                     "the " + what + " columns name " +
                         (units.size() > 1 ? "different" : "not all") +
                         " units: one unit word on each (or none, with the unit given as an "
                         "option)");
  }
  return *units.begin();
}

/// A unit given as an option where the header names one too: the two must agree (a file in m
/// read as mm is 1000 times off, and neither is silently preferred). `stated` "" (the header
/// names none) accepts the option.
void requireAgreeingUnit(const fs::path& file, const std::string& option, const std::string& given,
                         const std::string& stated, const std::string& what) {
  if (given.empty() || stated.empty() || given == stated) return;
  throw InputError(file.string(), "line 1",
                   "the header names the " + what + " unit " + stated + " and " + option +
                       " says " + given +
                       ": drop the option (the header's unit is read) or correct the header");
}

/// commonUnit where an option gives the unit: "" when the header's words do not name one unit
/// (the option then decides, as without a header).
std::string headerUnitBesideOption(const fs::path& file, const std::vector<std::string>& fields,
                                   const std::string& what) {
  try {
    return commonUnit(file, fields, what);
  } catch (const InputError&) {
    return {};
  }
}

/// The markers of a header-named station file an import reads: --marker's (each one named in
/// the header), or the header's only marker.
std::vector<std::string> markersRead(const fs::path& file, const std::vector<std::string>& bases,
                                     const ReadingsImport& import) {
  const std::vector<std::string> markers = headerMarkers(bases);
  std::string listed;
  for (const std::string& m : markers) listed += (listed.empty() ? "\"" : ", \"") + m + "\"";
  if (import.markers.empty()) {
    if (markers.size() != 1) {
      throw InputError(file.string(), "line 1",
                       markers.empty()
                           ? "no marker: expected the columns <marker>_x, <marker>_y, "
                             "<marker>_z of the measured point (or x1, y1, z1; x_<marker>, ...)"
                           : "the header names several markers (" + listed +
                                 "): select the machine's tip with --marker NAME (several "
                                 "--marker: one reading of each per row)");
    }
    return markers;
  }
  for (const std::string& marker : import.markers) {
    if (std::find(markers.begin(), markers.end(), marker) == markers.end()) {
      throw InputError(file.string(), "line 1",
                       "no marker \"" + marker +
                           "\" (<name>_x, <name>_y, <name>_z; x<k>, y<k>, z<k>) in the header" +
                           (listed.empty() ? std::string() : " (it names " + listed + ")"));
    }
  }
  return import.markers;
}

/// The orientation columns of `marker` and the form they are read as: the header's word set
/// whose default form is `orientation` (any, when it is ""), else the one `orientation` may read
/// (rx, ry, rz as roll-pitch-yaw with --orientation rpy). InputError naming the file when none
/// or several are found.
std::pair<const OrientationColumns*, std::string> orientationColumns(
    const fs::path& file, const std::vector<std::string>& fields,
    const std::vector<std::string>& bases, const std::string& marker,
    const std::string& orientation) {
  auto present = [&](const OrientationColumns& o) {
    for (int k = 0; k < o.count; ++k)
      if (markerField(file, fields, bases, marker, o.words[static_cast<std::size_t>(k)]) < 0)
        return false;
    return true;
  };
  for (const int choice : {0, 1}) {
    std::vector<const OrientationColumns*> found;
    for (const OrientationColumns& o : kOrientationColumns) {
      const std::string form = o.forms[static_cast<std::size_t>(choice)];
      if (!form.empty() && present(o) && (orientation.empty() ? choice == 0 : form == orientation))
        found.push_back(&o);
    }
    if (found.size() > 1) {
      throw InputError(
          file.string(), "line 1",
          "marker \"" + marker + "\" has several orientations: choose one with --orientation");
    }
    if (found.size() == 1)
      return {found.front(), found.front()->forms[static_cast<std::size_t>(choice)]};
  }
  throw InputError(file.string(), "line 1",
                   "no orientation of marker \"" + marker + "\"" +
                       (orientation.empty() ? std::string() : " as " + orientation) +
                       ": expected its columns _rx, _ry, _rz (a rotation vector; roll-pitch-yaw "
                       "with --orientation rpy), _roll, _pitch, _yaw, _qw, _qx, _qy, _qz or "
                       "phix, phiy, phiz (roll-pitch-yaw)");
}

/// Refuses a point instrument's file whose header names `marker`'s orientation too: its rows are
/// a pose's (`joints` joint readings, then x, y, z and the orientation), read only with
/// --instrument-angle.
void requireNoOrientation(const fs::path& file, const std::vector<std::string>& fields,
                          const std::vector<std::string>& bases, const std::string& marker,
                          std::size_t joints) {
  for (const OrientationColumns& o : kOrientationColumns) {
    bool all = true;
    for (int k = 0; k < o.count; ++k)
      all = all &&
            markerField(file, fields, bases, marker, o.words[static_cast<std::size_t>(k)]) >= 0;
    if (!all) continue;
    throw InputError(file.string(), "line 1",
                     std::to_string(joints) + " joint readings then " +
                         std::to_string(kPointColumns + static_cast<std::size_t>(o.count)) +
                         " coordinates: a pose (x, y, z, then the orientation " + o.words[0] +
                         ", ...): give --instrument-angle, the orientation's noise (deg)");
  }
}

/// A marker's point (and a pose's orientation) columns appended to `columns`, their units to
/// `entry` ("point_unit", "orientation", "orientation_unit"), the fields marked `used`.
void readMarkerColumns(const fs::path& file, const std::vector<std::string>& fields,
                       const std::vector<std::string>& bases, const std::string& marker,
                       const ReadingsImport& import, bool pose, std::vector<bool>& used,
                       json& entry, json& columns) {
  auto take = [&](int f) {
    used[static_cast<std::size_t>(f)] = true;
    requireReadUnit(file, fields, static_cast<std::size_t>(f));
    columns.push_back(trimmedField(fields[static_cast<std::size_t>(f)]));
    return fields[static_cast<std::size_t>(f)];
  };
  std::vector<std::string> point_fields;
  for (const char* axis : {"x", "y", "z"})
    point_fields.push_back(take(markerField(file, fields, bases, marker, axis)));
  std::string point_unit = import.point_unit;
  if (point_unit.empty()) {
    point_unit = commonUnit(file, point_fields, "point's");
  } else {
    requireAgreeingUnit(file, "--point-unit", point_unit,
                        headerUnitBesideOption(file, point_fields, "point's"), "point's");
  }
  if (point_unit.empty()) {
    throw InputError(file.string(), "line 1",
                     "the point's columns name no unit (" + marker + "_x_mm or " + marker +
                         "_x [m]): state it with --point-unit");
  }
  if (point_unit != "mm" && point_unit != "m")
    throw InputError(file.string(), "line 1", "the point's columns are in mm or m");
  entry["point_unit"] = point_unit;
  if (!pose) {
    requireNoOrientation(file, fields, bases, marker, columns.size() - kPointColumns);
    return;
  }
  const auto [o, form] = orientationColumns(file, fields, bases, marker, import.orientation);
  std::vector<std::string> angle_fields;
  for (int k = 0; k < o->count; ++k)
    angle_fields.push_back(
        take(markerField(file, fields, bases, marker, o->words[static_cast<std::size_t>(k)])));
  entry["orientation"] = form;
  if (form == "quaternion") return;
  std::string angle_unit = import.orientation_unit;
  if (angle_unit.empty()) {
    angle_unit = commonUnit(file, angle_fields, "orientation's");
  } else {
    requireAgreeingUnit(file, "--orientation-unit", angle_unit,
                        headerUnitBesideOption(file, angle_fields, "orientation's"),
                        "orientation's");
  }
  if (angle_unit.empty()) {
    throw InputError(file.string(), "line 1",
                     "the orientation's columns name no unit (deg or rad): state it with "
                     "--orientation-unit");
  }
  entry["orientation_unit"] = angle_unit;
}

/// The joint (from 0) `base` names by its index, as exports of machines whose joints have no
/// names write: j1, joint1, joint_1, joint 1, q1, axis1 (any case, from 1); std::nullopt for any
/// other name.
std::optional<std::size_t> indexNamed(const std::string& base) {
  const std::string l = lowered(base);
  for (const std::string_view prefix : {"joint_", "joint ", "joint", "axis_", "axis", "j", "q"}) {
    if (!l.starts_with(prefix)) continue;
    const std::string digits = l.substr(prefix.size());
    if (!allDigits(digits) || digits.size() > 4 || digits.front() == '0') return std::nullopt;
    return static_cast<std::size_t>(std::stoi(digits)) - 1;
  }
  return std::nullopt;
}

bool isIndexName(const std::string& base, std::size_t joint) {
  const auto index = indexNamed(base);
  return index && *index == joint;
}

/// The name messages give joint `joint`: the model's, its axis letter, or j<k>.
std::string jointName(const MachineReadings& machine, std::size_t joint) {
  if (joint < machine.names.size()) return machine.names[joint];
  if (joint < machine.labels.size()) return machine.labels[joint];
  return "j" + std::to_string(joint + 1);
}

/// True when --hold's `name` names joint `joint`: a machine that names its joints (a URDF
/// chain), by those names alone (exact); else by its axis letter (a machine tool's X .. C, any
/// case) or its index (isIndexName).
bool namesJoint(const MachineReadings& machine, const std::string& name, std::size_t joint) {
  if (!machine.names.empty()) return joint < machine.names.size() && machine.names[joint] == name;
  const std::string l = lowered(name);
  for (std::size_t j = 0; j < machine.labels.size(); ++j)
    if (l == lowered(machine.labels[j])) return j == joint;
  return isIndexName(name, joint);
}

/// The --hold of joint `joint`, or nullptr.
const std::pair<std::string, double>* holdOf(const MachineReadings& machine,
                                             const ReadingsImport& import, std::size_t joint) {
  for (const auto& hold : import.holds)
    if (namesJoint(machine, hold.first, joint)) return &hold;
  return nullptr;
}

/// The header fields naming each joint (a joint named twice has two): by the machine's own names
/// where the header names any of them (a URDF chain's joints; a machine tool's axis letters),
/// wherever they stand. Else by index (isIndexName) when the index names cover every joint not
/// held and name no joint beyond the machine's (a header `column_m, j1, ..., j6` of a 7-joint
/// machine names its columns otherwise: read by position, as before). Empty: no joint named.
std::vector<std::vector<int>> jointFieldsOf(const std::vector<std::string>& bases,
                                            const MachineReadings& machine,
                                            const ReadingsImport& import) {
  const std::size_t joints = machine.kinds.size();
  auto match = [&](auto&& names_joint) {
    std::vector<std::vector<int>> out(joints);
    bool any = false;
    for (std::size_t f = 0; f < bases.size(); ++f) {
      for (std::size_t j = 0; j < joints; ++j) {
        if (!names_joint(bases[f], j)) continue;
        out[j].push_back(static_cast<int>(f));
        any = true;
      }
    }
    return any ? out : std::vector<std::vector<int>>{};
  };
  auto own = match([&](const std::string& base, std::size_t j) {
    return (j < machine.names.size() && base == machine.names[j]) ||
           (j < machine.labels.size() && lowered(base) == lowered(machine.labels[j]));
  });
  if (!own.empty()) return own;
  auto by_index =
      match([](const std::string& base, std::size_t j) { return isIndexName(base, j); });
  for (const std::string& base : bases)
    if (const auto index = indexNamed(base); index && *index >= joints) return {};
  for (std::size_t j = 0; j < by_index.size(); ++j)
    if (by_index[j].empty() && holdOf(machine, import, j) == nullptr) return {};
  return by_index;
}

/// Refuses a joint named by two header fields, naming both.
void requireEachJointOnce(const fs::path& file, const std::vector<std::string>& fields,
                          const MachineReadings& machine,
                          const std::vector<std::vector<int>>& joint_fields) {
  for (std::size_t j = 0; j < joint_fields.size(); ++j) {
    if (joint_fields[j].size() < 2) continue;
    const auto a = static_cast<std::size_t>(joint_fields[j][0]);
    const auto b = static_cast<std::size_t>(joint_fields[j][1]);
    throw InputError(file.string(), "line 1",
                     "joint \"" + jointName(machine, j) + "\" is named twice, columns " +
                         std::to_string(a + 1) + " (\"" + fields[a] + "\") and " +
                         std::to_string(b + 1) + " (\"" + fields[b] +
                         "\"): keep one column per joint");
  }
}

/// The columns of `file` when its header names at least one of the machine's readings (a file
/// whose columns are named, docs/plan-format.md "Columns by name"); std::nullopt otherwise.
std::optional<NamedColumns> namedColumns(const fs::path& file, const MachineReadings& machine,
                                         const ReadingsImport& import, bool instrument, bool pose) {
  const std::vector<std::string> fields = headerFields(file);
  std::vector<std::string> bases;
  for (const std::string& f : fields) bases.push_back(withoutUnit(f));
  const std::vector<std::vector<int>> named = jointFieldsOf(bases, machine, import);
  if (named.empty()) return std::nullopt;
  requireEachJointOnce(file, fields, machine, named);
  std::vector<int> joint_field;
  for (const std::vector<int>& f : named) joint_field.push_back(f.empty() ? -1 : f.front());
  NamedColumns out;
  std::vector<bool> used(fields.size(), false);
  std::vector<std::string> joint_fields;
  for (std::size_t j = 0; j < joint_field.size(); ++j) {
    const int f = joint_field[j];
    const bool held = holdOf(machine, import, j) != nullptr;
    if (f >= 0 && held) {
      throw InputError(file.string(), "line 1",
                       "joint \"" + jointName(machine, j) + "\" is both read (column " +
                           std::to_string(f + 1) + ") and held with --hold");
    }
    if (f < 0 && !held) {
      throw InputError(file.string(), "line 1",
                       "no column for joint \"" + jointName(machine, j) +
                           "\": the header names other joints of the machine; a joint no file "
                           "reads is held at a value with --hold " +
                           jointName(machine, j) + "=VALUE");
    }
    if (f >= 0) {
      used[static_cast<std::size_t>(f)] = true;
      requireReadUnit(file, fields, static_cast<std::size_t>(f));
      joint_fields.push_back(fields[static_cast<std::size_t>(f)]);
    }
  }
  std::string unit = import.unit;
  if (unit.empty()) {
    unit = unitOfNamed(file, joint_fields);
  }
  const auto units = readingUnitsFromName(unit);
  json columns = json::array();
  for (std::size_t j = 0; j < joint_field.size(); ++j) {
    const int f = joint_field[j];
    if (f >= 0) {
      columns.push_back(trimmedField(fields[static_cast<std::size_t>(f)]));
      continue;
    }
    const double held = holdOf(machine, import, j)->second;
    // --hold is in deg (mm): the entry's value is in the file's unit, as a column would be.
    columns.push_back(machine.kinds[j] == JointKind::Revolute ? held * kDegree / units->angle_to_rad
                                                              : held / units->length_to_mm);
  }
  if (!instrument) {
    json entry = {{"unit", unit}, {"columns", columns}};
    out.entries.push_back(entry);
  } else {
    // A marker's columns are among those the joints do not take (a machine tool's X is an axis).
    std::vector<std::string> free = bases;
    for (const int f : joint_field)
      if (f >= 0) free[static_cast<std::size_t>(f)].clear();
    for (const std::string& marker : markersRead(file, free, import)) {
      json entry = {{"unit", unit}};
      json marker_columns = columns;
      readMarkerColumns(file, fields, free, marker, import, pose, used, entry, marker_columns);
      entry["columns"] = marker_columns;
      if (import.markers.size() > 1) entry["tip"] = marker;
      out.entries.push_back(entry);
    }
  }
  std::vector<int> selected;
  for (const int f : joint_field)
    if (f >= 0) selected.push_back(f);
  const auto [shift, row] = namedFieldShift(file, selected);
  if (shift > 0) {
    out.note = file.string() + ": its header names its rows' last " + std::to_string(row - shift) +
               " fields (the first " + std::to_string(shift) +
               " are unnamed, an export's labels): read so";
  }
  for (std::size_t f = 0; f < fields.size(); ++f) {
    if (used[f]) continue;
    if (!trimmedField(fields[f]).empty())
      out.ignored.push_back(trimmedField(fields[f]));
    else if (shift == 0)  // an index as pandas writes it, first or last
      out.ignored.push_back("(unnamed column " + std::to_string(f + 1) + ")");
  }
  return out;
}

/// The "columns" of a file whose columns are read in order but some joints are held (--hold):
/// the fields by position ("#k"), the held joints' values in the file's `unit`.
json heldColumns(const MachineReadings& machine, const ReadingsImport& import,
                 const std::string& unit, std::size_t measured) {
  const auto units = readingUnitsFromName(unit);
  json columns = json::array();
  int field = 0;
  auto position = [&field] {
    std::string text = std::to_string(++field);
    text.insert(text.begin(), '#');
    return text;
  };
  for (std::size_t j = 0; j < machine.kinds.size(); ++j) {
    const auto* held = holdOf(machine, import, j);
    if (held == nullptr) {
      columns.push_back(position());
    } else {
      columns.push_back(machine.kinds[j] == JointKind::Revolute
                            ? held->second * kDegree / units->angle_to_rad
                            : held->second / units->length_to_mm);
    }
  }
  for (std::size_t k = 0; k < measured; ++k) columns.push_back(position());
  return columns;
}

// ------------------------------------------------------------------ an instrument's stations

/// The CSV files of a folder, in name order.
std::vector<fs::path> csvFiles(const fs::path& folder) {
  std::vector<fs::path> out;
  for (const FolderEntry& entry : folderEntries(folder))
    if (entry.regular && csvName(entry.path)) out.push_back(entry.path);
  return out;
}

/// DIR's stations: its sub-folders holding CSV files (a station each, named after the folder, each
/// file one entry), or, without such sub-folders, each CSV file of DIR (named after its stem).
std::vector<std::pair<std::string, std::vector<fs::path>>> stations(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir.string(), "", "is not a folder");
  std::vector<std::pair<std::string, std::vector<fs::path>>> out;
  std::vector<fs::path> folders;
  for (const FolderEntry& entry : folderEntries(dir))
    if (entry.directory && !csvFiles(entry.path).empty()) folders.push_back(entry.path);
  for (const fs::path& folder : folders) out.emplace_back(folderName(folder), csvFiles(folder));
  const std::vector<fs::path> loose = csvFiles(dir);
  if (!out.empty() && !loose.empty()) {
    throw InputError(loose.front().string(), "",
                     "a CSV file beside station sub-folders (" + folders.front().string() +
                         ", ...): with sub-folders each station is one; move the file into a "
                         "station's folder, or make every station one CSV file of " +
                         dir.string());
  }
  if (out.empty()) {
    for (const fs::path& file : loose)
      out.emplace_back(file.stem().string(), std::vector<fs::path>{file});
  }
  if (out.empty()) {
    throw InputError(dir.string(), "",
                     "no readings: expected one CSV file per station (or one sub-folder of CSV "
                     "files per station), each row the joint readings then x, y, z");
  }
  return out;
}

/// The one unit the header fields [first, first + 3) name, one of `allowed`; "" when it names
/// none of them or several.
std::string unitOfThree(const std::vector<std::string>& fields, std::size_t first,
                        std::initializer_list<const char*> allowed) {
  std::set<std::string> units;
  for (std::size_t i = first; i < first + 3; ++i) units.insert(*headerUnit(fields[i]));
  if (units.size() != 1) return {};
  for (const char* unit : allowed)
    if (*units.begin() == unit) return unit;
  return {};
}

/// What a station file's rows hold: `joints` joint readings, then a point's 3 coordinates or,
/// for a pose instrument (`pose`), a pose's 6. A file of the other width is refused here, where
/// it can say which option is missing; any other width is the plan parser's to name.
void checkStationWidth(const fs::path& file, std::size_t columns, int joints, bool pose) {
  const auto joint_count = static_cast<std::size_t>(joints);
  const std::string head = std::to_string(joints) + " joint readings then ";
  if (!pose && columns == joint_count + kPoseColumns) {
    throw InputError(file.string(), "line 1",
                     head +
                         "6 coordinates: a pose (x, y, z, then the orientation as a rotation "
                         "vector): give --instrument-angle, the orientation's noise (deg)");
  }
  if (pose && columns == joint_count + kPointColumns) {
    throw InputError(file.string(), "line 1",
                     head +
                         "3 coordinates: a point, where a pose instrument (--instrument-angle) "
                         "reads x, y, z, then the orientation rx, ry, rz");
  }
}

/// A station file's measurement entries (one per marker read; one for a file without names): its
/// joints' unit and its point's (and a pose's orientation's), from --unit, --point-unit and
/// --orientation-unit where given, otherwise from its header (the last 3 columns are the point's:
/// `q1_deg, ..., x_m, y_m, z_m`; of a pose, the last 6: `..., x_m, y_m, z_m, rx_rad, ry_rad,
/// rz_rad`); a point without a stated unit is in mm, an orientation in deg.
std::vector<json> stationEntries(const fs::path& file, const ReadingsImport& import,
                                 const fs::path& plan_folder, const MachineReadings& machine,
                                 bool pose, std::vector<std::string>& ignored) {
  const fs::path relative = fs::absolute(file).lexically_normal().lexically_relative(plan_folder);
  if (auto named = namedColumns(file, machine, import, true, pose)) {
    std::vector<json> entries;
    for (const json& columns : named->entries) {
      entries.push_back({{"csv", relative.generic_string()}});
      entries.back().update(columns);
    }
    ignored.insert(ignored.end(), named->ignored.begin(), named->ignored.end());
    return entries;
  }
  if (import.markers.size() > 1) {
    throw InputError(file.string(), "line 1",
                     "several --marker need a header naming the columns (the joints by name, "
                     "<marker>_x, <marker>_y, <marker>_z of each marker)");
  }
  std::string unit = import.unit, point_unit = import.point_unit,
              orientation_unit = import.orientation_unit;
  const std::vector<std::string> fields = headerFields(file);
  // Joints held (--hold) have no column; a quaternion takes 4 columns.
  int joints = 0;
  for (std::size_t j = 0; j < machine.kinds.size(); ++j)
    joints += holdOf(machine, import, j) == nullptr ? 1 : 0;
  const bool quaternion = pose && import.orientation == "quaternion";
  checkStationWidth(file, fields.size() - (quaternion ? 1 : 0), joints, pose);
  const std::size_t measured = pose ? kPoseColumns + (quaternion ? 1 : 0) : kPointColumns;
  // A quaternion's 4 columns have no unit; every other column names one in a header with units.
  const auto with_units = static_cast<std::ptrdiff_t>(fields.size()) - (quaternion ? 4 : 0);
  const bool units_in_header =
      with_units > 0 && std::all_of(fields.begin(), fields.begin() + with_units,
                                    [](const std::string& f) { return headerUnit(f).has_value(); });
  if (unit.empty()) {
    if (fields.size() <= measured || !units_in_header) {
      throw InputError(file.string(), "line 1",
                       pose
                           ? "expected a header naming each column's unit (q1_deg, ..., x_m, y_m, "
                             "z_m, rx_deg, ry_deg, rz_deg), or state the joints' unit with --unit, "
                             "the point's with --point-unit and the orientation's with "
                             "--orientation-unit"
                           : "expected a header naming each column's unit (q1_deg, ..., x_m, y_m, "
                             "z_m), or state the joints' unit with --unit and the point's with "
                             "--point-unit");
    }
    unit = unitOfColumns(file, fields, 0, fields.size() - measured);
  }
  const bool header = units_in_header && fields.size() > measured;
  const std::size_t first = fields.size() - measured;
  if (point_unit.empty() && header) {
    point_unit = unitOfThree(fields, first, {"mm", "m"});
    if (point_unit.empty()) {
      throw InputError(file.string(), "line 1",
                       std::string("the ") +
                           (pose ? "3 columns after the joints" : "last 3 columns") +
                           " are the measured point: one length unit (x_mm, y_mm, z_mm or x_m, "
                           "y_m, z_m)");
    }
  }
  if (header) {  // an option beside a header's own unit words: the two agree
    requireAgreeingUnit(file, "--point-unit", point_unit, unitOfThree(fields, first, {"mm", "m"}),
                        "point's");
    if (pose && !quaternion) {
      requireAgreeingUnit(file, "--orientation-unit", orientation_unit,
                          unitOfThree(fields, first + kPointColumns, {"deg", "rad"}),
                          "orientation's");
    }
  }
  if (pose && !quaternion && orientation_unit.empty() && header) {
    orientation_unit = unitOfThree(fields, first + kPointColumns, {"deg", "rad"});
    if (orientation_unit.empty()) {
      throw InputError(file.string(), "line 1",
                       "the last 3 columns are the measured orientation: one angle unit (rx_deg, "
                       "ry_deg, rz_deg or rx_rad, ry_rad, rz_rad)");
    }
  }
  json entry = {{"csv", relative.generic_string()},
                {"unit", unit},
                {"point_unit", point_unit.empty() ? "mm" : point_unit}};
  if (pose && !quaternion)
    entry["orientation_unit"] = orientation_unit.empty() ? "deg" : orientation_unit;
  if (pose && !import.orientation.empty()) entry["orientation"] = import.orientation;
  if (!import.holds.empty()) entry["columns"] = heldColumns(machine, import, unit, measured);
  return {entry};
}

/// The stations of CSV files given one by one: each file one station, named after its stem.
std::vector<std::pair<std::string, std::vector<fs::path>>> stationsOfFiles(
    const std::vector<std::string>& inputs) {
  std::vector<std::pair<std::string, std::vector<fs::path>>> out;
  std::set<std::string> names;
  for (const std::string& input : inputs) {
    const fs::path path = fs::path(input).lexically_normal();
    std::error_code ec;
    if (!csvName(path) || !fs::is_regular_file(path, ec)) {
      throw InputError(input, "",
                       "expected a folder of stations (one CSV file or sub-folder each), or CSV "
                       "files of one station each (*.csv)");
    }
    if (!names.insert(path.stem().string()).second) {
      throw InputError(input, "",
                       "a second file named " + path.stem().string() +
                           ".csv: stations need names of their own; rename one");
    }
    out.emplace_back(path.stem().string(), std::vector<fs::path>{path});
  }
  return out;
}

json stationPlacements(const std::vector<std::pair<std::string, std::vector<fs::path>>>& sources,
                       const ReadingsImport& import, const fs::path& plan_folder,
                       const std::string& instrument_id, const MachineReadings& machine, bool pose,
                       std::vector<std::string>& ignored) {
  json placements = json::array();
  for (const auto& [name, files] : sources) {
    json measurements = json::array();
    for (const fs::path& file : files)
      for (json& entry : stationEntries(file, import, plan_folder, machine, pose, ignored))
        measurements.push_back(std::move(entry));
    placements.push_back(
        {{"name", name}, {"artifact", instrument_id}, {"measurements", measurements}});
  }
  return placements;
}

/// A feature file's CSV entry: its unit (the layout's, --unit, or the header's) and, for a file
/// whose header names its columns or with joints held, its "columns".
json featureEntry(const FeatureFile& file, const ReadingsImport& import,
                  const fs::path& plan_folder, const MachineReadings& machine,
                  std::vector<std::string>& ignored, std::vector<std::string>& notes) {
  const fs::path relative =
      fs::absolute(file.path).lexically_normal().lexically_relative(plan_folder);
  json entry = {{"feature", file.feature}, {"csv", relative.generic_string()}};
  if (auto named = namedColumns(file.path, machine, import, false, false)) {
    entry.update(named->entries.front());
    ignored.insert(ignored.end(), named->ignored.begin(), named->ignored.end());
    if (!named->note.empty()) notes.push_back(named->note);
    return entry;
  }
  entry["unit"] = file.unit.empty() ? unitFromHeader(file.path) : file.unit;
  if (!import.holds.empty())
    entry["columns"] = heldColumns(machine, import, entry["unit"].get<std::string>(), 0);
  return entry;
}

/// A marker's offset from the chain's tip, one standard deviation per coordinate, mm: where on
/// the hand a marker sits is not known, so no correction within several of these is implausible
/// (corrections.hpp); as information it weighs nothing beside the readings.
constexpr double kMarkerOffsetPrior = 100.0;

/// The joint of marker `name` in a machine block of several markers.
std::string markerJoint(const std::string& name) {
  return "marker_" + name;
}

/// `machine` (a chain of one tip) with one tip per marker of `markers`: a fixed joint
/// "marker_<name>" after the chain's last joint, its origin 0 (the marker's offset from the
/// chain's tip is what the calibration estimates), and "tips" naming each path (docs/urdf.md,
/// "one machine, several tips"). With "calibrate": "identifiable", the markers' x, y, z are listed
/// first; each has a prior of kMarkerOffsetPrior unless the block states one.
json withMarkerTips(json machine, const std::vector<std::string>& markers) {
  if (machine.value("model", "") != "chain" || machine.contains("tips") ||
      !machine.contains("joints") || !machine["joints"].is_array()) {
    throw InputError("--marker", markers.front(),
                     "several markers need a chain machine of one tip (--urdf with one --tip, "
                     "or a chain machine block without \"tips\"): each marker becomes a tip");
  }
  json path = json::array();
  std::set<std::string> names;
  for (const json& joint : machine["joints"]) {
    const std::string name = joint.value("name", "");
    if (name.empty()) {
      throw InputError("--marker", markers.front(),
                       "several markers need the chain's joints named (\"name\")");
    }
    path.push_back(name);
    names.insert(name);
  }
  json tips = json::array();
  for (const std::string& marker : markers) {
    const std::string joint = markerJoint(marker);
    if (!names.insert(joint).second) {
      throw InputError("--marker", marker,
                       "given twice, or the machine already has a joint \"" + joint + "\"");
    }
    machine["joints"].push_back({{"name", joint},
                                 {"type", "fixed"},
                                 {"origin", {{"xyz", {0.0, 0.0, 0.0}}, {"rpy", {0.0, 0.0, 0.0}}}}});
    json joints = path;
    joints.push_back(joint);
    tips.push_back({{"name", marker}, {"joints", joints}});
  }
  machine["tips"] = tips;
  // The markers' offsets first in the rank rule's order (the chain's tip frame then takes none of
  // their directions), each with a prior of kMarkerOffsetPrior: unknown, not implausible.
  json first = json::array();
  for (const std::string& marker : markers)
    for (const char* axis : {".x", ".y", ".z"}) first.push_back(markerJoint(marker) + axis);
  if (machine.value("calibrate", json()) == "identifiable")
    machine["calibrate"] = {{"identifiable", first}};
  if (!machine.contains("prior") || !machine["prior"].is_object())
    machine["prior"] = json::object();
  for (const json& name : first)
    if (!machine["prior"].contains(name.get<std::string>()))
      machine["prior"][name.get<std::string>()] = kMarkerOffsetPrior;
  return machine;
}

json machineBlock(const ReadingsImport& import) {
  if (!import.machine_file.empty()) {
    json machine = readJsonFile(import.machine_file);
    if (machine.is_object() && machine.contains("machine")) machine = machine.at("machine");
    if (!machine.is_object())
      throw InputError(import.machine_file, "", "expected a machine block (an object)");
    if (!import.keep_calibrate) machine["calibrate"] = "identifiable";
    return import.markers.size() > 1 ? withMarkerTips(machine, import.markers) : machine;
  }
  json machine = import.tips.size() > 1 ? importUrdf(import.urdf, import.base, import.tips)
                                        : importUrdf(import.urdf, import.base, import.tip);
  machine["calibrate"] = "identifiable";
  return import.markers.size() > 1 ? withMarkerTips(machine, import.markers) : machine;
}

/// machineBlock with --prior's tolerances as the machine's default prior.
json machineWithPrior(const ReadingsImport& import) {
  json machine = machineBlock(import);
  if (import.prior_length > 0.0 && import.prior_angle > 0.0)
    machine["prior"]["default"] = {{"length", import.prior_length}, {"angle", import.prior_angle}};
  return machine;
}

/// The artifacts block and the id of the artifact placed.
std::pair<json, std::string> artifactBlock(const ReadingsImport& import) {
  if (import.instrument) {
    json instrument = {
        {"type", "instrument"}, {"measures", "point"}, {"noise", *import.instrument}};
    if (import.instrument_angle) {  // a 6-DOF tracker: each reading a pose
      instrument["measures"] = "pose";
      instrument["noise_angle"] = *import.instrument_angle;
    }
    return {json{{"instrument", instrument}}, "instrument"};
  }
  if (import.ball_bar) {
    json bar = {{"type", "ball_bar"}, {"length", *import.ball_bar}};
    if (import.u_length > 0.0) bar["u_length"] = import.u_length;
    return {json{{"bar", bar}}, "bar"};
  }
  const json artifacts = readJsonFile(import.artifact_file);
  if (!artifacts.is_object() || artifacts.empty()) {
    throw InputError(import.artifact_file, "",
                     "expected an artifacts block: {\"id\": {\"type\": ...}}");
  }
  return {artifacts, artifacts.begin().key()};
}

/// The placement folders of DIR: its sub-folders with feature files, in name order; DIR itself
/// when it holds feature files and no such sub-folder.
std::vector<fs::path> placementFolders(const fs::path& dir, const std::string& unit) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir.string(), "", "is not a folder");
  std::vector<fs::path> out;
  for (const FolderEntry& entry : folderEntries(dir))
    if (entry.directory && !featureFiles(entry.path, unit).empty()) out.push_back(entry.path);
  const std::vector<FeatureFile> loose = featureFiles(dir, unit);
  if (!out.empty() && !loose.empty()) {
    throw InputError(loose.front().path.string(), "",
                     "a feature file beside placement sub-folders (" + out.front().string() +
                         ", ...): with sub-folders each placement is one; move the file into a "
                         "placement's folder, or out of " +
                         dir.string());
  }
  if (out.empty() && !loose.empty()) out.push_back(dir);
  if (out.empty()) {
    throw InputError(dir.string(), "",
                     "no readings: expected sub-folders (one per placement) holding hole_<k>.csv "
                     "or feature_<k>.csv files");
  }
  return out;
}

/// One placement of the import: its name, its feature files and the folder's pose.json (a
/// plane's placement), if any.
struct PlacementSource {
  std::string name;
  std::vector<FeatureFile> files;
  fs::path pose;  ///< empty: none
  /// A log of several placements in one file: the rows whose `rows_column` holds `rows_value`.
  std::string rows_column, rows_value;
};

/// The header field naming each row's placement in a log of several ("sphere", "placement",
/// any case, a unit word aside), or std::nullopt.
std::optional<std::string> placementColumn(const fs::path& file) {
  for (const std::string& field : headerFields(file)) {
    const std::string base = lowered(withoutUnit(field));
    if (base == "sphere" || base == "placement") return trimmedField(field);
  }
  return std::nullopt;
}

/// One placement per value of the log's placement column, in the order the values first
/// appear (docs/five-axis.md: a probing log of several spheres).
std::vector<PlacementSource> placementsOfLog(const fs::path& path, const std::string& column,
                                             const std::string& unit) {
  std::vector<PlacementSource> out;
  std::set<std::string> seen;
  for (const auto& [line, value] : readCsvColumn(path.string(), column)) {
    if (value.empty())
      throw InputError(path.string(), "line " + std::to_string(line),
                       "no value in column \"" + column + "\": name each row's placement");
    if (seen.insert(value).second)
      out.push_back({value, {FeatureFile{0, path, unit}}, {}, column, value});
  }
  return out;
}

/// The inputs of the import: DIR, or CSV files.
std::vector<std::string> importInputs(const ReadingsImport& import) {
  return import.inputs.empty() ? std::vector<std::string>{import.folder} : import.inputs;
}

/// True when the import reads CSV files given one by one (not a folder).
bool filesGiven(const ReadingsImport& import) {
  const std::vector<std::string> inputs = importInputs(import);
  std::error_code ec;
  return inputs.size() > 1 || !fs::is_directory(inputs.front(), ec);
}

/// The placements of the import: DIR's placement folders, or one per CSV file given (named after
/// the file, its rows feature 0's readings).
std::vector<PlacementSource> placementSources(const ReadingsImport& import) {
  std::vector<PlacementSource> out;
  if (!filesGiven(import)) {
    const fs::path dir = fs::path(importInputs(import).front()).lexically_normal();
    for (const fs::path& folder : placementFolders(dir, import.unit)) {
      PlacementSource source{folderName(folder), featureFiles(folder, import.unit), {}, {}, {}};
      if (const fs::path pose = folder / "pose.json"; fs::exists(pose)) source.pose = pose;
      out.push_back(std::move(source));
    }
    return out;
  }
  std::set<std::string> names;
  for (const std::string& input : importInputs(import)) {
    const fs::path path = fs::path(input).lexically_normal();
    std::error_code ec;
    if (!csvName(path) || !fs::is_regular_file(path, ec)) {
      throw InputError(input, "",
                       "expected a folder of placement sub-folders, or CSV files of one placement "
                       "each (*.csv)");
    }
    std::vector<PlacementSource> sources;
    if (const auto column = placementColumn(path))
      sources = placementsOfLog(path, *column, import.unit);
    else
      sources.push_back({path.stem().string(), {FeatureFile{0, path, import.unit}}, {}, {}, {}});
    for (PlacementSource& source : sources) {
      if (!names.insert(source.name).second)
        throw InputError(input, "",
                         "a second placement named " + source.name +
                             ": placements need names of their own; rename one (a file, or a "
                             "value of its sphere column)");
      out.push_back(std::move(source));
    }
  }
  return out;
}

/// Which tip touched in placement `name` of a machine with several `tips` (--tip-of); std::nullopt
/// for a machine of one tip. InputError when several tips leave it unsaid, or --tip-of names no
/// tip of the machine.
std::optional<std::string> placementTip(const ReadingsImport& import,
                                        const std::vector<std::string>& tips,
                                        const std::string& name) {
  if (tips.empty()) return std::nullopt;
  std::string listed;
  for (const std::string& tip : tips) listed += (listed.empty() ? "" : ", ") + tip;
  for (const auto& [placement, tip] : import.tip_of) {
    if (placement != name) continue;
    if (std::find(tips.begin(), tips.end(), tip) == tips.end())
      throw InputError("--tip-of", placement + "=" + tip,
                       "not a tip of the machine (its tips: " + listed + ")");
    return tip;
  }
  throw InputError(name, "",
                   "which tip touched in this placement? The machine has " +
                       std::to_string(tips.size()) + " (" + listed + "): add --tip-of " + name +
                       "=TIP");
}

/// --tip-of checked whole before any placement is read: each names a placement of the import
/// and a tip of the machine; a placement given twice is refused unless both say the same tip; a
/// machine of one tip takes --tip-of naming that tip with a note (every placement is its), and
/// refuses any other.
void checkTipOf(const ReadingsImport& import, const std::vector<std::string>& tips,
                const std::vector<PlacementSource>& sources, std::vector<std::string>& notes) {
  std::map<std::string, std::string> chosen;
  for (const auto& entry : import.tip_of) {
    // Named, not bound: a lambda below reads the placement (clang 14 captures no binding).
    const std::string& placement = entry.first;
    const std::string& tip = entry.second;
    const std::string given = placement + "=" + tip;
    if (std::none_of(sources.begin(), sources.end(),
                     [&](const PlacementSource& s) { return s.name == placement; }))
      throw InputError("--tip-of", given, "no placement of that name");
    const auto [at, inserted] = chosen.emplace(placement, tip);
    if (!inserted && at->second != tip) {
      throw InputError("--tip-of", given,
                       "placement " + placement + " is given two tips, " + at->second + " and " +
                           tip + ": give one --tip-of per placement");
    }
    if (tips.empty()) {
      if (!import.tip.empty() && tip == import.tip) continue;
      throw InputError("--tip-of", given,
                       "the machine has one tip" +
                           (import.tip.empty() ? std::string() : " (" + import.tip + ")") +
                           ": --tip-of says which of several --tip touched; drop it");
    }
    if (std::find(tips.begin(), tips.end(), tip) == tips.end()) {
      std::string listed;
      for (const std::string& t : tips) listed += (listed.empty() ? "" : ", ") + t;
      throw InputError("--tip-of", given, "not a tip of the machine (its tips: " + listed + ")");
    }
  }
  if (tips.empty() && !import.tip_of.empty()) {
    notes.push_back("--tip-of: the machine has one tip, " + import.tip +
                    ": every placement is its (--tip-of chooses among several --tip)");
  }
}

/// Largest revolute range a widened limit may reach, deg: beyond it a reading is taken for one
/// in the wrong unit.
constexpr double kWidestRevoluteDeg = 360.0;

/// The range a joint's readings may reach and its limits be widened to (internal units): a
/// revolute joint up to kWidestRevoluteDeg, or, where its limits span a whole turn (a URDF
/// continuous joint, [-180, 180]: it turns on), a turn beyond them (a continuous joint at 400
/// deg); a prismatic joint a tenth of its range (at least 1 mm) beyond its limits, a reading in
/// the wrong unit being 1000 times off.
std::array<double, 2> widenableRange(const std::array<double, 2>& limits, bool revolute) {
  if (!revolute) {
    const double reach = std::max(0.1 * (limits[1] - limits[0]), 1.0);
    return {limits[0] - reach, limits[1] + reach};
  }
  const bool whole_turn = limits[1] - limits[0] >= 2.0 * std::numbers::pi - 1e-9;
  const double widest = whole_turn ? std::max(-limits[0], limits[1]) + degToRad(kWidestRevoluteDeg)
                                   : degToRad(kWidestRevoluteDeg);
  return {-widest, widest};
}

/// The machine's joint limits widened to the range of the plan's CSV readings (see the header).
std::vector<std::string> widenJointLimits(json& document, const std::string& source,
                                          const fs::path& folder) {
  json machine_only = document;
  machine_only.erase("placements");
  const Plan plan = parsePlan(machine_only, source, /*require_placements=*/false, false);
  const Machine& machine = plan.machine;
  if (!machine.limits_stated) return {};
  const Mechanism& mech = *machine.mechanism;
  std::vector<JointKind> kinds;
  for (int i = 0; i < mech.jointCount(); ++i) kinds.push_back(mech.jointKind(i));
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(mech.jointCount(), INFINITY);
  Eigen::VectorXd hi = -lo;
  for (const json& placement : document.at("placements")) {
    for (const json& entry : placement.at("measurements")) {
      const std::string file =
          (folder / entry.at("csv").get<std::string>()).lexically_normal().string();
      const auto units = readingUnitsFromName(entry.at("unit").get<std::string>());
      // An instrument's rows end with the measured point (or pose), read here as lengths and not
      // kept; entries whose "columns" select the fields read the joints' alone.
      std::vector<JointKind> columns = kinds;
      std::optional<std::vector<CsvColumn>> selected;
      if (entry.contains("columns")) {
        const Node node(entry.at("columns"), "/columns", file);
        selected = parseCsvColumns(node, entry.at("columns").size());
        selected->resize(kinds.size());
      } else if (entry.contains("point_unit")) {
        const std::size_t measured =
            entry.contains("orientation_unit") ? kPoseColumns : kPointColumns;
        columns.resize(kinds.size() + measured, JointKind::Prismatic);
      }
      for (const Eigen::VectorXd& row :
           readJointCsv(file, columns, *units, nullptr, selected ? &*selected : nullptr)) {
        const Eigen::VectorXd q = row.head(mech.jointCount());
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
      }
    }
  }
  std::vector<std::string> warnings;
  for (int i = 0; i < mech.jointCount(); ++i) {
    auto limits = machine.joint_limits[static_cast<std::size_t>(i)];
    if (lo[i] >= limits[0] && hi[i] <= limits[1]) continue;
    const bool revolute = kinds[static_cast<std::size_t>(i)] == JointKind::Revolute;
    const auto widest = widenableRange(limits, revolute);
    const bool widen = lo[i] >= widest[0] && hi[i] <= widest[1];
    if (!widen) continue;  // refused when the plan is parsed, naming the file and row
    const double to_file = revolute ? radToDeg(1.0) : 1.0;
    const char* unit = revolute ? "deg" : "mm";
    const double old_lo = limits[0] * to_file, old_hi = limits[1] * to_file;
    limits = {std::min(limits[0], lo[i]), std::max(limits[1], hi[i])};
    document["machine"]["joint_limits"][static_cast<std::size_t>(i)] = {limits[0] * to_file,
                                                                        limits[1] * to_file};
    char text[320];
    std::snprintf(text, sizeof text,
                  "joint %d: readings reach [%.3f, %.3f] %s, beyond its limits [%.3f, %.3f] "
                  "%s: joint_limits widened to the readings",
                  i + 1, lo[i] * to_file, hi[i] * to_file, unit, old_lo, old_hi, unit);
    warnings.emplace_back(text);
  }
  return warnings;
}

/// A --hold value where the option gives it, not as the CSV column it becomes (issue 44): within
/// the range the joint's readings may reach (widenableRange), in deg (mm for a prismatic joint).
void checkHeldValue(const Machine& machine, const MachineReadings& readings, std::size_t joint,
                    const std::string& name, double value) {
  const bool revolute = readings.kinds[joint] == JointKind::Revolute;
  const auto limits = machine.joint_limits[joint];
  const auto range = widenableRange(limits, revolute);
  const double to_file = revolute ? radToDeg(1.0) : 1.0;
  const double internal = value / to_file;
  if (std::abs(value) <= kMaxInputMagnitude && internal >= range[0] && internal <= range[1]) return;
  const char* unit = revolute ? " deg" : " mm";
  throw InputError(
      "--hold", name + "=" + formatShortest(value),
      "joint \"" + jointName(readings, joint) + "\" held at " + formatShortest(value) + unit +
          ", beyond what its readings may reach (" + formatShortest(range[0] * to_file) + " .. " +
          formatShortest(range[1] * to_file) + unit + ", its joint_limits [" +
          formatShortest(limits[0] * to_file) + ", " + formatShortest(limits[1] * to_file) + "]" +
          unit + "): check the value (deg, or mm for a prismatic joint)");
}

/// The joint readings per row of the machine block `machine` (its driving joints), read beside
/// the plan's `artifacts`; InputError when --hold names a joint the machine does not read.
MachineReadings machineReadings(const json& machine, const json& artifacts,
                                const std::string& source, const ReadingsImport& import) {
  const json document = {{"format", "artcal-plan/1"},
                         {"machine", machine},
                         {"noise", {{"probe", 0.1}, {"encoder", 0.0}}},
                         {"artifacts", artifacts}};
  const Plan plan = parsePlan(document, source, /*require_placements=*/false, false);
  const Mechanism& mech = *plan.machine.mechanism;
  MachineReadings out;
  out.names = mech.readingNames();
  out.labels = mech.jointLabels();
  if (mech.stylusNames().size() > 1) out.tips = mech.stylusNames();
  for (int i = 0; i < mech.jointCount(); ++i) out.kinds.push_back(mech.jointKind(i));
  std::map<std::size_t, double> held;
  for (const auto& [name, value] : import.holds) {
    std::size_t joint = 0;
    while (joint < out.kinds.size() && !namesJoint(out, name, joint)) ++joint;
    if (joint == out.kinds.size()) {
      std::string names;
      for (std::size_t j = 0; j < out.kinds.size(); ++j)
        names += (names.empty() ? "" : ", ") + jointName(out, j);
      throw InputError(
          "--hold", name,
          "not a joint the machine reads (it reads " + names +
              (out.names.empty() ? std::string(", also j1, joint_1, q1, ...") : std::string()) +
              ")");
    }
    checkHeldValue(plan.machine, out, joint, name, value);
    // Given twice: the same value is one hold; two values conflict (options given twice are
    // refused where they conflict, docs/hardening.md).
    const auto [at, inserted] = held.emplace(joint, value);
    if (!inserted && at->second != value) {
      throw InputError("--hold", name + "=" + formatShortest(value),
                       "joint \"" + jointName(out, joint) + "\" is held twice, at " +
                           formatShortest(at->second) + " and " + formatShortest(value) +
                           ": give one --hold per joint");
    }
  }
  return out;
}

/// A folder's pose.json, checked as a placement's pose against that file (its pointer, its
/// numbers' bounds) where it is read: the plan written from it is the import's output, not yet
/// written, and no place to point at. The 2-D form is the one with an "angle".
json readPoseFile(const std::string& path) {
  json document = readJsonFile(path);
  const Node pose(document, "", path);
  const bool planar = document.is_object() && document.contains("angle");
  std::vector<std::string> warnings;  // the plan's own reading warns once more, where it is used
  parsePose(pose, planar ? 2 : 3, warnings, /*centre_only=*/true);
  return document;
}

}  // namespace

ImportedPlan importReadings(const ReadingsImport& import) {
  const bool prior = import.prior_length != 0.0 || import.prior_angle != 0.0;
  const auto tolerance = [](double v) { return v > 0.0 && v <= kMaxInputMagnitude; };
  if (prior && !(tolerance(import.prior_length) && tolerance(import.prior_angle))) {
    const bool finite = std::isfinite(import.prior_length) && std::isfinite(import.prior_angle);
    throw InputError(
        "--prior",
        finite ? formatShortest(import.prior_length) + "," + formatShortest(import.prior_angle)
               : std::string(),
        "expected LENGTH,ANGLE (mm, deg), each > 0 and within 1e9, e.g. 5,0.5");
  }
  if (!import.unit.empty() && !readingUnitsFromName(import.unit)) {
    throw InputError(
        import.unit, "",
        "unknown unit (expected deg, rad, mm, m, or an angle and a length unit as rad+m)");
  }
  const std::vector<std::string> inputs = importInputs(import);
  const bool files_given = filesGiven(import);
  const fs::path dir = fs::path(inputs.front()).lexically_normal();
  const bool to_stdout = import.output.empty() || import.output == kStandardOutput;
  const fs::path output_folder = to_stdout ? fs::path() : fs::path(import.output).parent_path();
  const fs::path plan_folder = fs::absolute(output_folder.empty() ? fs::path(".") : output_folder);
  const auto [artifacts, artifact_id] = artifactBlock(import);
  const json& artifact = artifacts.at(artifact_id);
  const bool instrument = artifact.is_object() && artifact.value("type", "") == "instrument";
  if (import.markers.size() > 1 && !instrument) {
    throw InputError("--marker", import.markers.front(),
                     "several markers are an instrument's readings (--instrument): a ball bar's "
                     "or an artifact's files read one tip");
  }
  const std::string source = to_stdout ? std::string("import-readings") : import.output;
  const json machine = machineWithPrior(import);
  json placements = json::array();
  const MachineReadings readings = machineReadings(machine, artifacts, source, import);
  std::vector<std::string> ignored;  // columns of header-named files not read
  std::vector<std::string> notes;    // headers naming their rows' last fields only
  if (instrument) {
    const auto measures = artifact.find("measures");
    const bool pose = measures != artifact.end() && *measures == "pose";
    placements = stationPlacements(files_given ? stationsOfFiles(inputs) : stations(dir), import,
                                   plan_folder, artifact_id, readings, pose, ignored);
  }
  const std::vector<std::string>& tips = readings.tips;
  const std::vector<PlacementSource> sources =
      instrument ? std::vector<PlacementSource>{} : placementSources(import);
  checkTipOf(import, tips, sources, notes);
  for (const PlacementSource& source : sources) {
    const std::optional<std::string> tip = placementTip(import, tips, source.name);
    json measurements = json::array();
    for (const FeatureFile& file : source.files) {
      if (import.ball_bar && file.feature > 1) {
        throw InputError(file.path.string(), "",
                         "feature " + std::to_string(file.feature) +
                             " of a ball bar, whose features are 0 and 1: rename the file or "
                             "move it out of the folder");
      }
      measurements.push_back(featureEntry(file, import, plan_folder, readings, ignored, notes));
      if (tip) measurements.back()["tip"] = *tip;
      if (!source.rows_column.empty()) {
        measurements.back()["rows"] = {{"column", source.rows_column},
                                       {"value", source.rows_value}};
        std::erase(ignored, source.rows_column);
      }
    }
    placements.push_back(
        {{"name", source.name}, {"artifact", artifact_id}, {"measurements", measurements}});
    // Where the artifact stood (a plane's placement, docs/planes.md): the folder's pose.json,
    // {"center": [...], "direction": [...], "roll": deg}, checked when the plan is read; without
    // one a plane's placement is where its touches put it.
    if (!source.pose.empty()) placements.back()["pose"] = readPoseFile(source.pose.string());
  }
  checkEachFileReadOnce(placements, plan_folder);
  const std::string plan_name = !files_given         ? folderName(dir)
                                : inputs.size() == 1 ? dir.stem().string()
                                                     : folderName(fs::absolute(dir).parent_path());
  std::string what;
  for (const std::string& input : inputs)
    what += (what.empty() ? "" : ", ") + fs::path(input).lexically_normal().generic_string();
  ImportedPlan out;
  out.plan = {{"format", "artcal-plan/1"},
              {"name", plan_name},
              {"description", "readings of " + what + " (artcal import-readings)"},
              {"machine", machine},
              {"noise", {{"probe", import.probe}, {"encoder", import.encoder}}},
              {"artifacts", artifacts},
              {"placements", placements}};
  out.source = source;
  if (!files_given) out.warnings = unreadCsvFiles(dir, placements, plan_folder);
  out.warnings.insert(out.warnings.end(), notes.begin(), notes.end());
  if (!ignored.empty()) {
    std::set<std::string> distinct(ignored.begin(), ignored.end());
    std::string names;
    for (const std::string& name : distinct) names += (names.empty() ? "" : ", ") + name;
    out.warnings.push_back("columns not read (not a joint of the machine nor the marker's): " +
                           names);
  }
  if (!out.plan["machine"].contains("joint_limits") || import.keep_limits) return out;
  for (std::string& warning : widenJointLimits(out.plan, out.source, plan_folder))
    out.warnings.push_back(std::move(warning));
  return out;
}

}  // namespace artcal
