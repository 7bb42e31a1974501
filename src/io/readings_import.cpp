#include "artcal/io/readings_import.hpp"

#include <Eigen/Core>
#include <algorithm>
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
#include "artcal/io/plan_io.hpp"
#include "artcal/io/urdf.hpp"

namespace artcal {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

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

std::string firstLine(const fs::path& file) {
  const std::string text = readInputFile(file.string());
  return text.substr(0, text.find('\n'));
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

/// The unit of a general-layout file from its header.
std::string unitFromHeader(const fs::path& file) {
  const std::vector<std::string> fields = headerFields(file);
  return unitOfColumns(file, fields, 0, fields.size());
}

/// The feature files of one folder, by feature index; empty when it holds none.
std::vector<FeatureFile> featureFiles(const fs::path& folder, const std::string& unit) {
  std::map<int, FeatureFile> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    if (!entry.is_regular_file()) continue;
    const std::string name = entry.path().filename().string();
    FeatureFile file;
    file.path = entry.path();
    if (const auto k = featureIndex(name, "hole_")) {  // MUKCa: rad, no header
      file.feature = *k;
      file.unit = unit.empty() ? "rad" : unit;
    } else if (const auto f = featureIndex(name, "feature_")) {
      file.feature = *f;
      file.unit = unit.empty() ? unitFromHeader(file.path) : unit;
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

// ------------------------------------------------------------------ an instrument's stations

/// The coordinates an instrument reports per reading: a point's x, y, z; a pose's x, y, z, then
/// its orientation as a rotation vector rx, ry, rz.
constexpr std::size_t kPointColumns = 3;
constexpr std::size_t kPoseColumns = 6;

/// The CSV files of a folder, in name order.
std::vector<fs::path> csvFiles(const fs::path& folder) {
  std::vector<fs::path> out;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && entry.path().extension() == ".csv") out.push_back(entry.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// DIR's stations: its sub-folders holding CSV files (a station each, named after the folder, each
/// file one entry), or, without such sub-folders, each CSV file of DIR (named after its stem).
std::vector<std::pair<std::string, std::vector<fs::path>>> stations(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir.string(), "", "is not a folder");
  std::vector<std::pair<std::string, std::vector<fs::path>>> out;
  std::vector<fs::path> folders;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    if (entry.is_directory() && !csvFiles(entry.path()).empty()) folders.push_back(entry.path());
  }
  std::sort(folders.begin(), folders.end());
  for (const fs::path& folder : folders) out.emplace_back(folderName(folder), csvFiles(folder));
  if (out.empty()) {
    for (const fs::path& file : csvFiles(dir))
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

/// A station file's measurement entry: its joints' unit and its point's (and a pose's
/// orientation's), from --unit, --point-unit and --orientation-unit where given, otherwise from
/// its header (the last 3 columns are the point's: `q1_deg, ..., x_m, y_m, z_m`; of a pose, the
/// last 6: `..., x_m, y_m, z_m, rx_rad, ry_rad, rz_rad`); a point without a stated unit is in mm,
/// an orientation in deg.
json stationEntry(const fs::path& file, const ReadingsImport& import, const fs::path& plan_folder,
                  int joints, bool pose) {
  std::string unit = import.unit, point_unit = import.point_unit,
              orientation_unit = import.orientation_unit;
  const std::vector<std::string> fields = headerFields(file);
  checkStationWidth(file, fields.size(), joints, pose);
  const std::size_t measured = pose ? kPoseColumns : kPointColumns;
  const bool units_in_header = std::all_of(
      fields.begin(), fields.end(), [](const std::string& f) { return headerUnit(f).has_value(); });
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
  if (pose && orientation_unit.empty() && header) {
    orientation_unit = unitOfThree(fields, first + kPointColumns, {"deg", "rad"});
    if (orientation_unit.empty()) {
      throw InputError(file.string(), "line 1",
                       "the last 3 columns are the measured orientation (a rotation vector): one "
                       "angle unit (rx_deg, ry_deg, rz_deg or rx_rad, ry_rad, rz_rad)");
    }
  }
  const fs::path relative = fs::absolute(file).lexically_normal().lexically_relative(plan_folder);
  json entry = {{"csv", relative.generic_string()},
                {"unit", unit},
                {"point_unit", point_unit.empty() ? "mm" : point_unit}};
  if (pose) entry["orientation_unit"] = orientation_unit.empty() ? "deg" : orientation_unit;
  return entry;
}

json stationPlacements(const fs::path& dir, const ReadingsImport& import,
                       const fs::path& plan_folder, const std::string& instrument_id, int joints,
                       bool pose) {
  json placements = json::array();
  for (const auto& [name, files] : stations(dir)) {
    json measurements = json::array();
    for (const fs::path& file : files)
      measurements.push_back(stationEntry(file, import, plan_folder, joints, pose));
    placements.push_back(
        {{"name", name}, {"artifact", instrument_id}, {"measurements", measurements}});
  }
  return placements;
}

json machineBlock(const ReadingsImport& import) {
  if (!import.machine_file.empty()) {
    json machine = readJsonFile(import.machine_file);
    if (machine.is_object() && machine.contains("machine")) machine = machine.at("machine");
    if (!machine.is_object())
      throw InputError(import.machine_file, "", "expected a machine block (an object)");
    if (!import.keep_calibrate) machine["calibrate"] = "identifiable";
    return machine;
  }
  json machine = importUrdf(import.urdf, import.base, import.tip);
  machine["calibrate"] = "identifiable";
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
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    if (entry.is_directory() && !featureFiles(entry.path(), unit).empty())
      out.push_back(entry.path());
  }
  std::sort(out.begin(), out.end());
  if (out.empty() && !featureFiles(dir, unit).empty()) out.push_back(dir);
  if (out.empty()) {
    throw InputError(dir.string(), "",
                     "no readings: expected sub-folders (one per placement) holding hole_<k>.csv "
                     "or feature_<k>.csv files");
  }
  return out;
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
      // kept.
      std::vector<JointKind> columns = kinds;
      if (entry.contains("point_unit")) {
        const std::size_t measured =
            entry.contains("orientation_unit") ? kPoseColumns : kPointColumns;
        columns.resize(kinds.size() + measured, JointKind::Prismatic);
      }
      for (const Eigen::VectorXd& row : readJointCsv(file, columns, *units)) {
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
    if (kinds[static_cast<std::size_t>(i)] != JointKind::Revolute || lo[i] < -widest ||
        hi[i] > widest) {
      continue;  // refused when the plan is parsed, naming the file and row
    }
    const double old_lo = radToDeg(limits[0]), old_hi = radToDeg(limits[1]);
    limits = {std::min(limits[0], lo[i]), std::max(limits[1], hi[i])};
    document["machine"]["joint_limits"][static_cast<std::size_t>(i)] = {radToDeg(limits[0]),
                                                                        radToDeg(limits[1])};
    char text[256];
    std::snprintf(text, sizeof text,
                  "joint %d: readings reach [%.3f, %.3f] deg, beyond its limits [%.3f, %.3f] "
                  "deg: joint_limits widened to the readings",
                  i + 1, radToDeg(lo[i]), radToDeg(hi[i]), old_lo, old_hi);
    warnings.emplace_back(text);
  }
  return warnings;
}

/// The joint readings per row of the machine block `machine` (its driving joints), read beside
/// the plan's `artifacts`.
int jointCountOf(const json& machine, const json& artifacts, const std::string& source) {
  const json document = {{"format", "artcal-plan/1"},
                         {"machine", machine},
                         {"noise", {{"probe", 0.1}, {"encoder", 0.0}}},
                         {"artifacts", artifacts}};
  const Plan plan = parsePlan(document, source, /*require_placements=*/false, false);
  return plan.machine.mechanism->jointCount();
}

}  // namespace

ImportedPlan importReadings(const ReadingsImport& import) {
  if (!import.unit.empty() && !readingUnitsFromName(import.unit)) {
    throw InputError(
        import.unit, "",
        "unknown unit (expected deg, rad, mm, m, or an angle and a length unit as rad+m)");
  }
  const fs::path dir = fs::path(import.folder).lexically_normal();
  const bool to_stdout = import.output.empty() || import.output == kStandardOutput;
  const fs::path output_folder = to_stdout ? fs::path() : fs::path(import.output).parent_path();
  const fs::path plan_folder = fs::absolute(output_folder.empty() ? fs::path(".") : output_folder);
  const auto [artifacts, artifact_id] = artifactBlock(import);
  const json& artifact = artifacts.at(artifact_id);
  const bool instrument = artifact.is_object() && artifact.value("type", "") == "instrument";
  const std::string source = to_stdout ? std::string("import-readings") : import.output;
  const json machine = machineBlock(import);
  json placements = json::array();
  if (instrument) {
    const auto measures = artifact.find("measures");
    const bool pose = measures != artifact.end() && *measures == "pose";
    placements = stationPlacements(dir, import, plan_folder, artifact_id,
                                   jointCountOf(machine, artifacts, source), pose);
  }
  for (const fs::path& folder :
       instrument ? std::vector<fs::path>{} : placementFolders(dir, import.unit)) {
    json measurements = json::array();
    for (const FeatureFile& file : featureFiles(folder, import.unit)) {
      if (import.ball_bar && file.feature > 1) {
        throw InputError(file.path.string(), "",
                         "feature " + std::to_string(file.feature) +
                             " of a ball bar, whose features are 0 and 1: rename the file or "
                             "move it out of the folder");
      }
      const fs::path relative =
          fs::absolute(file.path).lexically_normal().lexically_relative(plan_folder);
      measurements.push_back(
          {{"feature", file.feature}, {"csv", relative.generic_string()}, {"unit", file.unit}});
    }
    const std::string name = folderName(folder);
    placements.push_back(
        {{"name", name}, {"artifact", artifact_id}, {"measurements", measurements}});
    // Where the artifact stood (a plane's placement, docs/planes.md): the folder's pose.json,
    // {"center": [...], "direction": [...], "roll": deg}, checked when the plan is read.
    if (const fs::path pose = folder / "pose.json"; fs::exists(pose))
      placements.back()["pose"] = readJsonFile(pose.string());
  }
  const std::string plan_name = folderName(dir);
  ImportedPlan out;
  out.plan = {{"format", "artcal-plan/1"},
              {"name", plan_name},
              {"description", "readings of " + dir.generic_string() + " (artcal import-readings)"},
              {"machine", machine},
              {"noise", {{"probe", import.probe}, {"encoder", import.encoder}}},
              {"artifacts", artifacts},
              {"placements", placements}};
  out.source = source;
  if (!out.plan["machine"].contains("joint_limits")) return out;
  if (!import.keep_limits) out.warnings = widenJointLimits(out.plan, out.source, plan_folder);
  return out;
}

}  // namespace artcal
