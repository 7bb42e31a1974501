#include "artcal/io/plan_io.hpp"

#include <fcntl.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <limits>
#include <numbers>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <new>
#include <set>
#include <sstream>

#include "artcal/core/linear_algebra.hpp"
#include "artcal/estimation/identifiability.hpp"
#include "artcal/estimation/plane_rows.hpp"
#include "artcal/io/acceptance_spec.hpp"
#include "artcal/io/artifact_registry.hpp"
#include "artcal/io/compliance_block.hpp"
#include "artcal/io/csv_readings.hpp"
#include "artcal/io/instrument_codec.hpp"
#include "artcal/io/json_node.hpp"
#include "artcal/io/model_registry.hpp"
#include "artcal/io/plausibility.hpp"

namespace artcal {

namespace {

using nlohmann::json;

constexpr std::size_t kMaxPlacements = 1'000'000;
constexpr std::size_t kMaxMeasurements = 10'000;
// Workspace configurations evaluated: 3 to 10 KB each while the tip uncertainty is prepared
// (planar2r 3.2 GB at 10^6, the hexapod 0.98 GB at 10^5): 10^7 ran out of memory, 10^6 holds (issue
// 19).
constexpr long kMaxWorkspace = 1'000'000;
constexpr long kMaxPosturesPerRequest = 100;

// machine.calibrate: [names], "identifiable" (every parameter in the model's order) or
// {"identifiable": [names in preferred order]} (docs/plan-format.md; docs/models.md section 1). The
// identifiable forms list candidates that resolveCalibratedSet decides from the readings.
void parseCalibrateNames(const Node& names, const Mechanism& mech, Machine& machine) {
  const std::size_t n = names.arraySize(1, mech.parameters().size());
  std::set<int> seen;
  for (std::size_t i = 0; i < n; ++i) {
    const Node entry = names[i];
    const std::string pname = entry.string();
    const int index = mech.parameterIndex(pname);
    if (index < 0) entry.fail("unknown parameter \"" + pname + "\" of " + mech.modelName());
    if (!seen.insert(index).second) entry.fail("parameter \"" + pname + "\" named twice");
    machine.calibrated.push_back(index);
  }
}

void parseCalibrate(const Node& calibrate, const Mechanism& mech, Machine& machine) {
  if (calibrate.value().is_string()) {
    if (calibrate.string() != "identifiable") {
      calibrate.fail(
          "expected a list of parameter names, \"identifiable\" or {\"identifiable\": "
          "[names]}, got \"" +
          calibrate.string() + "\"");
    }
    machine.calibrate_identifiable = true;
    for (int i = 0; i < mech.parameterCount(); ++i) machine.calibrated.push_back(i);
  } else if (calibrate.value().is_object()) {
    if (calibrate.object().size() != 1 || !calibrate.has("identifiable")) {
      calibrate.fail("expected {\"identifiable\": [parameter names in preferred order]}");
    }
    machine.calibrate_identifiable = true;
    parseCalibrateNames(calibrate.at("identifiable"), mech, machine);
    // The listed names come first; the model's own order follows for the rest (docs/models.md
    // section 1): a preference, not a restriction.
    std::vector<bool> listed(static_cast<std::size_t>(mech.parameterCount()), false);
    for (int index : machine.calibrated) listed[static_cast<std::size_t>(index)] = true;
    for (int i = 0; i < mech.parameterCount(); ++i) {
      if (!listed[static_cast<std::size_t>(i)]) machine.calibrated.push_back(i);
    }
  } else {
    parseCalibrateNames(calibrate, mech, machine);
  }
}

// machine.prior (docs/plan-format.md): {"default": {"length": mm, "angle": deg}, "NAME": value
// in the parameter's file unit, ...}: the standard deviation of each nominal value, > 0.
Eigen::VectorXd parsePrior(const Node& prior, const Mechanism& mech) {
  Eigen::VectorXd sigma = Eigen::VectorXd::Zero(mech.parameterCount());
  if (const auto defaults = prior.find("default")) {
    std::vector<std::string> ignored;
    defaults->warnUnknown({"length", "angle"}, ignored);
    const auto length = defaults->find("length");
    const auto angle = defaults->find("angle");
    for (int i = 0; i < mech.parameterCount(); ++i) {
      const bool is_angle = mech.parameters()[static_cast<std::size_t>(i)].quantity.isAngle();
      if (is_angle && angle) sigma[i] = degToRad(angle->standardDeviation(false));
      if (!is_angle && length) sigma[i] = length->standardDeviation(false);
    }
  }
  for (const auto& [name, value] : prior.object().items()) {
    if (name == "default" || name.starts_with("x-")) continue;
    const int index = mech.parameterIndex(name);
    if (index < 0) prior.at(name).fail("unknown parameter \"" + name + "\" of " + mech.modelName());
    const Quantity q = mech.parameters()[static_cast<std::size_t>(index)].quantity;
    sigma[index] = fromFileUnit(q, prior.at(name).standardDeviation(false));
  }
  return sigma;
}

Machine parseMachine(const Node& node, std::vector<std::string>& warnings) {
  node.object();
  Machine machine;
  const Node model = node.at("model");
  const std::string name = model.string();
  const ModelCodec* codec = findModelCodec(name);
  if (!codec) model.fail("unknown model \"" + name + "\" (expected " + modelNameList() + ")");
  MachineBlock block = readOwnMembers(*codec, node, warnings);
  machine.mechanism = std::move(block.mechanism);
  machine.nominal = std::move(block.nominal);
  const std::vector<std::array<double, 2>>& default_limits = block.default_limits;
  const Mechanism& mech = *machine.mechanism;
  if (const auto calibrate = node.find("calibrate")) {
    parseCalibrate(*calibrate, mech, machine);
  } else {
    for (int i = 0; i < mech.parameterCount(); ++i) machine.calibrated.push_back(i);
  }
  if (const auto prior = node.find("prior")) machine.prior_sigma = parsePrior(*prior, mech);
  const int joints = mech.jointCount();
  if (const auto limits = node.find("joint_limits")) {
    // One pair per joint of the machine as described: a count that differs is as likely the
    // machine's description (a joint left out of "joints") as the limits.
    if (limits->value().is_array() && limits->value().size() != static_cast<std::size_t>(joints))
      limits->fail(std::to_string(limits->value().size()) +
                   (limits->value().size() == 1 ? " entry" : " entries") +
                   ", but the machine described has " + std::to_string(joints) +
                   " joints (model \"" + mech.modelName() +
                   "\"): one [lower, upper] per joint; check the machine's joints as well as " +
                   "these limits");
    limits->arraySize(static_cast<std::size_t>(joints), static_cast<std::size_t>(joints));
    for (int i = 0; i < joints; ++i) {
      const Node pair = (*limits)[static_cast<std::size_t>(i)];
      const Eigen::VectorXd lh = pair.numbers(2);
      if (!(lh[0] < lh[1])) pair.fail("expected [lower, upper] with lower < upper");
      const Quantity q = jointQuantity(mech.jointKind(i));
      machine.joint_limits.push_back({fromFileUnit(q, lh[0]), fromFileUnit(q, lh[1])});
    }
    machine.limits_stated = true;
  } else if (!default_limits.empty()) {
    machine.joint_limits = default_limits;
    machine.limits_stated = true;
  } else {
    for (int i = 0; i < joints; ++i) {
      if (mech.jointKind(i) == JointKind::Prismatic) {
        node.fail("joint_limits are required when a joint is prismatic");
      }
      machine.joint_limits.push_back({-std::numbers::pi, std::numbers::pi});
    }
  }
  return machine;
}

// noise.probe: a standard deviation (mm), or "estimate" / {"estimate": START} for the calibrator
// to estimate from the fit (calibration/calibrate_readings.hpp); START (default
// kDefaultProbeNoiseGuess) is what evaluate and the first iteration use.
double parseProbeNoise(const Node& probe, bool& estimate) {
  estimate = false;
  if (probe.value().is_string()) {
    if (probe.string() != "estimate")
      probe.fail("expected a number, got a string: a standard deviation in mm, or \"estimate\"");
    estimate = true;
    return kDefaultProbeNoiseGuess;
  }
  if (probe.value().is_object()) {
    if (probe.object().size() != 1 || !probe.has("estimate"))
      probe.fail("expected {\"estimate\": starting standard deviation in mm}");
    estimate = true;
    return probe.at("estimate").standardDeviation(false);
  }
  return probe.standardDeviation(false);
}

Noise parseNoise(const Node& node, const Machine& machine, std::vector<std::string>& warnings) {
  node.object();
  node.warnUnknown({"probe", "encoder"}, warnings);
  Noise noise;
  noise.probe = parseProbeNoise(node.at("probe"), noise.estimate_probe);
  const Node encoder = node.at("encoder");
  const int joints = machine.jointCount();
  noise.encoder.resize(joints);
  if (encoder.value().is_array()) {
    const Eigen::VectorXd values = encoder.numbers(static_cast<std::size_t>(joints));
    for (int i = 0; i < joints; ++i) {
      const double v = encoder[static_cast<std::size_t>(i)].standardDeviation(true);
      noise.encoder[i] = fromFileUnit(jointQuantity(machine.mechanism->jointKind(i)), v);
      (void)values;
    }
  } else {
    const double v = encoder.standardDeviation(true);
    for (int i = 0; i < joints; ++i) {
      noise.encoder[i] = fromFileUnit(jointQuantity(machine.mechanism->jointKind(i)), v);
    }
  }
  return noise;
}

}  // namespace

Pose parsePose(const Node& node, int dimension, std::vector<std::string>& warnings,
               bool centre_only) {
  node.object();
  Pose pose;
  pose.center = node.at("center").numbers(static_cast<std::size_t>(dimension));
  if (dimension == 2) {
    node.warnUnknown({"center", "angle"}, warnings);
    pose.angle = degToRad(node.find("angle") ? node.at("angle").number() : 0.0);
  } else {
    node.warnUnknown({"center", "direction", "roll"}, warnings);
    // A sphere's or a table ball's placement is its centre: no direction to state.
    if (centre_only && !node.has("direction")) return pose;
    const Node direction = node.at("direction");
    pose.direction = direction.numbers(3);
    if (pose.direction.norm() <= 0.0) direction.fail("direction must not be zero");
    pose.direction.normalize();
    pose.roll = degToRad(node.find("roll") ? node.at("roll").number() : 0.0);
  }
  return pose;
}

Eigen::VectorXd jointsFromFile(const Mechanism& mech, const Eigen::VectorXd& values) {
  Eigen::VectorXd q(values.size());
  for (int i = 0; i < values.size(); ++i)
    q[i] = fromFileUnit(jointQuantity(mech.jointKind(i)), values[i]);
  return q;
}

namespace {

// A reading outside the plan's joint_limits is a typo, other units (radians, metres) or the wrong
// machine: the machine never reported it (docs/hardening.md). Only limits the plan states are
// enforced: the default revolute range wraps, and a reading of -200 deg is one of 160 deg.
// Compared in internal units, with 1e-9 of the range as slack for a reading written at a limit.
// The first joint outside its limits and what to say about it; std::nullopt when all are inside.
std::optional<std::pair<int, std::string>> jointLimitViolation(const Machine& machine,
                                                               const Eigen::VectorXd& q) {
  const Mechanism& mech = *machine.mechanism;
  for (int i = 0; i < q.size(); ++i) {
    const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
    const double slack = 1e-9 * (hi - lo);
    if (q[i] >= lo - slack && q[i] <= hi + slack) continue;
    const Quantity unit = jointQuantity(mech.jointKind(i));
    auto file = [&](double v) {
      char text[32];
      std::snprintf(text, sizeof text, "%.10g", toFileUnit(unit, v));
      return std::string(text);
    };
    const std::string u = " " + std::string(unitName(unit));
    return std::pair{i,
                     "reading " + file(q[i]) + u + " of joint " + std::to_string(i + 1) +
                         " is outside its joint_limits [" + file(lo) + ", " + file(hi) + "]" + u +
                         ": check the reading, its units (degrees, mm) and machine.joint_limits"};
  }
  return std::nullopt;
}

void checkWithinJointLimits(const Node& joints, const Machine& machine, const Eigen::VectorXd& q) {
  if (const auto violation = jointLimitViolation(machine, q))
    joints[static_cast<std::size_t>(violation->first)].fail(violation->second);
}

/// The ISO 9283 block's "seed_posture" (deg, mm per joint), within the limits the plan states.
void readSeedPosture(const Node& acceptance, const Machine& machine, AcceptanceSpec& spec) {
  const auto seed = acceptance.find("seed_posture");
  if (!seed || spec.test != "iso9283") return;
  const Mechanism& mech = *machine.mechanism;
  spec.seed_posture =
      jointsFromFile(mech, seed->finiteNumbers(static_cast<std::size_t>(mech.jointCount())));
  if (machine.limits_stated) checkWithinJointLimits(*seed, machine, *spec.seed_posture);
}

/// The "exclude_rows" of a CSV measurement entry: data rows (from 1) a person has judged gross
/// errors (a ball not seated, a socket that moved), each in 1..rows and named once.
std::set<long> excludedRows(const Node& entry, std::size_t rows) {
  std::set<long> out;
  const auto exclude = entry.find("exclude_rows");
  if (!exclude) return out;
  const std::size_t n = exclude->arraySize(0, rows);
  for (std::size_t i = 0; i < n; ++i) {
    const long row = (*exclude)[i].integer(1, static_cast<long>(rows));
    if (!out.insert(row).second)
      (*exclude)[i].fail("row " + std::to_string(row) + " is excluded twice");
  }
  if (out.size() == rows) exclude->fail("every row is excluded: leave the measurement out");
  return out;
}

/// Most readings a plan takes from CSV files in all (a file named by several placements counts
/// each time): memory stays bounded by the input's size, ~150 bytes a reading.
constexpr std::size_t kMaxPlanCsvReadings = 2'000'000;

/// The CSV files a plan names, each read and parsed once however many placements name it.
struct CsvFiles {
  struct Parsed {
    std::vector<Eigen::VectorXd> rows;
    std::vector<long> lines;  ///< each row's line in the file
  };
  std::map<std::pair<std::string, std::pair<double, double>>, Parsed> files;
  std::size_t readings = 0;  ///< taken from them by the plan's placements
};

/// The file a {"csv": ...} entry names, as written (relative to the plan file, docs/models.md
/// section 7).
std::filesystem::path csvRelativePath(const Node& entry) {
  const Node csv = entry.at("csv");
  const std::filesystem::path relative(csv.string());
  if (relative.empty()) csv.fail("expected a file name");
  return relative;
}

/// The path of the file a {"csv": ...} entry names.
std::string csvFileOf(const Node& entry, const Plan& plan) {
  const std::filesystem::path relative = csvRelativePath(entry);
  const std::filesystem::path path =
      relative.is_absolute() ? relative
                             : std::filesystem::path(plan.source).parent_path() / relative;
  return path.lexically_normal().string();
}

/// The rows of the CSV file a {"feature", "csv", "unit"} entry names, each file read once per
/// unit whatever the number of entries naming it.
const CsvFiles::Parsed& csvRowsOf(const Node& entry, const Plan& plan, CsvFiles& files) {
  const std::string file = csvFileOf(entry, plan);
  ReadingUnits units;
  if (const auto unit = entry.find("unit")) {
    const auto named = readingUnitsFromName(unit->string());
    if (!named)
      unit->fail("unknown unit \"" + unit->string() +
                 "\" (expected deg, rad, mm, m, or an angle and a length unit as rad+m)");
    units = *named;
  }
  const Mechanism& mech = *plan.machine.mechanism;
  std::vector<JointKind> kinds;
  for (int i = 0; i < mech.jointCount(); ++i) kinds.push_back(mech.jointKind(i));
  // Columns selected by name (csv_readings.hpp): part of what the file's rows are.
  std::optional<std::vector<CsvColumn>> columns;
  std::string selection;
  if (const auto given = entry.find("columns")) {
    columns = parseCsvColumns(*given, kinds.size());
    selection = "\n" + given->value().dump();
  }
  const auto key =
      std::make_pair(file + selection, std::make_pair(units.angle_to_rad, units.length_to_mm));
  auto cached = files.files.find(key);
  try {
    if (cached == files.files.end()) {
      CsvFiles::Parsed parsed;
      parsed.rows = readJointCsv(file, kinds, units, &parsed.lines, columns ? &*columns : nullptr);
      cached = files.files.emplace(key, std::move(parsed)).first;
    }
  } catch (const std::bad_alloc&) {
    throw InputError(file, "", "not enough memory for its readings");
  }
  return cached->second;
}

/// The bound on the CSV readings of the whole plan, checked before any reading is taken: every
/// {"csv"} entry of an artifact placement counts its file's rows (the file is read once). Entries
/// that are not well formed are left to the placement's own parsing, which names them.
void checkCsvReadingsInAll(const Node& placements, const Plan& plan, CsvFiles& files) {
  const nlohmann::json& all = placements.value();
  if (!all.is_array()) return;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const nlohmann::json& placement = all[i];
    if (!placement.is_object() || !placement.contains("measurements") ||
        !placement["measurements"].is_array() || !placement.contains("artifact") ||
        !placement["artifact"].is_string())
      continue;
    const int artifact = plan.artifactIndex(placement["artifact"].get<std::string>());
    if (artifact < 0 ||
        plan.artifacts[static_cast<std::size_t>(artifact)].kind().readings_are_features)
      continue;
    const Node measurements = placements[i].at("measurements");
    for (std::size_t j = 0; j < placement["measurements"].size(); ++j) {
      const nlohmann::json& entry = placement["measurements"][j];
      if (!entry.is_object() || !entry.contains("csv")) continue;
      const Node node = measurements[j];
      files.readings += csvRowsOf(node, plan, files).rows.size();
      if (files.readings > kMaxPlanCsvReadings) {
        node.at("csv").fail("the plan takes more than " + std::to_string(kMaxPlanCsvReadings) +
                            " readings from CSV files in all (a file named by several placements "
                            "counts each time)");
      }
    }
  }
}

/// The lines of the rows a CSV entry's "rows": {"column", "value"} selects (a probing log with a
/// sphere column: one placement per sphere, docs/plan-format.md); std::nullopt without "rows".
std::optional<std::set<long>> selectedLines(const Node& entry, const std::string& file) {
  const auto rows = entry.find("rows");
  if (!rows) return std::nullopt;
  std::vector<std::string> warnings;
  rows->warnUnknown({"column", "value"}, warnings);
  const std::string column = rows->at("column").string();
  const std::string value = rows->at("value").string();
  std::set<long> out;
  for (const auto& [line, field] : readCsvColumn(file, column))
    if (field == value) out.insert(line);
  if (out.empty())
    rows->at("value").fail("no row of " + file + " has \"" + value + "\" in column \"" + column +
                           "\"");
  return out;
}

/// A measurement entry {"feature", "csv", "unit", "exclude_rows"}: one measurement per row of
/// the CSV file, which is relative to the plan file (docs/models.md section 7), but the rows
/// excluded.
void appendCsvMeasurements(const Node& entry, const Plan& plan, const Artifact& artifact,
                           CsvFiles& files, bool explicit_limits, int entry_index,
                           std::vector<Measurement>& out, std::vector<std::string>& warnings) {
  entry.warnUnknown({"feature", "csv", "unit", "columns", "exclude_rows", "tip", "rows", "payload"},
                    warnings);
  const int feature = static_cast<int>(entry.at("feature").integer(0, artifact.featureCount() - 1));
  const int stylus = readStylus(entry, *plan.machine.mechanism);
  const Node csv = entry.at("csv");
  const std::filesystem::path relative = csvRelativePath(entry);
  const CsvFiles::Parsed& parsed = csvRowsOf(entry, plan, files);
  const std::vector<Eigen::VectorXd>& rows = parsed.rows;
  const std::vector<long>& lines = parsed.lines;
  const std::string file = csvFileOf(entry, plan);
  const Mechanism& mech = *plan.machine.mechanism;
  const std::set<long> excluded = excludedRows(entry, rows.size());
  const std::optional<std::set<long>> selected = selectedLines(entry, file);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const long row = static_cast<long>(r) + 1;
    if (excluded.count(row) || (selected && !selected->count(lines[r]))) continue;
    // A fault of a row names the file and its line and row, like the CSV reader's own errors.
    const std::string where =
        "line " + std::to_string(lines[r]) + " (row " + std::to_string(row) + ")";
    if (explicit_limits) {
      if (const auto violation = jointLimitViolation(plan.machine, rows[r]))
        throw InputError(file, where, violation->second);
    }
    Eigen::VectorXd x;
    const ForwardStatus status = mech.forwardStylus(stylus, plan.machine.nominal, rows[r], x);
    if (status != ForwardStatus::Ok) throw InputError(file, where, forwardStatusName(status));
    if (out.size() >= kMaxMeasurements)
      csv.fail("more than " + std::to_string(kMaxMeasurements) + " readings in one placement");
    Measurement measurement;
    measurement.feature = feature;
    measurement.joints = rows[r];
    measurement.csv = relative.string();
    measurement.csv_row = static_cast<int>(row);
    measurement.entry = entry_index;
    measurement.stylus = stylus;
    out.push_back(std::move(measurement));
  }
}

}  // namespace

int readStylus(const Node& entry, const Mechanism& mech) {
  const auto tip = entry.find("tip");
  if (!tip) {
    const auto stylus = entry.find("stylus");
    return stylus ? static_cast<int>(stylus->integer(0, mech.stylusCount() - 1)) : 0;
  }
  if (entry.has("stylus")) entry.at("stylus").fail("give \"tip\" or \"stylus\", not both");
  const std::vector<std::string> names = mech.stylusNames();
  const std::string name = tip->string();
  std::string known;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return static_cast<int>(i);
    known += (i ? ", \"" : "\"") + names[i] + "\"";
  }
  tip->fail(names.empty() ? "the machine names no tips (its \"tips\", docs/urdf.md)"
                          : "no tip named \"" + name + "\" (the machine's tips: " + known + ")");
}

namespace {

/// A measurement entry {"feature": k, "postures": N}: N readings of feature k to be planned from
/// the placement's pose by `artcal plan --complete` (docs/plan-format.md); a plan to be run
/// needs them planned first.
PostureRequest parsePostureRequest(const Node& entry, const Artifact& artifact,
                                   const Placement& placement, const Mechanism& mech,
                                   bool require_measurements, std::vector<std::string>& warnings) {
  entry.warnUnknown({"feature", "postures", "tip"}, warnings);
  PostureRequest request;
  if (entry.has("tip")) request.stylus = readStylus(entry, mech);
  request.feature = static_cast<int>(entry.at("feature").integer(0, artifact.featureCount() - 1));
  request.postures = static_cast<int>(entry.at("postures").integer(1, kMaxPosturesPerRequest));
  request.pointer = entry.pointer();
  if (!placement.pose) entry.fail("\"postures\" needs the placement's pose to plan readings from");
  if (require_measurements) {
    entry.fail("readings to be planned: run `artcal plan --complete PLAN -o OUT` to write them");
  }
  return request;
}

/// An instrument placement's readings (instrument_codec.hpp): each reading's joints parsed and
/// checked as any other's; the station then checked.
void parseStation(const Node& node, const Node& measurements, Plan& plan, Placement& placement,
                  std::size_t index, bool explicit_limits, std::vector<std::string>& warnings) {
  const Machine& machine = plan.machine;
  const Mechanism& mech = *machine.mechanism;
  auto joints_from_node = [&](const Node& joints) {
    const Eigen::VectorXd q =
        jointsFromFile(mech, joints.finiteNumbers(static_cast<std::size_t>(mech.jointCount())));
    if (explicit_limits) checkWithinJointLimits(joints, machine, q);
    Eigen::VectorXd x;
    const ForwardStatus status = mech.forwardStylus(0, machine.nominal, q, x);
    if (status != ForwardStatus::Ok) joints.fail(forwardStatusName(status));
    return q;
  };
  auto check_csv_joints = [&](const Eigen::VectorXd& q, const std::string& file,
                              const std::string& where) {
    if (explicit_limits) {
      if (const auto violation = jointLimitViolation(machine, q))
        throw InputError(file, where, violation->second);
    }
    Eigen::VectorXd x;
    const ForwardStatus status = mech.forwardStylus(0, machine.nominal, q, x);
    if (status != ForwardStatus::Ok) throw InputError(file, where, forwardStatusName(status));
  };
  Artifact& instrument = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  parseStationReadings(measurements, plan.source, machine, instrument, placement, joints_from_node,
                       check_csv_joints, warnings);
  const std::string label = placement.name.empty() ? std::to_string(index) : placement.name;
  checkStation(node, machine, placement, label);
}

// docs/compliance.md section 1: each reading's payload, its entry's "payload" or else its
// placement's (a CSV entry's for all its rows); only a machine with compliance takes one.
static void applyPayloads(const Node& placement_node, const Node& measurements,
                          const Machine& machine, Placement& placement,
                          std::vector<std::string>& warnings) {
  const auto read = [&](const Node& owner) -> std::optional<Payload> {
    const auto payload = owner.find("payload");
    if (!payload) return std::nullopt;
    if (!machine.mechanism->jointCompliance()) {
      payload->fail(
          "a payload needs a machine with a compliance block (docs/compliance.md): add "
          "\"compliance\" to the machine or remove the payload");
    }
    return readMassPoint(*payload, warnings);
  };
  const Payload common = read(placement_node).value_or(Payload{});
  std::map<int, std::optional<Payload>> own;
  for (Measurement& m : placement.measurements) {
    auto found = own.find(m.entry);
    if (found == own.end())
      found = own.emplace(m.entry, read(measurements[static_cast<std::size_t>(m.entry)])).first;
    m.payload = found->second.value_or(common);
  }
}

// A plane placement without a "pose": where its touches put the plane with the nominal machine
// (docs/planes.md); refused, naming the placement, when they fix none.
Pose planePoseOfTouches(const Node& node, const Plan& plan, const Placement& placement) {
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  const std::string where = node.pointer() + "/pose";
  if (!placement.posture_requests.empty())
    throw InputError(node.source(), where, "missing: postures to plan need where the plane stands");
  if (auto pose = planePoseFromTouches(artifact, plan.machine, plan.machine.nominal,
                                       placement.measurements))
    return *pose;
  if (artifact.plane.shape == PlaneShape::TableBall) {
    throw InputError(node.source(), where,
                     "missing, and the readings give none (4 or more spindle-ball points, in the "
                     "workpiece frame, not on one circle): state where the table ball is, "
                     "{\"center\": [x, y, z]} (mm, workpiece frame)");
  }
  throw InputError(node.source(), where,
                   "missing, and the touches give none (a single plane in 3-D touched flush, or "
                   "at 3 or more points not on one line): state where the plane stands, "
                   "{\"center\": [x, y, z], \"direction\": its outward normal}");
}

Placement parsePlacement(const Node& node, Plan& plan, CsvFiles& csv_files,
                         bool require_measurements, bool explicit_limits, std::size_t index,
                         std::vector<std::string>& warnings) {
  node.object();
  node.warnUnknown({"artifact", "pose", "measurements", "name", "payload"}, warnings);
  Placement placement;
  if (const auto name = node.find("name")) {
    placement.name = name->string();
    if (placement.name.empty()) name->fail("expected a non-empty name");
  }
  const Node artifact = node.at("artifact");
  const std::string id = artifact.string();
  placement.artifact = plan.artifactIndex(id);
  if (placement.artifact < 0) artifact.fail("unknown artifact \"" + id + "\"");
  const int dimension = plan.machine.dimension();
  if (const auto pose = node.find("pose")) {
    const Artifact& placed = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    placement.pose = parsePose(*pose, dimension, warnings, placed.translatesOnly());
  }
  // A plane's touches lie anywhere on its faces: where it stands is the plan's pose, or what its
  // touches give (docs/planes.md).
  const bool plane =
      plan.artifacts[static_cast<std::size_t>(placement.artifact)].kind().touches_faces;
  const auto measurements = node.find("measurements");
  if (!placement.pose && plane && !measurements) node.at("pose");  // raises "missing"
  if (!measurements) {
    if (require_measurements || !placement.pose) node.at("measurements");  // raises "missing"
    return placement;
  }
  if (plan.artifacts[static_cast<std::size_t>(placement.artifact)].kind().readings_are_features) {
    parseStation(node, *measurements, plan, placement, index, explicit_limits, warnings);
    applyPayloads(node, *measurements, plan.machine, placement, warnings);
    return placement;
  }
  const std::size_t n = measurements->arraySize(1, kMaxMeasurements);
  const Artifact& art = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  const Mechanism& mech = *plan.machine.mechanism;
  for (std::size_t i = 0; i < n; ++i) {
    const Node m = (*measurements)[i];
    m.object();
    if (m.has("csv")) {
      appendCsvMeasurements(m, plan, art, csv_files, explicit_limits, static_cast<int>(i),
                            placement.measurements, warnings);
      continue;
    }
    if (m.has("postures")) {
      placement.posture_requests.push_back(
          parsePostureRequest(m, art, placement, mech, require_measurements, warnings));
      continue;
    }
    m.warnUnknown({"feature", "joints", "stylus", "tip", "payload"}, warnings);
    Measurement measurement;
    measurement.entry = static_cast<int>(i);
    measurement.feature = static_cast<int>(m.at("feature").integer(0, art.featureCount() - 1));
    measurement.joints = jointsFromFile(
        mech, m.at("joints").finiteNumbers(static_cast<std::size_t>(mech.jointCount())));
    if (explicit_limits) checkWithinJointLimits(m.at("joints"), plan.machine, measurement.joints);
    measurement.stylus = readStylus(m, mech);
    // A closed chain's forward kinematics is numerical: a reading it cannot solve at nominal is
    // bad input, named here (docs/models.md section 3), not a failure deep in the estimation.
    Eigen::VectorXd x;
    const ForwardStatus status =
        mech.forwardStylus(measurement.stylus, plan.machine.nominal, measurement.joints, x);
    if (status != ForwardStatus::Ok) m.at("joints").fail(forwardStatusName(status));
    placement.measurements.push_back(std::move(measurement));
  }
  applyPayloads(node, *measurements, plan.machine, placement, warnings);
  if (plane && !placement.pose) placement.pose = planePoseOfTouches(node, plan, placement);
  return placement;
}

// A region of the machine's space: `reach` [min, max] (distance from the origin) and/or `box`
// (two opposite corners), mm. The design's region and the task-space workspace's.
Region parseRegion(const Node& region, int dimension, std::vector<std::string>& warnings) {
  region.object();
  region.warnUnknown({"reach", "box"}, warnings);
  if (!region.has("reach") && !region.has("box")) region.fail("expected reach and/or box");
  Region out;
  if (const auto reach = region.find("reach")) {
    const Eigen::VectorXd r = reach->numbers(2);
    if (!(r[0] >= 0.0 && r[0] < r[1])) reach->fail("expected [min, max] with 0 <= min < max");
    out.reach = std::array<double, 2>{r[0], r[1]};
  }
  if (const auto box = region.find("box")) {
    box->arraySize(2, 2);
    const auto d = static_cast<std::size_t>(dimension);
    out.box = std::array<Eigen::VectorXd, 2>{(*box)[0].numbers(d), (*box)[1].numbers(d)};
  }
  return out;
}

std::uint64_t parseSeed(const Node& node) {
  return static_cast<std::uint64_t>(node.integer(0, std::numeric_limits<long>::max()));
}

// docs/models.md section 5: {"region": {...}, "samples": N, "seed": S, "tilt": deg}.
WorkspaceSpec parseTaskSpaceWorkspace(const Node& node, const Machine& machine,
                                      std::vector<std::string>& warnings) {
  WorkspaceSpec spec;
  spec.kind = WorkspaceSpec::Kind::TaskSpace;
  spec.region = parseRegion(node.at("region"), machine.dimension(), warnings);
  if (const auto samples = node.find("samples"))
    spec.samples = static_cast<int>(samples->integer(1, kMaxWorkspace));
  if (const auto seed = node.find("seed")) spec.seed = parseSeed(*seed);
  if (const auto tilt = node.find("tilt")) {
    const double deg = tilt->nonNegative();
    if (deg > 90.0) tilt->fail("must be at most 90 deg, got " + json(deg).dump());
    spec.tilt = degToRad(deg);
  }
  return spec;
}

WorkspaceSpec parseWorkspace(const Node& node, const Machine& machine,
                             std::vector<std::string>& warnings) {
  node.object();
  node.warnUnknown({"configurations", "samples", "seed", "grid", "region", "tilt"}, warnings);
  if (node.has("region")) {
    if (node.has("configurations") || node.has("grid"))
      node.fail("a task-space workspace (region) takes no configurations or grid");
    return parseTaskSpaceWorkspace(node, machine, warnings);
  }
  if (const auto tilt = node.find("tilt")) tilt->fail("tilt needs a task-space region");
  WorkspaceSpec spec;
  const int kinds = node.has("configurations") + node.has("samples") + node.has("grid");
  if (kinds != 1) node.fail("expected exactly one of configurations, samples, grid or region");
  const auto joints = static_cast<std::size_t>(machine.jointCount());
  if (const auto configurations = node.find("configurations")) {
    spec.kind = WorkspaceSpec::Kind::Configurations;
    const std::size_t n = configurations->arraySize(1, kMaxWorkspace);
    for (std::size_t i = 0; i < n; ++i) {
      spec.configurations.push_back(
          jointsFromFile(*machine.mechanism, (*configurations)[i].numbers(joints)));
    }
  } else if (const auto samples = node.find("samples")) {
    spec.kind = WorkspaceSpec::Kind::Samples;
    spec.samples = static_cast<int>(samples->integer(1, kMaxWorkspace));
    if (const auto seed = node.find("seed"))
      spec.seed = static_cast<std::uint64_t>(seed->integer(0, std::numeric_limits<long>::max()));
  } else {
    spec.kind = WorkspaceSpec::Kind::Grid;
    const Node grid = node.at("grid");
    grid.arraySize(joints, joints);
    long total = 1;
    for (std::size_t i = 0; i < joints; ++i) {
      const long n = grid[i].integer(1, kMaxWorkspace);
      total *= n;
      if (total > kMaxWorkspace)
        grid.fail("more than " + std::to_string(kMaxWorkspace) + " configurations");
      spec.grid.push_back(static_cast<int>(n));
    }
  }
  return spec;
}

Criterion parseCriterion(const Node& node) {
  const std::string name = node.string();
  if (const auto criterion = criterionFromName(name)) return *criterion;
  node.fail("unknown criterion \"" + name + "\" (expected worst-tip, mean-tip, D, A, E or pass)");
}

// design.joint_margin: one number for every joint or one per joint (deg revolute, mm prismatic),
// default 2 deg / 1 mm; it must leave some of each joint's range (docs/plan-format.md).
Eigen::VectorXd parseJointMargin(const std::optional<Node>& node, const Machine& machine) {
  const Mechanism& mech = *machine.mechanism;
  const int joints = mech.jointCount();
  Eigen::VectorXd file_margin(joints);
  for (int i = 0; i < joints; ++i) {
    file_margin[i] = mech.jointKind(i) == JointKind::Revolute ? kDefaultRevoluteMarginDeg
                                                              : kDefaultPrismaticMarginMm;
  }
  if (node && node->value().is_array()) {
    node->numbers(static_cast<std::size_t>(joints));
    for (int i = 0; i < joints; ++i)
      file_margin[i] = (*node)[static_cast<std::size_t>(i)].nonNegative();
  } else if (node) {
    file_margin.setConstant(node->nonNegative());
  }
  Eigen::VectorXd margin(joints);
  for (int i = 0; i < joints; ++i) {
    const Quantity q = jointQuantity(mech.jointKind(i));
    margin[i] = fromFileUnit(q, file_margin[i]);
    const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
    if (node && hi - lo <= 2.0 * margin[i]) {
      node->fail("a margin of " + json(file_margin[i]).dump() + " " + std::string(unitName(q)) +
                 " leaves nothing of joint " + std::to_string(i + 1) + "'s range");
    }
  }
  return margin;
}

// An instrument design (instruments.md, "Planning an instrument calibration"): `stations`
// (default 1), `readings` per station (at least 3), `candidates`: {"samples", "seed"}, and an
// optional task-space `region` the candidates are drawn in.
constexpr int kMaxDesignReadings = 10'000;
constexpr int kMaxDesignCandidates = 1'000'000;

void parseInstrumentDesign(const Node& node, const Plan& plan, DesignSpec& design,
                           std::vector<std::string>& warnings) {
  if (node.has("placements"))
    node.at("placements").fail("an instrument design counts \"stations\" and \"readings\"");
  if (node.has("postures"))
    node.at("postures").fail("an instrument design counts \"stations\" and \"readings\"");
  if (const auto v = node.find("stations"))
    design.placements = static_cast<int>(v->integer(1, 1000));
  InstrumentDesignSpec instrument;
  instrument.readings = static_cast<int>(node.at("readings").integer(3, kMaxDesignReadings));
  if (const auto candidates = node.find("candidates")) {
    candidates->object();
    candidates->warnUnknown({"samples", "seed"}, warnings);
    if (const auto v = candidates->find("samples"))
      instrument.candidates = static_cast<int>(v->integer(3, kMaxDesignCandidates));
    if (const auto v = candidates->find("seed")) instrument.candidate_seed = parseSeed(*v);
  }
  if (const auto region = node.find("region")) {
    design.region = parseRegion(*region, plan.machine.dimension(), warnings);
    instrument.task_space = true;
  }
  design.instrument = instrument;
}

DesignSpec parseDesign(const Node& node, const Plan& plan, std::vector<std::string>& warnings) {
  node.object();
  node.warnUnknown({"artifact", "placements", "postures", "region", "criterion", "seed", "starts",
                    "time_limit", "joint_margin", "pool", "evaluations", "polish", "kicks",
                    "target_tip", "stations", "readings", "candidates"},
                   warnings);
  DesignSpec design;
  const Node artifact = node.at("artifact");
  design.artifact = plan.artifactIndex(artifact.string());
  if (design.artifact < 0) artifact.fail("unknown artifact \"" + artifact.string() + "\"");
  // The optimizer places an artifact and its features in the region; a table-spindle bar's
  // readings are the spindle's positions on a sphere about the table ball (it failed deep in the
  // search, "no bar direction", naming no field).
  if (plan.artifacts[static_cast<std::size_t>(design.artifact)].plane.shape ==
      PlaneShape::TableBall) {
    artifact.fail("\"" + artifact.string() +
                  "\" is a table-spindle ball bar, which optimize does not place: write its "
                  "placements and readings in a plan (docs/five-axis.md section 3), or design "
                  "with a sphere");
  }
  if (plan.artifacts[static_cast<std::size_t>(design.artifact)].kind().readings_are_features) {
    parseInstrumentDesign(node, plan, design, warnings);
  } else {
    for (const char* key : {"stations", "readings", "candidates"})
      if (node.has(key))
        node.at(key).fail("only an instrument design has \"" + std::string(key) + "\"");
    design.placements = static_cast<int>(node.at("placements").integer(1, 100'000));
    if (const auto v = node.find("postures"))
      design.postures = static_cast<int>(v->integer(1, 100));
    design.region = parseRegion(node.at("region"), plan.machine.dimension(), warnings);
  }
  if (const auto v = node.find("criterion")) {
    design.criterion = parseCriterion(*v);
    if (design.criterion == Criterion::Pass &&
        !(plan.acceptance && plan.acceptance->test == "iso10360-2"))
      v->fail("criterion \"pass\" needs the plan's \"acceptance\" block with an iso10360-2 test");
  }
  if (const auto v = node.find("seed"))
    design.seed = static_cast<std::uint64_t>(v->integer(0, std::numeric_limits<long>::max()));
  if (const auto v = node.find("starts")) design.starts = static_cast<int>(v->integer(1, 10'000));
  if (const auto v = node.find("time_limit")) design.time_limit = v->positive();
  if (const auto v = node.find("pool")) design.pool = static_cast<int>(v->integer(1, 100'000));
  if (const auto v = node.find("evaluations"))
    design.evaluations = static_cast<int>(v->integer(1, 10'000'000));
  if (const auto v = node.find("polish")) design.polish = static_cast<int>(v->integer(0, 10'000));
  if (const auto v = node.find("kicks")) design.kicks = static_cast<int>(v->integer(0, 10'000));
  if (const auto v = node.find("target_tip")) design.target_tip = v->positive();
  design.joint_margin = parseJointMargin(node.find("joint_margin"), plan.machine);
  return design;
}

}  // namespace

std::string readInputFile(const std::string& path) {
  // O_NONBLOCK: opening a FIFO without a writer would wait for one.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw InputError(path, "", "cannot be read");
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat status {};
  if (::fstat(fd, &status) != 0) throw InputError(path, "", "cannot be read");
  if (S_ISDIR(status.st_mode)) throw InputError(path, "", "is a directory");
  if (!S_ISREG(status.st_mode)) {
    throw InputError(path, "",
                     "not a regular file (a device, a FIFO or a socket): give the file itself");
  }
  const auto size = static_cast<std::size_t>(status.st_size);
  if (size > kMaxPlanFileBytes) {
    throw InputError(path, "", "larger than " + std::to_string(kMaxPlanFileBytes >> 20) + " MiB");
  }
  noteInputFile(path);
  std::string text;
  try {
    text.resize(size);
  } catch (const std::bad_alloc&) {
    throw InputError(path, "", "not enough memory to read its " + std::to_string(size) + " bytes");
  }
  std::size_t done = 0;
  while (done < size) {
    const ssize_t got = ::read(fd, text.data() + done, size - done);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) throw InputError(path, "", "cannot be read: " + std::string(std::strerror(errno)));
    if (got == 0) break;  // the file shrank while read
    done += static_cast<std::size_t>(got);
  }
  text.resize(done);
  // A UTF-8 byte order mark (Windows editors write one) is not part of the content.
  if (text.starts_with("\xEF\xBB\xBF")) text.erase(0, 3);
  return text;
}

nlohmann::json readJsonFile(const std::string& path) {
  return parseJsonText(readInputFile(path), path);
}

/// InputError when arrays and objects nest deeper than kMaxJsonDepth in JSON text (strings
/// skipped; malformed text is left to the parser). A scan before parsing, because nlohmann's
/// callback parser is quadratic on long arrays of objects (3.11: end_object scans the parent).
static void checkNestingDepth(const std::string& text, const std::string& source) {
  int depth = 0;
  bool in_string = false;
  bool escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) {
        throw InputError(source, "",
                         "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
      }
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

nlohmann::json parseJsonText(const std::string& text, const std::string& source) {
  checkNestingDepth(text, source);
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    // parse_error, and out_of_range for a number beyond double ("1e999"). e.what() reads
    // "[json.exception.parse_error.101] parse error at line 3, column 5: ...": drop the id.
    const std::string message = e.what();
    const auto at = message.find("] ");
    throw InputError(
        source, "",
        "malformed JSON: " + (at == std::string::npos ? message : message.substr(at + 2)));
  }
}

Plan parsePlan(const nlohmann::json& document, const std::string& source, bool require_placements,
               bool check_plausibility) {
  Plan plan;
  plan.source = source;
  const Node root(document, "", source);
  root.object();
  root.warnUnknown(
      {"format", "name", "description", "machine", "noise", "artifacts", "placements", "workspace",
       "design", "predicted", "readings", "calibration", "truth", "simulation", "acceptance"},
      plan.warnings);
  const Node format = root.at("format");
  if (format.string() != "artcal-plan/1") {
    format.fail("unsupported format \"" + format.string() + "\" (expected artcal-plan/1)");
  }
  if (const auto name = root.find("name")) plan.name = name->string();
  if (const auto description = root.find("description")) plan.description = description->string();
  plan.machine = parseMachine(root.at("machine"), plan.warnings);
  plan.noise = parseNoise(root.at("noise"), plan.machine, plan.warnings);
  const Node artifacts = root.at("artifacts");
  if (artifacts.object().empty()) artifacts.fail("expected at least one artifact");
  for (const auto& [id, value] : artifacts.object().items()) {
    plan.artifacts.push_back(readArtifact(id, artifacts.at(id), plan.machine, plan.warnings));
  }
  if (const auto placements = root.find("placements")) {
    const std::size_t n = placements->arraySize(require_placements ? 1 : 0, kMaxPlacements);
    plan.placements.reserve(n);
    CsvFiles csv_files;
    checkCsvReadingsInAll(*placements, plan, csv_files);
    std::map<std::string, std::size_t> named;  // placement names are unique
    for (std::size_t i = 0; i < n; ++i) {
      plan.placements.push_back(parsePlacement((*placements)[i], plan, csv_files,
                                               require_placements, plan.machine.limits_stated, i,
                                               plan.warnings));
      const std::string& name = plan.placements.back().name;
      if (name.empty()) continue;
      const auto [first, fresh] = named.emplace(name, i);
      if (!fresh) {
        (*placements)[i].at("name").fail("placement name \"" + name + "\" is also placement " +
                                         std::to_string(first->second) + "'s");
      }
    }
  } else if (require_placements) {
    root.at("placements");
  }
  attachTorques(plan.machine, plan.placements);  // docs/compliance.md: once per reading
  if (const auto workspace = root.find("workspace")) {
    plan.workspace = parseWorkspace(*workspace, plan.machine, plan.warnings);
  }
  plan.acceptance = parseAcceptanceSpec(document, source);
  if (plan.acceptance) readSeedPosture(root.at("acceptance"), plan.machine, *plan.acceptance);
  if (const auto design = root.find("design"))
    plan.design = parseDesign(*design, plan, plan.warnings);
  if (check_plausibility) checkPlausibility(plan);  // only wrong units or a wrong pose explain
  // "calibrate": "identifiable", decided once, here; a plan whose readings are still to be
  // planned (posture requests, for `plan --complete`) has nothing to decide it from yet.
  const bool readings_pending =
      std::any_of(plan.placements.begin(), plan.placements.end(),
                  [](const Placement& p) { return !p.posture_requests.empty(); });
  if (!readings_pending) resolveCalibratedSet(plan);
  return plan;
}

Plan loadPlan(const std::string& path, bool require_placements) {
  return parsePlan(readJsonFile(path), path, require_placements);
}

namespace {

/// The stylus of a written reading, as readStylus reads it back: its "tip" on a machine that
/// names its tips, otherwise its "stylus" index when not the first.
void addStylus(json& entry, const Mechanism& mech, int stylus) {
  if (const std::vector<std::string> tips = mech.stylusNames(); !tips.empty()) {
    entry["tip"] = tips[static_cast<std::size_t>(stylus)];
  } else if (stylus != 0) {
    entry["stylus"] = stylus;
  }
}

}  // namespace

nlohmann::json placementsToJson(const Plan& plan) {
  json out = json::array();
  const Mechanism& mech = *plan.machine.mechanism;
  for (const Placement& placement : plan.placements) {
    json p;
    if (!placement.name.empty()) p["name"] = placement.name;
    p["artifact"] = plan.artifacts[static_cast<std::size_t>(placement.artifact)].id;
    if (placement.pose) {
      const Pose& pose = *placement.pose;
      p["pose"]["center"] =
          std::vector<double>(pose.center.data(), pose.center.data() + pose.center.size());
      if (plan.machine.dimension() == 2) {
        p["pose"]["angle"] = radToDeg(pose.angle);
      } else {
        p["pose"]["direction"] = {pose.direction[0], pose.direction[1], pose.direction[2]};
        p["pose"]["roll"] = radToDeg(pose.roll);
      }
    }
    json measurements = json::array();
    const bool instrument =
        plan.artifacts[static_cast<std::size_t>(placement.artifact)].kind().readings_are_features;
    for (const Measurement& m : placement.measurements) {
      std::vector<double> joints;
      for (int i = 0; i < m.joints.size(); ++i) {
        joints.push_back(toFileUnit(jointQuantity(mech.jointKind(i)), m.joints[i]));
      }
      const auto add_payload = [&m](json& entry) {
        if (m.payload.mass != 0.0) entry["payload"] = massPointToJson(m.payload);
      };
      if (instrument) {  // a station's reading: its joints and what was measured (mm, deg)
        json entry = {{"joints", joints}};
        add_payload(entry);
        if (m.point_given) {  // a pose's orientation follows, as a rotation vector in deg
          std::vector<double> point(m.point.data(), m.point.data() + m.point.size());
          for (int k = 0; k < m.orientation.size(); ++k)
            point.push_back(radToDeg(m.orientation[k]));
          entry["point"] = point;
        }
        if (m.stationing) entry["stationing"] = true;
        addStylus(entry, mech, m.stylus);
        measurements.push_back(entry);
        continue;
      }
      json entry = {{"feature", m.feature}, {"joints", joints}};
      addStylus(entry, mech, m.stylus);
      add_payload(entry);
      measurements.push_back(entry);
    }
    p["measurements"] = measurements;
    out.push_back(p);
  }
  return out;
}

nlohmann::json machineToJson(const Machine& machine, const Eigen::VectorXd& parameters) {
  const Mechanism& mech = *machine.mechanism;
  json out;
  out["model"] = mech.modelName();
  const ModelCodec* codec = findModelCodec(mech.modelName());
  if (!codec) throw std::logic_error("no codec registered for model " + mech.modelName());
  codec->write(mech, parameters, out);
  json calibrate = json::array();
  for (int k : machine.calibrated) calibrate.push_back(mech.parameters()[k].name);
  out["calibrate"] = calibrate;
  json limits = json::array();
  for (int j = 0; j < mech.jointCount(); ++j) {
    const Quantity q = jointQuantity(mech.jointKind(j));
    limits.push_back(
        {toFileUnit(q, machine.joint_limits[j][0]), toFileUnit(q, machine.joint_limits[j][1])});
  }
  out["joint_limits"] = limits;
  if (machine.prior_sigma.size() > 0) {
    json prior = json::object();
    for (int i = 0; i < mech.parameterCount(); ++i) {
      const ParameterInfo& info = mech.parameters()[static_cast<std::size_t>(i)];
      if (machine.prior_sigma[i] > 0.0)
        prior[info.name] = toFileUnit(info.quantity, machine.prior_sigma[i]);
    }
    out["prior"] = prior;
  }
  return out;
}

}  // namespace artcal
