#include "artcal/io/readings_import.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
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

std::string firstLine(const fs::path& file) {
  const std::string text = readInputFile(file.string());
  std::string line = text.substr(0, text.find('\n'));
  if (static_cast<std::size_t>(std::count(line.begin(), line.end(), ',')) >= kMaxHeaderColumns) {
    throw InputError(file.string(), "line 1",
                     "more than " + std::to_string(kMaxHeaderColumns) +
                         " columns: a file of readings has one column per joint reading and "
                         "coordinate");
  }
  return line;
}

/// The unit a header field names as its last word: "q1_deg", "joint1 [rad]", "z (mm)".
std::optional<std::string> headerUnit(std::string field) {
  while (!field.empty() && std::isspace(static_cast<unsigned char>(field.back()))) field.pop_back();
  if (!field.empty() && (field.back() == ']' || field.back() == ')')) field.pop_back();
  const auto start = field.find_last_of(" _[(\t");
  const std::string word = start == std::string::npos ? field : field.substr(start + 1);
  for (const char* unit : {"deg", "rad", "mm", "m"}) {
    if (word == unit) return word;
  }
  return std::nullopt;
}

/// How far right of where the header of `file` puts them its first data row's fields at
/// `selected` (header positions) are (csv_readings.hpp, headerShift), and the row's field count.
std::pair<std::size_t, std::size_t> namedFieldShift(const fs::path& file,
                                                    const std::vector<int>& selected) {
  const std::string text = readInputFile(file.string());
  const std::size_t first_end = text.find('\n');
  if (first_end == std::string::npos) return {0, 0};
  const std::string_view header(text.data(), first_end);
  std::size_t start = first_end;
  while (start != std::string::npos && start + 1 < text.size()) {
    const std::size_t end = text.find('\n', start + 1);
    const std::string_view line = std::string_view(text).substr(start + 1, end - start - 1);
    start = end;
    if (line.find_first_not_of(" \t\r") == std::string_view::npos) continue;
    if (static_cast<std::size_t>(std::count(line.begin(), line.end(), ',')) >= kMaxCsvFields)
      return {0, 0};
    const auto row = csvFields(line);
    return {headerShift(csvFields(header), row, selected), row.size()};
  }
  return {0, 0};
}

/// The header's fields of a CSV file (its first line split at commas).
std::vector<std::string> headerFields(const fs::path& file) {
  const std::string header = firstLine(file);
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (true) {
    const auto comma = header.find(',', start);
    fields.push_back(header.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return fields;
}

/// The reading unit the header fields [first, last) name: one angle unit and one length unit at
/// most ("rad+m" when both differ from deg and mm).
std::string unitOfColumns(const fs::path& file, const std::vector<std::string>& fields,
                          std::size_t first, std::size_t last) {
  std::set<std::string> units;
  for (std::size_t i = first; i < last; ++i) {
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
  if (!headerUnit(f)) return f;
  if (!f.empty() && (f.back() == ']' || f.back() == ')')) {
    const auto open = f.find_last_of("[(");
    return trimmedField(f.substr(0, open));
  }
  const auto start = f.find_last_of(" _\t");
  return start == std::string::npos ? f : trimmedField(f.substr(0, start));
}

/// The orientation forms a header may name for a marker, the suffixes of their columns.
struct OrientationColumns {
  const char* form;
  std::array<const char*, 4> suffixes;
  int count;
};
constexpr std::array<OrientationColumns, 3> kOrientationColumns = {
    {{"rotation_vector", {"rx", "ry", "rz", ""}, 3},
     {"rpy", {"roll", "pitch", "yaw", ""}, 3},
     {"quaternion", {"qw", "qx", "qy", "qz"}, 4}}};

/// The field of `base` + one of the separators + `suffix` (or `suffix` alone for the marker ""),
/// case-insensitive in the suffix; -1 when the header has none.
int markerField(const std::vector<std::string>& bases, const std::string& marker,
                const std::string& suffix) {
  auto lower = [](std::string t) {
    for (char& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return t;
  };
  for (std::size_t i = 0; i < bases.size(); ++i) {
    const std::string& b = bases[i];
    if (marker.empty()) {
      if (lower(b) == suffix) return static_cast<int>(i);
      continue;
    }
    if (b.size() != marker.size() + 1 + suffix.size() || !b.starts_with(marker)) continue;
    const char sep = b[marker.size()];
    if ((sep == '_' || sep == '.' || sep == ' ') && lower(b.substr(marker.size() + 1)) == suffix)
      return static_cast<int>(i);
  }
  return -1;
}

/// The markers a header names: every <name> with <name>_x, <name>_y and <name>_z fields (also
/// <name>.x, <name> x; the fields' unit words aside), in the order of their x fields.
std::vector<std::string> headerMarkers(const std::vector<std::string>& bases) {
  std::vector<std::string> markers;
  for (const std::string& b : bases) {
    std::string marker;
    if (b == "x" || b == "X") {
      marker = "";
    } else if (b.size() > 2 && (b.ends_with("_x") || b.ends_with(".x") || b.ends_with(" x") ||
                                b.ends_with("_X") || b.ends_with(".X") || b.ends_with(" X"))) {
      marker = b.substr(0, b.size() - 2);
    } else {
      continue;
    }
    if (markerField(bases, marker, "y") >= 0 && markerField(bases, marker, "z") >= 0)
      markers.push_back(marker);
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
                             "<marker>_z of the measured point"
                           : "the header names several markers (" + listed +
                                 "): select the machine's tip with --marker NAME (several "
                                 "--marker: one reading of each per row)");
    }
    return markers;
  }
  for (const std::string& marker : import.markers) {
    if (std::find(markers.begin(), markers.end(), marker) == markers.end()) {
      throw InputError(file.string(), "line 1",
                       "no marker \"" + marker + "\" (<name>_x, <name>_y, <name>_z) in the header" +
                           (listed.empty() ? std::string() : " (it names " + listed + ")"));
    }
  }
  return import.markers;
}

/// A marker's point (and a pose's orientation) columns appended to `columns`, their units to
/// `entry` ("point_unit", "orientation", "orientation_unit"), the fields marked `used`.
void readMarkerColumns(const fs::path& file, const std::vector<std::string>& fields,
                       const std::vector<std::string>& bases, const std::string& marker,
                       const ReadingsImport& import, bool pose, std::vector<bool>& used,
                       json& entry, json& columns) {
  std::vector<std::string> point_fields;
  for (const char* axis : {"x", "y", "z"}) {
    const int f = markerField(bases, marker, axis);
    used[static_cast<std::size_t>(f)] = true;
    point_fields.push_back(fields[static_cast<std::size_t>(f)]);
    columns.push_back(trimmedField(fields[static_cast<std::size_t>(f)]));
  }
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
  if (pose) {
    std::vector<const OrientationColumns*> found;
    for (const OrientationColumns& o : kOrientationColumns) {
      bool all = true;
      for (int k = 0; k < o.count; ++k) all = all && markerField(bases, marker, o.suffixes[k]) >= 0;
      if (all && (import.orientation.empty() || import.orientation == o.form)) found.push_back(&o);
    }
    if (found.size() != 1) {
      throw InputError(
          file.string(), "line 1",
          found.empty()
              ? "no orientation of marker \"" + marker + "\"" +
                    (import.orientation.empty() ? std::string() : " as " + import.orientation) +
                    ": expected its columns _rx, _ry, _rz (a rotation vector), _roll, _pitch, "
                    "_yaw or _qw, _qx, _qy, _qz"
              : "marker \"" + marker +
                    "\" has several orientations: choose one with --orientation");
    }
    const OrientationColumns& o = *found.front();
    std::vector<std::string> angle_fields;
    for (int k = 0; k < o.count; ++k) {
      const int f = markerField(bases, marker, o.suffixes[static_cast<std::size_t>(k)]);
      used[static_cast<std::size_t>(f)] = true;
      angle_fields.push_back(fields[static_cast<std::size_t>(f)]);
      columns.push_back(trimmedField(fields[static_cast<std::size_t>(f)]));
    }
    entry["orientation"] = o.form;
    if (std::string(o.form) != "quaternion") {
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
  }
}

/// The columns of `file` when its header names at least one of the machine's readings (a file
/// whose columns are named, docs/plan-format.md "Columns by name"); std::nullopt otherwise.
std::optional<NamedColumns> namedColumns(const fs::path& file, const MachineReadings& machine,
                                         const ReadingsImport& import, bool instrument, bool pose) {
  if (machine.names.empty()) return std::nullopt;
  const std::vector<std::string> fields = headerFields(file);
  std::vector<std::string> bases;
  for (const std::string& f : fields) bases.push_back(withoutUnit(f));
  std::vector<int> joint_field;
  bool any = false;
  for (const std::string& name : machine.names) {
    const auto at = std::find(bases.begin(), bases.end(), name);
    joint_field.push_back(at == bases.end() ? -1 : static_cast<int>(at - bases.begin()));
    any = any || at != bases.end();
  }
  if (!any) return std::nullopt;
  NamedColumns out;
  std::vector<bool> used(fields.size(), false);
  std::vector<std::string> joint_fields;
  for (std::size_t j = 0; j < machine.names.size(); ++j) {
    const int f = joint_field[j];
    const bool held = std::any_of(import.holds.begin(), import.holds.end(),
                                  [&](const auto& h) { return h.first == machine.names[j]; });
    if (f >= 0 && held) {
      throw InputError(file.string(), "line 1",
                       "joint \"" + machine.names[j] + "\" is both read (column " +
                           std::to_string(f + 1) + ") and held with --hold");
    }
    if (f < 0 && !held) {
      throw InputError(file.string(), "line 1",
                       "no column for joint \"" + machine.names[j] +
                           "\": the header names other joints of the machine; a joint no file "
                           "reads is held at a value with --hold " +
                           machine.names[j] + "=VALUE");
    }
    if (f >= 0) {
      used[static_cast<std::size_t>(f)] = true;
      joint_fields.push_back(fields[static_cast<std::size_t>(f)]);
    }
  }
  std::string unit = import.unit;
  if (unit.empty()) {
    unit = unitOfNamed(file, joint_fields);
  }
  const auto units = readingUnitsFromName(unit);
  json columns = json::array();
  for (std::size_t j = 0; j < machine.names.size(); ++j) {
    const int f = joint_field[j];
    if (f >= 0) {
      columns.push_back(trimmedField(fields[static_cast<std::size_t>(f)]));
      continue;
    }
    const auto held = std::find_if(import.holds.begin(), import.holds.end(),
                                   [&](const auto& h) { return h.first == machine.names[j]; });
    // --hold is in deg (mm): the entry's value is in the file's unit, as a column would be.
    columns.push_back(machine.kinds[j] == JointKind::Revolute
                          ? held->second * kDegree / units->angle_to_rad
                          : held->second / units->length_to_mm);
  }
  if (!instrument) {
    json entry = {{"unit", unit}, {"columns", columns}};
    out.entries.push_back(entry);
  } else {
    for (const std::string& marker : markersRead(file, bases, import)) {
      json entry = {{"unit", unit}};
      json marker_columns = columns;
      readMarkerColumns(file, fields, bases, marker, import, pose, used, entry, marker_columns);
      entry["columns"] = marker_columns;
      if (import.markers.size() > 1) entry["tip"] = marker;
      out.entries.push_back(entry);
    }
  }
  for (std::size_t f = 0; f < fields.size(); ++f)
    if (!used[f] && !trimmedField(fields[f]).empty())
      out.ignored.push_back(trimmedField(fields[f]));
  std::vector<int> selected;
  for (const int f : joint_field)
    if (f >= 0) selected.push_back(f);
  if (const auto [shift, row] = namedFieldShift(file, selected); shift > 0) {
    out.note = file.string() + ": its header names its rows' last " + std::to_string(row - shift) +
               " fields (the first " + std::to_string(shift) +
               " are unnamed, an export's labels): read so";
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
    const auto held = std::find_if(import.holds.begin(), import.holds.end(), [&](const auto& h) {
      return j < machine.names.size() && h.first == machine.names[j];
    });
    if (held == import.holds.end()) {
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

/// The coordinates an instrument reports per reading: a point's x, y, z; a pose's x, y, z, then
/// its orientation as a rotation vector rx, ry, rz.
constexpr std::size_t kPointColumns = 3;
constexpr std::size_t kPoseColumns = 6;

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
  const int joints = static_cast<int>(machine.kinds.size() - import.holds.size());
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

json stationPlacements(const fs::path& dir, const ReadingsImport& import,
                       const fs::path& plan_folder, const std::string& instrument_id,
                       const MachineReadings& machine, bool pose,
                       std::vector<std::string>& ignored) {
  json placements = json::array();
  for (const auto& [name, files] : stations(dir)) {
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
};

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
      PlacementSource source{folderName(folder), featureFiles(folder, import.unit), {}};
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
    const std::string name = path.stem().string();
    if (!names.insert(name).second)
      throw InputError(input, "",
                       "a second file named " + name +
                           ".csv: placements need names "
                           "of their own; rename one");
    out.push_back({name, {FeatureFile{0, path, import.unit}}, {}});
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

/// Largest revolute range a widened limit may reach, deg: beyond it a reading is taken for one
/// in the wrong unit.
constexpr double kWidestRevoluteDeg = 360.0;

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
    const double widest = degToRad(kWidestRevoluteDeg);
    const bool revolute = kinds[static_cast<std::size_t>(i)] == JointKind::Revolute;
    // A prismatic joint: within a tenth of its range (at least 1 mm) of its limits; a reading in
    // the wrong unit is 1000 times off.
    const double reach = std::max(0.1 * (limits[1] - limits[0]), 1.0);
    const bool widen = revolute ? lo[i] >= -widest && hi[i] <= widest
                                : lo[i] >= limits[0] - reach && hi[i] <= limits[1] + reach;
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
  if (mech.stylusNames().size() > 1) out.tips = mech.stylusNames();
  for (int i = 0; i < mech.jointCount(); ++i) out.kinds.push_back(mech.jointKind(i));
  for (const auto& [name, value] : import.holds) {
    if (std::find(out.names.begin(), out.names.end(), name) == out.names.end()) {
      std::string names;
      for (const std::string& n : out.names) names += (names.empty() ? "" : ", ") + n;
      throw InputError("--hold", name,
                       "not a joint the machine reads" +
                           (names.empty() ? std::string(" (its model names no joints)")
                                          : " (it reads " + names + ")"));
    }
  }
  return out;
}

}  // namespace

ImportedPlan importReadings(const ReadingsImport& import) {
  const bool prior = import.prior_length != 0.0 || import.prior_angle != 0.0;
  if (prior && !(import.prior_length > 0.0 && import.prior_angle > 0.0 &&
                 std::isfinite(import.prior_length) && std::isfinite(import.prior_angle))) {
    throw InputError("--prior", "", "expected LENGTH,ANGLE (mm, deg), each > 0, e.g. 5,0.5");
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
  if (instrument && files_given) {
    throw InputError(inputs.front(), "",
                     "an instrument's readings are read from a folder (one CSV file or sub-folder "
                     "per station): give the folder");
  }
  if (instrument) {
    const auto measures = artifact.find("measures");
    const bool pose = measures != artifact.end() && *measures == "pose";
    placements = stationPlacements(dir, import, plan_folder, artifact_id, readings, pose, ignored);
  }
  const std::vector<std::string>& tips = readings.tips;
  const std::vector<PlacementSource> sources =
      instrument ? std::vector<PlacementSource>{} : placementSources(import);
  for (const auto& given : import.tip_of) {
    if (std::none_of(sources.begin(), sources.end(),
                     [&](const PlacementSource& s) { return s.name == given.first; }))
      throw InputError("--tip-of", given.first + "=" + given.second, "no placement of that name");
  }
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
    }
    placements.push_back(
        {{"name", source.name}, {"artifact", artifact_id}, {"measurements", measurements}});
    // Where the artifact stood (a plane's placement, docs/planes.md): the folder's pose.json,
    // {"center": [...], "direction": [...], "roll": deg}, checked when the plan is read; without
    // one a plane's placement is where its touches put it.
    if (!source.pose.empty()) placements.back()["pose"] = readJsonFile(source.pose.string());
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
