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

/// The unit of a general-layout file from its header: one angle unit and one length unit at
/// most, and not rad and m together (a measurement entry states one "unit").
std::string unitFromHeader(const fs::path& file) {
  const std::string header = firstLine(file);
  std::set<std::string> units;
  std::size_t start = 0;
  while (true) {
    const auto comma = header.find(',', start);
    const auto unit = headerUnit(header.substr(start, comma - start));
    if (!unit) {
      throw InputError(file.string(), "line 1",
                       "expected a header naming each column's unit (q1_deg, q2_rad, q3_mm, ...), "
                       "or state the unit with --unit");
    }
    units.insert(*unit);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  const bool rad = units.count("rad") > 0, m = units.count("m") > 0;
  if ((rad && units.count("deg")) || (m && units.count("mm")) || (rad && m)) {
    throw InputError(file.string(), "line 1",
                     "columns in mixed units: one file takes deg or rad for its angles and mm or "
                     "m for its lengths, not rad and m together");
  }
  return rad ? "rad" : m ? "m" : "deg";
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
      for (const Eigen::VectorXd& q : readJointCsv(file, kinds, *units)) {
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

}  // namespace

ImportedPlan importReadings(const ReadingsImport& import) {
  if (!import.unit.empty() && !readingUnitsFromName(import.unit)) {
    throw InputError(import.unit, "", "unknown unit (expected deg, rad, mm or m)");
  }
  const fs::path dir = fs::path(import.folder).lexically_normal();
  const bool to_stdout = import.output.empty() || import.output == kStandardOutput;
  const fs::path output_folder = to_stdout ? fs::path() : fs::path(import.output).parent_path();
  const fs::path plan_folder = fs::absolute(output_folder.empty() ? fs::path(".") : output_folder);
  const auto [artifacts, artifact_id] = artifactBlock(import);
  json placements = json::array();
  for (const fs::path& folder : placementFolders(dir, import.unit)) {
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
  }
  const std::string plan_name = folderName(dir);
  ImportedPlan out;
  out.plan = {{"format", "artcal-plan/1"},
              {"name", plan_name},
              {"description", "readings of " + dir.generic_string() + " (artcal import-readings)"},
              {"machine", machineBlock(import)},
              {"noise", {{"probe", import.probe}, {"encoder", import.encoder}}},
              {"artifacts", artifacts},
              {"placements", placements}};
  out.source = to_stdout ? std::string("import-readings") : import.output;
  if (!out.plan["machine"].contains("joint_limits")) return out;
  if (!import.keep_limits) out.warnings = widenJointLimits(out.plan, out.source, plan_folder);
  return out;
}

}  // namespace artcal
