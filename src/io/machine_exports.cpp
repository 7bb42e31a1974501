// Exports of a calibrated machine file (io/machine_exports.hpp, docs/exports.md).

#include "artcal/io/machine_exports.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <sstream>

#include "artcal/core/error.hpp"
#include "artcal/core/units.hpp"
#include "artcal/io/machine_covariance.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/urdf_origin_edit.hpp"
#include "artcal/model/rotation_vector.hpp"

namespace artcal {

namespace {

using nlohmann::json;

constexpr double kCoverage = 2.0;  // U = k u, k = 2

// The machine block wrapped in a minimal plan (as the TRUTH reader does, io/truth_io.cpp): one
// parser for one format; the reader's pointers are mapped back into the machine file.
Plan planOfMachine(const json& document, const std::string& source) {
  json block = document.contains("machine") ? document.at("machine") : document;
  if (!block.is_object()) throw InputError(source, "", "expected a machine block (an object)");
  block.erase("frames");
  const json wrapper = {{"format", "artcal-plan/1"},
                        {"machine", block},
                        {"noise", {{"probe", 1.0}, {"encoder", 1.0}}},
                        {"artifacts", {{"a", {{"type", "ball_bar"}, {"length", 1.0}}}}}};
  try {
    return parsePlan(wrapper, source, false);
  } catch (const InputError& e) {
    std::string where = e.pointer();
    if (where.rfind("/machine", 0) == 0) where = where.substr(8);
    throw InputError(source, where.empty() ? "/" : where, e.what());
  }
}

// Where `index` sits in the covariance (-1: not calibrated, or no covariance).
int covariancePosition(const MachineFile& file, int index) {
  if (!file.uncertainty) return -1;
  const std::vector<int>& indices = file.uncertainty->indices;
  for (std::size_t k = 0; k < indices.size(); ++k)
    if (indices[k] == index) return static_cast<int>(k);
  return -1;
}

bool calibrated(const MachineFile& file, int index) {
  for (const int i : file.plan.machine.calibrated)
    if (i == index) return true;
  return false;
}

// A value written: sum c_i p_i (+ constant), file units, with its status and u when every term
// is calibrated (u from the file's covariance, in its units).
json combination(const MachineFile& file, const std::vector<std::pair<std::string, double>>& terms,
                 double constant) {
  const Machine& machine = file.plan.machine;
  double value = constant;
  std::vector<std::string> not_calibrated;
  const int n = file.uncertainty ? static_cast<int>(file.uncertainty->indices.size()) : 0;
  Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
  bool has_u = file.uncertainty.has_value();
  for (const auto& [name, c] : terms) {
    const int index = machine.mechanism->parameterIndex(name);
    value +=
        c * toFileUnit(machine.mechanism->parameters()[static_cast<std::size_t>(index)].quantity,
                       machine.nominal[index]);
    if (!calibrated(file, index)) not_calibrated.push_back(name);
    const int k = covariancePosition(file, index);
    if (k >= 0)
      w[k] = c;
    else
      has_u = false;
  }
  json out = {{"value", value},
              {"status", terms.empty()            ? "given"
                         : not_calibrated.empty() ? "determined"
                                                  : "not determined"},
              {"not_calibrated", not_calibrated}};
  if (!terms.empty() && not_calibrated.empty() && has_u) {
    // V is in internal units (mm, rad); the terms of one combination share a quantity.
    const int first = machine.mechanism->parameterIndex(terms.front().first);
    const Quantity& q = machine.mechanism->parameters()[static_cast<std::size_t>(first)].quantity;
    const double u = toFileUnit(q, std::sqrt(std::max(0.0, w.dot(file.uncertainty->V * w))));
    out["u"] = u;
    out["U"] = kCoverage * u;
  } else {
    out["u"] = nullptr;
    out["U"] = nullptr;
  }
  return out;
}

// One parameter the format cannot carry: its value and status, and why.
json notCarried(const MachineFile& file, const std::string& name, const std::string& why) {
  const Machine& machine = file.plan.machine;
  const int index = machine.mechanism->parameterIndex(name);
  const Quantity& q = machine.mechanism->parameters()[static_cast<std::size_t>(index)].quantity;
  json out = combination(file, {{name, 1.0}}, 0.0);
  out["name"] = name;
  out["unit"] = std::string(unitName(q));
  out["why"] = why;
  return out;
}

std::string numberText(double v) {
  return shortestNumber(v);
}

// "x y z" of a JSON array of three numbers, each in its shortest text ("0", never "-0.0").
std::string triple(const json& v) {
  return numberText(v[0].get<double>()) + " " + numberText(v[1].get<double>()) + " " +
         numberText(v[2].get<double>());
}

// " determined, u 0.85 um, U (k = 2) 1.71 um" or " not determined (E_X0C not calibrated)".
std::string statusText(const json& entry, const std::string& unit) {
  if (entry["status"] == "given") return "given (--pivot)";
  if (entry["status"] != "determined") {
    std::string names;
    for (const json& n : entry["not_calibrated"])
      names += (names.empty() ? "" : ", ") + n.get<std::string>();
    return "NOT DETERMINED (" + names + " not calibrated: the file's value, not measured)";
  }
  if (!entry["u"].is_number()) return "determined";
  const double u = entry["u"].get<double>(), U = entry["U"].get<double>();
  std::ostringstream out;
  if (unit == "deg")
    out << "determined, u " << degToRad(u) * 1e6 << " urad, U (k = 2) " << degToRad(U) * 1e6
        << " urad";
  else
    out << "determined, u " << u * 1e3 << " um, U (k = 2) " << U * 1e3 << " um";
  return out.str();
}

void requireLocationErrors(const MachineFile& file) {
  const Mechanism& m = *file.plan.machine.mechanism;
  if (!m.hasLocationErrors())
    throw InputError(file.source, "/model",
                     "export-linuxcnc takes a five-axis machine tool (model machine-tool)");
  if (m.parameterIndex("E_Y0A") < 0)
    throw InputError(
        file.source, "/configuration",
        "LinuxCNC's tilting-table kinematics (xyzac-trt, xyzbc-trt) carry C on a tilting "
        "table; this machine has B in the spindle head (head-B-table-C), which they do "
        "not describe: no export");
}

}  // namespace

MachineFile readMachineFile(const json& document, const std::string& source) {
  MachineFile file;
  file.plan = planOfMachine(document, source);
  file.document = document.contains("machine") ? document.at("machine") : document;
  file.source = source;
  file.uncertainty = parseMachineCovariance(file.document, source, file.plan);
  return file;
}

namespace {

constexpr const char* kKins = "xyzac-trt-kins";

// A pin of xyzac-trt-kins and the value written to it.
struct Pin {
  std::string pin, formula;
  json value;
};

// trtfuncs (LinuxCNC 2.9+): the C line through (x-rot-point, y-rot-point), vertical at A = 0;
// the A line along X through (y-rot-point + y-offset, z-rot-point + z-offset) in the slides' Z
// (tool-offset added by the kinematics). artcal's lines: C through (E_X0C, E_Y0C), A through
// (E_Y0A, E_Z0A), about the pivot (docs/exports.md).
std::vector<Pin> linuxcncPins(const MachineFile& file, const Eigen::Vector3d& pivot) {
  return {{"x-rot-point", "pivot X + E_X0C", combination(file, {{"E_X0C", 1.0}}, pivot.x())},
          {"y-rot-point", "pivot Y + E_Y0C", combination(file, {{"E_Y0C", 1.0}}, pivot.y())},
          {"z-rot-point", "pivot Z", combination(file, {}, pivot.z())},
          {"y-offset", "E_Y0A - E_Y0C", combination(file, {{"E_Y0A", 1.0}, {"E_Y0C", -1.0}}, 0.0)},
          {"z-offset", "E_Z0A", combination(file, {{"E_Z0A", 1.0}}, 0.0)}};
}

// What xyzac-trt cannot hold: its axes exact, its slides square, no zero offsets, no tool.
json linuxcncNotCarried(const MachineFile& file) {
  const std::string square = "xyzac-trt's slides are square";
  const std::string along_x = "xyzac-trt's A axis lies exactly along X";
  const std::string along_z = "xyzac-trt's C axis lies exactly along Z at A = 0";
  const std::string zero = "xyzac-trt takes the axis reading as the angle (no zero offset)";
  return json::array(
      {notCarried(file, "E_B0A", along_x), notCarried(file, "E_C0A", along_x),
       notCarried(file, "E_A0A", zero), notCarried(file, "E_A0C", along_z),
       notCarried(file, "E_B0C", along_z), notCarried(file, "E_C0C", zero),
       notCarried(file, "E_C0Y", square), notCarried(file, "E_B0Z", square),
       notCarried(file, "E_A0Z", square),
       notCarried(file, "L",
                  std::string("the tool length is the tool table's (motion.tooloffset.z, netted "
                              "to ") +
                      kKins + ".tool-offset), not a kinematics value")});
}

// The HAL file: a header, each pin's setp with its status on the line above, the notes.
std::string halText(const MachineFile& file, const Eigen::Vector3d& pivot,
                    const std::vector<Pin>& pins, const json& not_carried) {
  const std::string kins = kKins;
  std::ostringstream text;
  text << "# artcal export-linuxcnc of " << file.source << ": LinuxCNC " << kins
       << " (trtfuncs, LinuxCNC 2.9 and later)\n"
       << "# HAL: loadrt " << kins
       << ", then these setp lines. Units mm. u standard uncertainty, U = 2 u (k = 2).\n"
       << "# pivot (LinuxCNC machine coordinates of the slides at artcal's zero readings): "
       << numberText(pivot.x()) << " " << numberText(pivot.y()) << " " << numberText(pivot.z())
       << " mm\n"
       << "# Rotary directions: artcal's positive A and C turn the table as " << kins
       << "'s default (conventional-directions 0 where that pin exists) does.\n";
  for (const Pin& p : pins) {
    // The comment on a line of its own: halcmd reads a '#' at the start of a line.
    text << "# " << p.pin << " = " << p.formula << ", mm; " << statusText(p.value, "mm") << "\n"
         << "setp " << kins << "." << p.pin << " " << numberText(p.value["value"].get<double>())
         << "\n";
  }
  const Machine& machine = file.plan.machine;
  const int l = machine.mechanism->parameterIndex("L");
  if (!calibrated(file, l)) {
    text << "# z-offset holds E_Z0A, which sphere probing determines only relative to the probe's "
            "length L = "
         << numberText(machine.nominal[l])
         << " mm (docs/five-axis.md section 4): the tool table must give the probe that length.\n";
  }
  text << "# " << kins << ".x-offset is not read by xyzac-trt; " << kins
       << ".tool-offset comes from the tool table.\n"
       << "# NOT CARRIED by " << kins << " (not written; compensate otherwise or accept):\n";
  for (const json& e : not_carried) {
    text << "#   " << e["name"].get<std::string>() << " = " << numberText(e["value"].get<double>())
         << " " << e["unit"].get<std::string>() << " ("
         << statusText(e, e["unit"].get<std::string>()) << "): " << e["why"].get<std::string>()
         << "\n";
  }
  return text.str();
}

}  // namespace

MachineExport linuxcncExport(const MachineFile& file, const Eigen::Vector3d& pivot) {
  requireLocationErrors(file);
  const std::vector<Pin> pins = linuxcncPins(file, pivot);
  const json not_carried = linuxcncNotCarried(file);
  json values = json::array();
  for (const Pin& p : pins) {
    json v = p.value;
    v["pin"] = std::string(kKins) + "." + p.pin;
    v["from"] = p.formula;
    v["unit"] = "mm";
    values.push_back(v);
  }
  MachineExport out;
  out.text = halText(file, pivot, pins, not_carried);
  out.summary = {{"format", "linuxcnc-hal"},
                 {"kinematics", kKins},
                 {"pivot_mm", {pivot.x(), pivot.y(), pivot.z()}},
                 {"coverage_factor", kCoverage},
                 {"values", values},
                 {"not_carried", not_carried}};
  return out;
}

namespace {

Eigen::Isometry3d rotX(double a) {
  return Eigen::Isometry3d(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()));
}
Eigen::Isometry3d rotY(double a) {
  return Eigen::Isometry3d(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()));
}
Eigen::Isometry3d rotZ(double a) {
  return Eigen::Isometry3d(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()));
}
Eigen::Isometry3d shift(const Eigen::Vector3d& v) {
  return Eigen::Isometry3d(Eigen::Translation3d(v));
}

// A DH parameter by name ("j3.alpha"), internal units; absent (beta): 0.
double dh(const Machine& machine, int joint, const char* what) {
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "j" + std::string.
  std::string name = "j";
  name += std::to_string(joint);
  name += '.';
  name += what;
  const int index = machine.mechanism->parameterIndex(name);
  return index < 0 ? 0.0 : machine.nominal[index];
}

// The joint origins O_1..O_6 (mm) of T = O_1 Rz(q1) ... O_6 Rz(q6) Tail Trans(probe), from the
// serial-dh conventions (docs/plan-format.md, models.md section 2):
//   standard A_i = Rz(theta_i + q_i) Tz(d_i) Tx(a_i) Rx(alpha_i) Ry(beta_i): Rz and Tz commute,
//     so O_1 = Tz(d_1) Rz(theta_1), O_i = Tx(a_{i-1}) Rx(alpha_{i-1}) Ry(beta_{i-1}) Tz(d_i)
//     Rz(theta_i), Tail = Tx(a_6) Rx(alpha_6) Ry(beta_6);
//   modified A_i = Rx(alpha_i) Tx(a_i) Ry(beta_i) Rz(theta_i + q_i) Tz(d_i): O_i = Rx(alpha_i)
//     Tx(a_i) Ry(beta_i) Tz(d_i) Rz(theta_i), Tail = identity.
struct DhOrigins {
  std::vector<Eigen::Isometry3d> origins;
  Eigen::Isometry3d tail = Eigen::Isometry3d::Identity();
};

DhOrigins dhOrigins(const Machine& machine, bool modified) {
  DhOrigins out;
  Eigen::Isometry3d before = Eigen::Isometry3d::Identity();  // the previous joint's tail
  for (int j = 1; j <= 6; ++j) {
    const double theta = dh(machine, j, "theta"), d = dh(machine, j, "d"), a = dh(machine, j, "a"),
                 alpha = dh(machine, j, "alpha"), beta = dh(machine, j, "beta");
    const Eigen::Isometry3d own = shift(Eigen::Vector3d(0, 0, d)) * rotZ(theta);
    if (modified) {
      out.origins.push_back(rotX(alpha) * shift(Eigen::Vector3d(a, 0, 0)) * rotY(beta) * own);
    } else {
      out.origins.push_back(before * own);
      before = shift(Eigen::Vector3d(a, 0, 0)) * rotX(alpha) * rotY(beta);
    }
  }
  if (!modified) out.tail = before;
  return out;
}

void requireUrArm(const MachineFile& file) {
  const Mechanism& m = *file.plan.machine.mechanism;
  bool revolute = m.jointCount() == 6;
  for (int j = 0; revolute && j < 6; ++j) revolute = m.jointKind(j) == JointKind::Revolute;
  if (!revolute || m.parameterIndex("j1.theta") < 0 || m.parameterIndex("probe.x") < 0)
    throw InputError(file.source, "/model",
                     "export-ur takes a serial-dh arm of 6 revolute joints (a UR arm's model)");
}

// FNV-1a of the values' text: the file's own hash (not the controller's checksum).
std::string hashOf(const std::string& text) {
  std::uint64_t h = 1469598103934665603ull;
  for (const unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "artcal_%016llx", static_cast<unsigned long long>(h));
  return buffer;
}

json poseJson(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d rpy = rpyFromMatrix(T.linear());
  return {{"xyz_mm", {T.translation().x(), T.translation().y(), T.translation().z()}},
          {"rpy_deg", {radToDeg(rpy[0]), radToDeg(rpy[1]), radToDeg(rpy[2])}}};
}

}  // namespace

MachineExport urKinematicsExport(const MachineFile& file) {
  requireUrArm(file);
  const Machine& machine = file.plan.machine;
  const bool modified = file.document.value("convention", std::string("standard")) == "modified";
  const DhOrigins dh_origins = dhOrigins(machine, modified);
  static const char* kNames[] = {"shoulder", "upper_arm", "forearm",
                                 "wrist_1",  "wrist_2",   "wrist_3"};
  std::ostringstream body;
  json values = json::array();
  for (std::size_t i = 0; i < 6; ++i) {
    const Eigen::Isometry3d& O = dh_origins.origins[i];
    const Eigen::Vector3d xyz = O.translation() / 1000.0, rpy = rpyFromMatrix(O.linear());
    body << "  " << kNames[i] << ":\n";
    const char* keys[] = {"x", "y", "z", "roll", "pitch", "yaw"};
    const double numbers[] = {xyz[0], xyz[1], xyz[2], rpy[0], rpy[1], rpy[2]};
    for (int k = 0; k < 6; ++k) body << "    " << keys[k] << ": " << numberText(numbers[k]) << "\n";
    values.push_back({{"name", kNames[i]},
                      {"xyz_m", {xyz[0], xyz[1], xyz[2]}},
                      {"rpy_rad", {rpy[0], rpy[1], rpy[2]}}});
  }
  const Eigen::Vector3d probe(machine.nominal[machine.mechanism->parameterIndex("probe.x")],
                              machine.nominal[machine.mechanism->parameterIndex("probe.y")],
                              machine.nominal[machine.mechanism->parameterIndex("probe.z")]);
  const Eigen::Isometry3d tcp = dh_origins.tail * shift(probe);
  const std::string hash = hashOf(body.str());
  json not_carried = json::array(
      {{{"name", "tcp"},
        {"pose", poseJson(tcp)},
        {"why",
         "the fixed transform from wrist_3_link (after the last joint's turn) to the probe "
         "centre: a kinematics_config holds joint origins only; set it as the tool (TCP)"}},
       {{"name", "uncertainty"},
        {"why", "the format has no place for u: the machine file's covariance"}},
       {{"name", "controller"},
        {"why",
         "the file changes the ROS description (ur_description's URDF) only; the robot "
         "controller keeps its own calibration, and ur_robot_driver reports that this "
         "hash differs from the controller's checksum"}}});
  std::ostringstream text;
  text << "# artcal export-ur of " << file.source
       << ": Universal Robots kinematics_config (ur_description, ur_robot_driver)\n"
       << "# joint origins of the calibrated arm, metres and radians\n"
       << "# NOT CARRIED: the TCP, wrist_3_link to the probe centre: xyz "
       << triple(not_carried[0]["pose"]["xyz_mm"]) << " mm, rpy "
       << triple(not_carried[0]["pose"]["rpy_deg"])
       << " deg (set it as the tool); the uncertainties; the controller's own calibration\n"
       << "kinematics:\n"
       << body.str() << "  hash: " << hash << "\n";
  MachineExport out;
  out.text = text.str();
  out.summary = {{"format", "ur-kinematics-config"},
                 {"hash", hash},
                 {"values", values},
                 {"not_carried", not_carried}};
  return out;
}

std::string exportSummaryTable(const json& summary) {
  std::ostringstream out;
  out << "export " << summary.at("format").get<std::string>() << ":\n";
  for (const json& v : summary.at("values")) {
    if (v.contains("pin")) {
      out << "  " << v["pin"].get<std::string>() << " = " << numberText(v["value"].get<double>())
          << " mm  (" << v["from"].get<std::string>() << "; " << statusText(v, "mm") << ")\n";
    } else {  // a joint origin: UR's by "name", xacro's by "joint"
      const std::string name =
          v.contains("joint") ? v["joint"].get<std::string>() : v["name"].get<std::string>();
      out << "  " << name << ": xyz " << triple(v["xyz_m"]) << " m, rpy " << triple(v["rpy_rad"])
          << " rad\n";
    }
  }
  out << "not carried by this format:\n";
  for (const json& e : summary.at("not_carried")) {
    out << "  " << e["name"].get<std::string>();
    if (e.contains("value"))
      out << " = " << numberText(e["value"].get<double>()) << " " << e["unit"].get<std::string>()
          << " (" << statusText(e, e["unit"].get<std::string>()) << ")";
    if (e.contains("pose"))
      out << ": xyz " << triple(e["pose"]["xyz_mm"]) << " mm, rpy " << triple(e["pose"]["rpy_deg"])
          << " deg";
    out << ": " << e["why"].get<std::string>() << "\n";
  }
  return out.str();
}

}  // namespace artcal
