// Exports users load (docs/exports.md): each file read back the way its consumer reads it, its
// forward kinematics written out here from the consumer's own formulas, reproduces the calibrated
// machine to 1e-9 mm (what the format carries); what it cannot carry is listed with its value.
//   - LinuxCNC xyzac-trt-kins: the HAL setp lines parsed, the forward map of LinuxCNC's
//     trtfuncs (default directions) transcribed: pos = r + Rz(-c) (Rx(-a) (J - r - d) + d),
//     r = rot-point, d = (0, y-offset, z-offset + tool-offset), J the joints.
//   - UR kinematics_config: the YAML parsed; ur_description's chain of joint origins (xyz m,
//     rpy = Rz(yaw) Ry(pitch) Rx(roll)), each followed by Rz(q_i), then the listed TCP.
//   - xacro properties: substituted into the URDF's joints by text, the URDF imported again.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <map>
#include <random>
#include <regex>
#include <sstream>

#include "artcal/core/error.hpp"
#include "artcal/io/calibrated_urdf.hpp"
#include "artcal/io/chain_codec.hpp"
#include "artcal/io/machine_covariance.hpp"
#include "artcal/io/machine_exports.hpp"
#include "artcal/io/plan_file.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/urdf.hpp"
#include "cli_runner.hpp"
#include "random_vectors.hpp"
#include "temp_folder.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace exports_test {

using nlohmann::json;

using test_support::randomVector;

Eigen::Vector3d tipOf(const Mechanism& m, const Eigen::VectorXd& p, const Eigen::VectorXd& q) {
  Eigen::VectorXd x;
  EXPECT_EQ(m.forward(p, q, x), ForwardStatus::Ok);
  return x;
}

// ---- LinuxCNC

// The setp lines of a HAL file: pin -> value.
std::map<std::string, double> setpValues(const std::string& hal) {
  std::map<std::string, double> out;
  std::istringstream in(hal);
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string setp, pin;
    double value = 0.0;
    if (words >> setp >> pin >> value && setp == "setp") out[pin] = value;
  }
  return out;
}

// LinuxCNC's xyzacKinematicsForward (trtfuncs.c, conventional-directions 0): joints (mm, deg)
// to the world position.
Eigen::Vector3d linuxcncForward(const std::map<std::string, double>& pins, double tool_offset,
                                const Eigen::Vector3d& xyz, double a_deg, double c_deg) {
  const auto pin = [&](const char* name) { return pins.at(std::string("xyzac-trt-kins.") + name); };
  const double xr = pin("x-rot-point"), yr = pin("y-rot-point"), zr = pin("z-rot-point");
  const double dy = pin("y-offset"), dz = pin("z-offset") + tool_offset;
  const double a = a_deg * std::numbers::pi / 180, c = c_deg * std::numbers::pi / 180;
  const double X = xyz.x(), Y = xyz.y(), Z = xyz.z();
  return {std::cos(c) * (X - xr) + std::sin(c) * std::cos(a) * (Y - dy - yr) +
              std::sin(c) * std::sin(a) * (Z - dz - zr) + std::sin(c) * dy + xr,
          -std::sin(c) * (X - xr) + std::cos(c) * std::cos(a) * (Y - dy - yr) +
              std::cos(c) * std::sin(a) * (Z - dz - zr) + std::cos(c) * dy + yr,
          -std::sin(a) * (Y - dy - yr) + std::cos(a) * (Z - dz - zr) + dz + zr};
}

// The trunnion plan's machine with `values` (file units) and `calibrated` names, and a
// covariance (file units) over those.
json trunnionMachineFile(const std::map<std::string, double>& values,
                         const std::vector<std::string>& calibrated, const Eigen::MatrixXd& V) {
  Plan plan = loadPlan(test_support::planFile("machine-tool-trunnion-2spheres.json"));
  Machine& m = plan.machine;
  Eigen::VectorXd p = m.nominal;
  for (const auto& [name, value] : values) {
    const int i = m.mechanism->parameterIndex(name);
    p[i] = fromFileUnit(m.mechanism->parameters()[static_cast<std::size_t>(i)].quantity, value);
  }
  m.calibrated.clear();
  for (const std::string& name : calibrated)
    m.calibrated.push_back(m.mechanism->parameterIndex(name));
  json file = machineToJson(m, p);
  file["covariance"] = {{"parameters", calibrated}, {"matrix", json::array()}};
  for (int r = 0; r < V.rows(); ++r) {
    json row = json::array();
    for (int c = 0; c < V.cols(); ++c) row.push_back(V(r, c));
    file["covariance"]["matrix"].push_back(row);
  }
  return file;
}

// The largest distance between LinuxCNC's position and artcal's tip in W shifted by the pivot and
// the tool length (the work offset LinuxCNC's world frame has from W: docs/exports.md).
double linuxcncLargestDifference(const MachineFile& file, const std::map<std::string, double>& pins,
                                 const Eigen::Vector3d& pivot) {
  const Machine& m = file.plan.machine;
  const double L = m.nominal[m.mechanism->parameterIndex("L")];
  double worst = 0.0;
  for (int k = 0; k < 30; ++k) {
    const Eigen::VectorXd r = randomVector(5, 100 + static_cast<std::uint64_t>(k), 1.0);
    Eigen::VectorXd q(5);
    q << 300 * r[0], 300 * r[1], 200 + 150 * r[2], degToRad(100 * r[3]), degToRad(180 * r[4]);
    const Eigen::Vector3d artcal =
        tipOf(*m.mechanism, m.nominal, q) + pivot + Eigen::Vector3d(0, 0, L);
    const Eigen::Vector3d joints = q.head<3>() + pivot;
    const Eigen::Vector3d lcnc = linuxcncForward(pins, L, joints, radToDeg(q[3]), radToDeg(q[4]));
    worst = std::max(worst, (lcnc - artcal).norm());
  }
  return worst;
}

TEST(MachineExports, LinuxcncRoundTripReproducesTheLineOffsetsAndListsWhatItCannotCarry) {
  const std::vector<std::string> names = {"E_Y0A", "E_Z0A", "E_X0C", "E_Y0C"};
  Eigen::MatrixXd V(4, 4);  // mm^2: E_Y0A and E_Y0C correlated
  V << 4e-6, 0, 0, 1.5e-6, 0, 1e-6, 0, 0, 0, 0, 2.25e-6, 0, 1.5e-6, 0, 0, 9e-6;
  const json document = trunnionMachineFile(
      {{"E_Y0A", 0.031}, {"E_Z0A", -0.022}, {"E_X0C", -0.043}, {"E_Y0C", 0.017}, {"L", 123.4}},
      names, V);
  const MachineFile file = readMachineFile(document, "cal.json");
  const Eigen::Vector3d pivot(250.0, -120.0, -400.0);
  const MachineExport e = linuxcncExport(file, pivot);
  const std::map<std::string, double> pins = setpValues(e.text);
  ASSERT_EQ(pins.size(), 5u) << e.text;
  EXPECT_NEAR(pins.at("xyzac-trt-kins.x-rot-point"), 250.0 - 0.043, 1e-12);
  EXPECT_NEAR(pins.at("xyzac-trt-kins.y-rot-point"), -120.0 + 0.017, 1e-12);
  EXPECT_NEAR(pins.at("xyzac-trt-kins.z-rot-point"), -400.0, 1e-12);
  EXPECT_NEAR(pins.at("xyzac-trt-kins.y-offset"), 0.031 - 0.017, 1e-15);
  EXPECT_NEAR(pins.at("xyzac-trt-kins.z-offset"), -0.022, 1e-15);
  EXPECT_LT(linuxcncLargestDifference(file, pins, pivot), 1e-9);
  // u of y-offset = E_Y0A - E_Y0C: var + var - 2 cov; U = 2 u.
  const json& y_offset = e.summary["values"][3];
  ASSERT_EQ(y_offset["pin"], "xyzac-trt-kins.y-offset");
  EXPECT_NEAR(y_offset["u"].get<double>(), std::sqrt(4e-6 + 9e-6 - 3e-6), 1e-15);
  EXPECT_NEAR(y_offset["U"].get<double>(), 2 * std::sqrt(10e-6), 1e-15);
  // Not carried: every other location error and L, with values and status; L not calibrated.
  std::map<std::string, json> listed;
  for (const json& entry : e.summary["not_carried"]) listed[entry["name"]] = entry;
  for (const char* name :
       {"E_B0A", "E_C0A", "E_A0A", "E_A0C", "E_B0C", "E_C0C", "E_C0Y", "E_B0Z", "E_A0Z", "L"})
    EXPECT_TRUE(listed.count(name)) << name;
  EXPECT_EQ(listed["L"]["status"], "not determined");
  EXPECT_DOUBLE_EQ(listed["L"]["value"].get<double>(), 123.4);
  EXPECT_NE(e.text.find("#   L = 123.4 mm (NOT DETERMINED"), std::string::npos) << e.text;
}

TEST(MachineExports, AnOrientationErrorLinuxcncCannotCarryIsListedAndMovesTheTip) {
  Eigen::MatrixXd V = Eigen::MatrixXd::Identity(2, 2) * 1e-10;
  const json document =
      trunnionMachineFile({{"E_X0C", -0.043}, {"E_B0A", 0.003}}, {"E_X0C", "E_B0A"}, V);
  const MachineFile file = readMachineFile(document, "cal.json");
  const MachineExport e = linuxcncExport(file, Eigen::Vector3d::Zero());
  const json& b0a = e.summary["not_carried"][0];
  EXPECT_EQ(b0a["name"], "E_B0A");
  EXPECT_EQ(b0a["status"], "determined");
  EXPECT_DOUBLE_EQ(b0a["value"].get<double>(), 0.003);
  EXPECT_NEAR(b0a["u"].get<double>(), 1e-5, 1e-15);      // sqrt(1e-10 deg^2)
  EXPECT_EQ(e.summary["values"][2]["status"], "given");  // z-rot-point: the pivot alone
  // 3 mdeg over a few hundred mm: microns LinuxCNC does not reproduce (the test can fail).
  EXPECT_GT(linuxcncLargestDifference(file, setpValues(e.text), Eigen::Vector3d::Zero()), 1e-3);
}

TEST(MachineExports, LinuxcncRefusesTheHeadTableMachine) {
  const Plan plan = loadPlan(test_support::planFile("machine-tool-head-table-2spheres.json"));
  const MachineFile file =
      readMachineFile(machineToJson(plan.machine, plan.machine.nominal), "head.json");
  EXPECT_THROW(linuxcncExport(file, Eigen::Vector3d::Zero()), InputError);
}

// ---- Universal Robots

// ur_description's kinematics: name -> {x, y, z, roll, pitch, yaw}.
std::map<std::string, std::map<std::string, double>> urYaml(const std::string& text) {
  std::map<std::string, std::map<std::string, double>> out;
  std::istringstream in(text);
  std::string current;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::smatch m;
    if (std::regex_match(line, m, std::regex("  ([a-z_0-9]+):\\s*"))) current = m[1];
    if (std::regex_match(line, m, std::regex("    ([a-z]+): (\\S+)")))
      out[current][m[1]] = std::stod(m[2]);
  }
  return out;
}

Eigen::Isometry3d urOrigin(const std::map<std::string, double>& o) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(o.at("x"), o.at("y"), o.at("z")) * 1000.0;
  T.linear() = (Eigen::AngleAxisd(o.at("yaw"), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(o.at("pitch"), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(o.at("roll"), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return T;
}

// The UR arm of `block` (a serial-dh machine block) with every parameter moved by up to 0.5 mm /
// 0.5 deg: the exported YAML's chain and the listed TCP against artcal's forward kinematics.
double urRoundTrip(json block, std::uint64_t seed) {
  const Plan base = readMachineFile(block, "ur.json").plan;
  Eigen::VectorXd p = base.machine.nominal;
  const Eigen::VectorXd delta = randomVector(static_cast<int>(p.size()), seed, 0.5);
  for (int i = 0; i < p.size(); ++i) {
    const bool angle =
        base.machine.mechanism->parameters()[static_cast<std::size_t>(i)].quantity.isAngle();
    p[i] += angle ? degToRad(delta[i]) : delta[i];
  }
  Machine m = base.machine;
  const MachineFile file = readMachineFile(machineToJson(m, p), "ur.json");
  const MachineExport e = urKinematicsExport(file);
  const auto yaml = urYaml(e.text);
  EXPECT_EQ(yaml.size(), 6u) << e.text;
  const json& tcp = e.summary["not_carried"][0]["pose"];
  EXPECT_EQ(e.summary["not_carried"][0]["name"], "tcp");
  Eigen::Isometry3d T_tcp = Eigen::Isometry3d::Identity();
  T_tcp.translation() = Eigen::Vector3d(tcp["xyz_mm"][0], tcp["xyz_mm"][1], tcp["xyz_mm"][2]);
  T_tcp.linear() = urOrigin({{"x", 0},
                             {"y", 0},
                             {"z", 0},
                             {"roll", degToRad(tcp["rpy_deg"][0].get<double>())},
                             {"pitch", degToRad(tcp["rpy_deg"][1].get<double>())},
                             {"yaw", degToRad(tcp["rpy_deg"][2].get<double>())}})
                       .linear();
  double worst = 0.0;
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = randomVector(6, seed + 10 + static_cast<std::uint64_t>(k), 3.0);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    int j = 0;
    for (const char* name : {"shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3"})
      T = T * urOrigin(yaml.at(name)) * Eigen::AngleAxisd(q[j++], Eigen::Vector3d::UnitZ());
    const Eigen::Vector3d ur = (T * T_tcp).translation();
    worst = std::max(worst, (ur - tipOf(*file.plan.machine.mechanism, p, q)).norm());
  }
  return worst;
}

TEST(MachineExports, UrKinematicsConfigRoundTripReproducesTheArm) {
  const json ur5 = readJsonFile(test_support::testDataFile("ur5-tracker/ur5.machine.json"));
  EXPECT_LT(urRoundTrip(ur5, 1), 1e-9);
  // Hayati betas on the parallel joints 2 and 3, and the modified convention with them.
  json beta = ur5;
  beta["joints"][1]["beta"] = 0.0;
  beta["joints"][2]["beta"] = 0.0;
  EXPECT_LT(urRoundTrip(beta, 2), 1e-9);
  beta["convention"] = "modified";
  EXPECT_LT(urRoundTrip(beta, 3), 1e-9);
}

TEST(MachineExports, UrExportRefusesAnArmThatIsNotSixRevoluteJoints) {
  json arm = readJsonFile(test_support::testDataFile("ur5-tracker/ur5.machine.json"));
  arm["joints"].erase(5);
  arm["joint_limits"].erase(5);
  EXPECT_THROW(urKinematicsExport(readMachineFile(arm, "arm5.json")), InputError);
}

// ---- xacro properties

class XacroExport : public test_support::TempFolder {
 protected:
  XacroExport() : TempFolder("xacro") {}
};

// The URDF text with joint `joint`'s origin replaced by xyz and rpy (text as given).
std::string withOrigin(std::string urdf, const std::string& joint, const std::string& xyz,
                       const std::string& rpy) {
  const std::size_t start = urdf.find("<joint name=\"" + joint + "\"");
  EXPECT_NE(start, std::string::npos) << joint;
  const std::size_t end = urdf.find("</joint>", start);
  const std::string element = urdf.substr(start, end - start);
  const std::string origin = "<origin xyz=\"" + xyz + "\" rpy=\"" + rpy + "\"/>";
  std::string replaced = std::regex_replace(element, std::regex("<origin[^>]*/>"), origin,
                                            std::regex_constants::format_first_only);
  if (replaced == element) replaced.insert(element.find('>') + 1, origin);
  return urdf.replace(start, end - start, replaced);
}

TEST_F(XacroExport, PropertiesSubstitutedIntoTheUrdfReproduceTheCalibratedMachine) {
  const std::string urdf = test_support::testDataFile("urdf/arm3-slide.urdf");
  const MachineBlock block = readChainMachine(importUrdf(urdf, "world", "probe"), "machine");
  Machine machine;
  machine.mechanism = block.mechanism;
  machine.nominal = block.nominal;
  machine.joint_limits.assign(static_cast<std::size_t>(block.mechanism->jointCount()), {-3.0, 3.0});
  for (int i = 0; i < block.mechanism->parameterCount(); ++i) machine.calibrated.push_back(i);
  const Eigen::VectorXd p =
      block.nominal + randomVector(static_cast<int>(block.nominal.size()), 7, 0.05);
  const XacroProperties x = calibratedXacro(machineToJson(machine, p), "cal.json", urdf);
  // Each property by name, then substituted in the joints the summary names.
  std::map<std::string, std::string> properties;
  const std::regex property("<xacro:property name=\"([A-Za-z0-9_]+)\" value=\"([^\"]*)\"/>");
  for (auto it = std::sregex_iterator(x.text.begin(), x.text.end(), property);
       it != std::sregex_iterator(); ++it)
    properties[(*it)[1]] = (*it)[2];
  std::ifstream in(urdf);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GE(x.summary["values"].size(), 6u);
  for (const json& v : x.summary["values"]) {
    text = withOrigin(text, v["joint"], properties.at(v["xyz_property"]),
                      properties.at(v["rpy_property"]));
  }
  const std::string out = write("substituted.urdf", text);
  const MachineBlock again = readChainMachine(importUrdf(out, "world", "probe"), "machine");
  double worst = 0.0;
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = randomVector(block.mechanism->jointCount(), 40 + k, 2.0);
    worst = std::max(
        worst, (tipOf(*block.mechanism, p, q) - tipOf(*again.mechanism, again.nominal, q)).norm());
  }
  EXPECT_LT(worst, 1e-9);
}

}  // namespace exports_test
}  // namespace artcal

namespace artcal {
namespace exports_test {

class ExportCli : public test_support::TempFolder {
 protected:
  ExportCli() : TempFolder("export-cli") {}
};

// Bad input: exit 2, one line naming the file and what to check, no output file.
TEST_F(ExportCli, AMachineTheFormatCannotHoldIsOneLineAndExitStatus2) {
  const Plan head = loadPlan(test_support::planFile("machine-tool-head-table-2spheres.json"));
  write("head.json", machineToJson(head.machine, head.machine.nominal).dump());
  const std::string ur5 = test_support::testDataFile("ur5-tracker/ur5.machine.json");
  const std::pair<std::string, std::string> cases[] = {
      {"export-linuxcnc --machine " + path("head.json") + " --pivot 0 0 0 -o " + path("x.hal"),
       "head.json: /configuration: LinuxCNC's tilting-table kinematics"},
      {"export-ur --machine " + path("head.json") + " -o " + path("x.yaml"),
       "head.json: /model: export-ur takes a serial-dh arm of 6 revolute joints"},
      {"export-linuxcnc --machine " + ur5 + " --pivot 0 0 0 -o " + path("x.hal"),
       "ur5.machine.json: /model: export-linuxcnc takes a five-axis machine tool"},
      {"export-xacro --machine " + ur5 + " --urdf " +
           test_support::testDataFile("urdf/arm3-slide.urdf") + " -o " + path("x.xacro"),
       "ur5.machine.json"}};
  for (const auto& [arguments, expected] : cases) {
    const test_support::CliRun run = test_support::runCli(arguments, test_support::Stderr::Only);
    EXPECT_EQ(run.status, 2) << arguments;
    EXPECT_NE(run.out.find(expected), std::string::npos) << run.out;
    EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1) << run.out;
  }
  for (const char* name : {"x.hal", "x.yaml", "x.xacro"})
    EXPECT_FALSE(std::filesystem::exists(path(name))) << name;
}

}  // namespace exports_test
}  // namespace artcal
