#include "artcal/io/instrument_codec.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "artcal/core/error.hpp"
#include "artcal/core/linear_algebra.hpp"
#include "artcal/core/units.hpp"
#include "artcal/io/csv_readings.hpp"
#include "artcal/io/json_node.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/model/rotation_vector.hpp"

namespace artcal {

namespace {

constexpr std::size_t kMaxStationReadings = 10'000;

/// mm per unit of `point_unit` ("mm" or "m").
double pointUnitToMm(const Node& entry) {
  const auto unit = entry.find("point_unit");
  if (!unit) return 1.0;
  const std::string name = unit->string();
  if (name == "mm") return 1.0;
  if (name == "m") return 1000.0;
  unit->fail("unknown point_unit \"" + name + "\" (expected mm or m)");
}

/// deg per unit of a pose's `orientation_unit` ("deg" or "rad"); only a pose instrument's
/// readings have an orientation.
double orientationUnitToDeg(const Node& entry, const Artifact& instrument) {
  const auto unit = entry.find("orientation_unit");
  if (!unit) return 1.0;
  if (!instrument.measures_pose)
    unit->fail("only a \"pose\" instrument's readings have an orientation (its measures is point)");
  const std::string name = unit->string();
  if (name == "deg") return 1.0;
  if (name == "rad") return radToDeg(1.0);
  unit->fail("unknown orientation_unit \"" + name + "\" (expected deg or rad)");
}

/// How a pose's orientation is written in a CSV row (`"orientation"` of the entry).
enum class OrientationForm { RotationVector, RollPitchYaw, Quaternion };

OrientationForm orientationForm(const Node& entry, const Artifact& instrument) {
  const auto form = entry.find("orientation");
  if (!form) return OrientationForm::RotationVector;
  if (!instrument.measures_pose)
    form->fail("only a \"pose\" instrument's readings have an orientation (its measures is point)");
  const std::string name = form->string();
  if (name == "rotation_vector") return OrientationForm::RotationVector;
  if (name == "rpy") return OrientationForm::RollPitchYaw;
  if (name == "quaternion") return OrientationForm::Quaternion;
  form->fail("unknown orientation \"" + name + "\" (expected rotation_vector, rpy or quaternion)");
}

/// The rotation vector (deg) of an orientation read as `form`: roll, pitch, yaw in deg (the
/// URDF's fixed-axis x-y-z: R = Rz(yaw) Ry(pitch) Rx(roll)), or a unit quaternion w, x, y, z;
/// std::nullopt for a quaternion whose norm is not 1 within 1e-3.
std::optional<Eigen::Vector3d> rotationVectorDeg(OrientationForm form, const Eigen::VectorXd& o) {
  Eigen::Matrix3d R;
  if (form == OrientationForm::RollPitchYaw) {
    R = (Eigen::AngleAxisd(degToRad(o[2]), Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(degToRad(o[1]), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(degToRad(o[0]), Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
  } else {
    const Eigen::Quaterniond q(o[0], o[1], o[2], o[3]);
    if (!(std::abs(q.norm() - 1.0) <= 1e-3)) return std::nullopt;
    R = q.normalized().toRotationMatrix();
  }
  return rotationVector(R) * radToDeg(1.0);
}

/// Measured coordinates per reading: the point's, then a pose's 3 orientation coordinates.
int measuredCoordinates(const Artifact& instrument) {
  return instrument.dimension + (instrument.measures_pose ? 3 : 0);
}

/// A reading's measured coordinates (file units: the point in mm, a pose's orientation as a
/// rotation vector in deg) into `measurement`, which then joins the station.
void appendReading(Measurement measurement, const Eigen::VectorXd& measured, Artifact& instrument,
                   Placement& placement) {
  const int d = instrument.dimension;
  measurement.point = measured.head(d);
  if (instrument.measures_pose) measurement.orientation = measured.tail(3) * degToRad(1.0);
  measurement.feature = instrument.appendFeature(measurement.point);
  placement.measurements.push_back(std::move(measurement));
}

/// A measured orientation longer than a turn (a rotation vector's length is the angle it turns,
/// at most 360 deg however it is written): its unit or its columns are wrong. The message names
/// the reading (docs/hardening.md); "" when the orientation is plausible.
std::string implausibleOrientation(const Eigen::VectorXd& coordinates, const Artifact& instrument) {
  if (!instrument.measures_pose) return "";
  // The coordinates are within 1e9 deg (checked where they are read; 5.7e10 deg for rad): the
  // length is finite.
  const double turned = coordinates.tail(3).stableNorm();
  if (turned <= 360.0 + 1e-9) return "";
  char text[48];
  std::snprintf(text, sizeof text, "%.4g", turned);
  return std::string("the measured orientation (a rotation vector) turns ") + text +
         " deg, more than a turn: check its unit (orientation_unit deg or rad) and the columns "
         "(x, y, z, then rx, ry, rz)";
}

/// A number as a message shows it (4 significant digits: 1e+300, 1.5e+11).
std::string shortValue(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}

/// A measured coordinate of a CSV row that no reading can be, as the file writes it (`raw`, in
/// the file's unit): a point's beyond 1e9 mm (1000 km, the bound of every length), a rotation
/// vector's beyond 1e9 deg, a roll-pitch-yaw angle beyond a turn, a unit quaternion's component
/// beyond 1. Checked before any arithmetic on the row, so that no message says "inf". "" when in
/// range; else what to check.
std::string coordinateOutOfRange(int k, double raw, int d, OrientationForm form, double point_scale,
                                 const std::string& point_unit, double orientation_scale,
                                 const std::string& orientation_unit) {
  static const char* const kPoint[] = {"x", "y", "z"};
  static const char* const kRotationVector[] = {"rx", "ry", "rz"};
  static const char* const kRollPitchYaw[] = {"roll", "pitch", "yaw"};
  static const char* const kQuaternion[] = {"w", "x", "y", "z"};
  if (k < d) {
    if (std::abs(raw) <= kMaxInputMagnitude / point_scale) return "";
    return std::string("the measured ") + (d <= 3 ? kPoint[k] : "coordinate") + " is " +
           shortValue(raw) + " " + point_unit + ", beyond " + shortValue(kMaxInputMagnitude) +
           " mm (1000 km): check the value, its unit (point_unit mm or m) and the columns "
           "(the joints, then x, y, z)";
  }
  const int o = k - d;
  if (form == OrientationForm::Quaternion) {
    if (std::abs(raw) <= 1.0 + 1e-3) return "";
    return std::string("the quaternion's ") + kQuaternion[o] + " is " + shortValue(raw) +
           ", beyond 1 (a unit quaternion's components are within [-1, 1]): check the columns "
           "(w, x, y, z) and the entry's \"orientation\"";
  }
  if (form == OrientationForm::RollPitchYaw) {
    if (std::abs(raw) <= (360.0 + 1e-9) / orientation_scale) return "";
    return std::string("the measured ") + kRollPitchYaw[o] + " is " + shortValue(raw) + " " +
           orientation_unit +
           ", more than a turn: check its unit (orientation_unit deg or rad) and the columns "
           "(x, y, z, then roll, pitch, yaw)";
  }
  if (std::abs(raw) <= kMaxInputMagnitude / orientation_scale) return "";
  return std::string("the measured orientation's ") + kRotationVector[o] +
         " (a rotation vector) is " + shortValue(raw) + " " + orientation_unit +
         ", more than a turn: check its unit (orientation_unit deg or rad) and the columns "
         "(x, y, z, then rx, ry, rz)";
}

/// The nominal tip point of a reading: where the instrument sees it when the plan gives no point
/// (planning only; the station is then the identity).
Eigen::VectorXd nominalTip(const Machine& machine, const Eigen::VectorXd& q, int stylus) {
  Eigen::VectorXd x;
  forwardOrThrow(*machine.mechanism, machine.nominal, q, x, nullptr, nullptr, stylus);
  return x;
}

/// The CSV's rows, a wrong column count told in an instrument's terms (joints, then what the
/// instrument measures), at the file and line.
std::vector<Eigen::VectorXd> readStationCsv(const std::string& file,
                                            const std::vector<JointKind>& kinds,
                                            const ReadingUnits& units, int joints,
                                            const Artifact& instrument, std::vector<long>& lines,
                                            const std::vector<CsvColumn>* columns,
                                            CsvDropouts& dropouts) {
  try {
    return readJointCsv(file, kinds, units, &lines, columns, &dropouts);
  } catch (const InputError& e) {
    const std::string message = e.what();
    if (message.rfind("expected ", 0) != 0) throw;
    throw InputError(e.file(), e.pointer(),
                     message + " (" + std::to_string(joints) + " joints, then the " +
                         std::to_string(measuredCoordinates(instrument)) + " measured coordinates" +
                         (instrument.measures_pose
                              ? ": x, y, z, then the orientation as a rotation vector in deg)"
                              : ")"));
  }
}

/// The rows of a station file whose measured point was not seen, said once (never skipped
/// silently): how many, the first few lines, and the marker when the entry names its tip.
std::string droppedRowsWarning(const std::string& file, const Node& entry,
                               const std::vector<long>& dropped) {
  std::string list;
  for (std::size_t i = 0; i < dropped.size() && i < 5; ++i)
    list += (i ? ", " : "") + std::to_string(dropped[i]);
  if (dropped.size() > 5) list += ", ...";
  const std::string marker = entry.find("tip") && entry.at("tip").value().is_string()
                                 ? " of marker \"" + entry.at("tip").string() + "\""
                                 : std::string();
  return file + ": " + std::to_string(dropped.size()) + " row(s) without a reading" + marker +
         " (its coordinates empty or NaN: not seen) left out, line(s) " + list;
}

void appendCsvReadings(const Node& entry, const std::string& plan_source, const Machine& machine,
                       Artifact& instrument, Placement& placement, int entry_index,
                       const CheckCsvJoints& check_csv_joints, std::vector<std::string>& warnings) {
  entry.warnUnknown({"csv", "unit", "point_unit", "orientation_unit", "orientation", "columns",
                     "stationing", "tip", "stylus", "payload"},
                    warnings);
  const int stylus = readStylus(entry, *machine.mechanism);
  const OrientationForm form = orientationForm(entry, instrument);
  const Node csv = entry.at("csv");
  const std::filesystem::path relative(csv.string());
  if (relative.empty()) csv.fail("expected a file name");
  const std::filesystem::path path =
      relative.is_absolute() ? relative
                             : std::filesystem::path(plan_source).parent_path() / relative;
  ReadingUnits units;
  if (const auto unit = entry.find("unit")) {
    const auto named = readingUnitsFromName(unit->string());
    if (!named)
      unit->fail("unknown unit \"" + unit->string() +
                 "\" (expected deg, rad, mm, m, or an angle and a length unit as rad+m)");
    units = *named;
  }
  const double point_scale = pointUnitToMm(entry);
  const double orientation_scale = orientationUnitToDeg(entry, instrument);
  const bool stationing = entry.find("stationing") && entry.at("stationing").value().is_boolean() &&
                          entry.at("stationing").value().get<bool>();
  const Mechanism& mech = *machine.mechanism;
  const int joints = mech.jointCount();
  const int d = instrument.dimension;
  const int measured = measuredCoordinates(instrument);
  // A quaternion takes 4 columns where a rotation vector or roll-pitch-yaw takes 3.
  const int read = measured + (form == OrientationForm::Quaternion ? 1 : 0);
  // The measured coordinates read as lengths (the file's length unit), rescaled to point_unit
  // for the point; a pose's orientation is in orientation_unit (deg by default) whatever `unit`
  // says.
  std::vector<JointKind> kinds;
  for (int i = 0; i < joints; ++i) kinds.push_back(mech.jointKind(i));
  for (int k = 0; k < read; ++k) kinds.push_back(JointKind::Prismatic);
  const std::string file = path.lexically_normal().string();
  std::optional<std::vector<CsvColumn>> columns;
  if (const auto given = entry.find("columns")) columns = parseCsvColumns(*given, kinds.size());
  std::vector<long> lines;
  CsvDropouts dropouts{static_cast<std::size_t>(joints), {}};
  const std::vector<Eigen::VectorXd> rows = readStationCsv(
      file, kinds, units, joints, instrument, lines, columns ? &*columns : nullptr, dropouts);
  if (!dropouts.lines.empty()) warnings.push_back(droppedRowsWarning(file, entry, dropouts.lines));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const std::string where =
        "line " + std::to_string(lines[r]) + " (row " + std::to_string(r + 1) + ")";
    Measurement measurement;
    measurement.joints = rows[r].head(joints);
    check_csv_joints(measurement.joints, file, where);
    if (placement.measurements.size() >= kMaxStationReadings)
      csv.fail("more than " + std::to_string(kMaxStationReadings) + " readings in one station");
    measurement.csv = relative.string();
    measurement.csv_row = static_cast<int>(r + 1);
    measurement.entry = entry_index;
    measurement.stylus = stylus;
    measurement.stationing = stationing;
    for (int k = 0; k < read; ++k) {
      const double raw = rows[r][joints + k] / units.length_to_mm;
      const std::string why =
          coordinateOutOfRange(k, raw, d, form, point_scale, point_scale == 1.0 ? "mm" : "m",
                               orientation_scale, orientation_scale == 1.0 ? "deg" : "rad");
      if (why.empty()) continue;
      const std::string column = columns ? "" : ": column " + std::to_string(joints + k + 1);
      throw InputError(file, where + column, why);
    }
    Eigen::VectorXd coordinates(measured);
    coordinates.head(d) = rows[r].segment(joints, d) / units.length_to_mm * point_scale;
    if (instrument.measures_pose) {
      const Eigen::VectorXd o = rows[r].tail(read - d) / units.length_to_mm;
      if (form == OrientationForm::RotationVector) {
        coordinates.tail(3) = o * orientation_scale;
      } else {
        Eigen::VectorXd angles = o;
        if (form == OrientationForm::RollPitchYaw) angles *= orientation_scale;
        const auto w = rotationVectorDeg(form, angles);
        if (!w) {
          throw InputError(file, where,
                           "the quaternion (w, x, y, z) has norm " + std::to_string(o.norm()) +
                               ", not 1: check the columns' order");
        }
        coordinates.tail(3) = *w;
      }
    }
    if (const std::string why = implausibleOrientation(coordinates, instrument); !why.empty())
      throw InputError(file, where, why);
    appendReading(std::move(measurement), coordinates, instrument, placement);
  }
}

Artifact parseInstrumentArtifact(const std::string& id, const Node& node, const Machine& machine,
                                 std::vector<std::string>& warnings) {
  node.warnUnknown({"type", "measures", "noise", "noise_angle"}, warnings);
  const double noise = node.find("noise") ? node.at("noise").standardDeviation(true) : 0.0;
  Artifact instrument = Artifact::instrument(id, machine.dimension(), noise);
  if (const auto measures = node.find("measures")) {
    const std::string what = measures->string();
    if (what != "point" && what != "pose")
      measures->fail("unknown measures \"" + what + "\" (expected point or pose)");
    if (what == "pose") {
      if (!machine.mechanism->hasOrientation()) {
        measures->fail(
            "a \"pose\" measurement needs a model whose forward kinematics gives an "
            "orientation (chain, serial-dh); model " +
            machine.mechanism->modelName() + " gives points: use \"point\"");
      }
      // The orientation rows need a noise of their own (deg, per rotation-vector coordinate).
      if (!node.has("noise_angle"))
        node.fail("a \"pose\" instrument needs \"noise_angle\" (deg, > 0)");
      instrument.measures_pose = true;
      instrument.noise_angle = degToRad(node.at("noise_angle").standardDeviation(false));
    }
  }
  return instrument;
}

}  // namespace

ArtifactCodec instrumentArtifactCodec() {
  return {"instrument", parseInstrumentArtifact};
}

void parseStationReadings(const Node& measurements, const std::string& plan_source,
                          const Machine& machine, Artifact& instrument, Placement& placement,
                          const JointsFromNode& joints_from_node,
                          const CheckCsvJoints& check_csv_joints,
                          std::vector<std::string>& warnings) {
  const std::size_t n = measurements.arraySize(1, kMaxStationReadings);
  const auto measured = static_cast<std::size_t>(measuredCoordinates(instrument));
  for (std::size_t i = 0; i < n; ++i) {
    const Node m = measurements[i];
    m.object();
    if (m.has("csv")) {
      appendCsvReadings(m, plan_source, machine, instrument, placement, static_cast<int>(i),
                        check_csv_joints, warnings);
      continue;
    }
    m.warnUnknown({"joints", "point", "point_unit", "orientation_unit", "stationing", "tip",
                   "stylus", "payload"},
                  warnings);
    if (m.has("feature")) m.at("feature").fail("an instrument's reading has no feature");
    Measurement measurement;
    measurement.entry = static_cast<int>(i);
    measurement.stylus = readStylus(m, *machine.mechanism);
    measurement.joints = joints_from_node(m.at("joints"));
    if (const auto stationing = m.find("stationing")) {
      if (!stationing->value().is_boolean()) stationing->fail("expected true or false");
      measurement.stationing = stationing->value().get<bool>();
    }
    if (const auto given = m.find("point")) {
      // Every coordinate within the input bound (Node::number: 1e9 mm or deg), the point once
      // more in mm, so that no figure or message of the reading is inf.
      Eigen::VectorXd coordinates = given->numbers(measured);
      const double point_scale = pointUnitToMm(m);
      coordinates.head(instrument.dimension) *= point_scale;
      for (int k = 0; k < instrument.dimension; ++k) {
        if (std::abs(coordinates[k]) > kMaxInputMagnitude) {
          (*given)[static_cast<std::size_t>(k)].fail(
              "the measured point's coordinate is " + shortValue(coordinates[k]) + " mm, beyond " +
              shortValue(kMaxInputMagnitude) +
              " mm (1000 km): check the value and its unit (point_unit mm or m)");
        }
      }
      const double orientation_scale = orientationUnitToDeg(m, instrument);
      if (instrument.measures_pose) coordinates.tail(3) *= orientation_scale;
      if (const std::string why = implausibleOrientation(coordinates, instrument); !why.empty())
        given->fail(why);
      appendReading(std::move(measurement), coordinates, instrument, placement);
    } else {
      setNominalReading(machine, instrument, measurement);
      measurement.point_given = false;
      measurement.feature = instrument.appendFeature(measurement.point);
      placement.measurements.push_back(std::move(measurement));
    }
  }
}

void checkStation(const Node& placement_node, const Machine& machine, const Placement& placement,
                  const std::string& label) {
  const auto n = static_cast<int>(placement.measurements.size());
  if (n < 3) {
    placement_node.fail("station \"" + label + "\" has " + std::to_string(n) +
                        " reading(s): a station needs at least 3 readings whose tip points are "
                        "not collinear");
  }
  // The rank test about the station's centroid, scaled by its spread (instruments.md): far from
  // its points, plain [I, -[x]x] columns would look collinear to rounding.
  Eigen::MatrixXd tips(machine.dimension(), n);
  for (int i = 0; i < n; ++i) {
    const Measurement& m = placement.measurements[static_cast<std::size_t>(i)];
    tips.col(i) = nominalTip(machine, m.joints, m.stylus);
  }
  const Eigen::MatrixXd centred = tips.colwise() - tips.rowwise().mean();
  const Eigen::VectorXd sv = singularValues(centred);
  const bool collinear =
      sv.size() < 2 || !(sv[0] > 0.0) || (machine.dimension() == 3 && sv[1] <= 1e-6 * sv[0]);
  if (collinear) {
    placement_node.fail("station \"" + label +
                        "\": the tip points of its readings are collinear, so the station's "
                        "rotation about their line is free: add readings off that line");
  }
}

}  // namespace artcal
