// import-urdf --compliance (docs/compliance.md section 1): the links' <inertial> masses folded
// into the moving links (behind fixed joints on the chain, off the chain, an inertial rpy that
// does not move the centre, the base's mass ignored), and the chain's gravity torques with a
// payload against explicit cross products written here from the URDF's own numbers.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "artcal/io/calibrated_urdf.hpp"
#include "artcal/io/chain_codec.hpp"
#include "artcal/io/urdf.hpp"
#include "artcal/model/joint_compliance.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace urdf_compliance_test {

const std::string kUrdf = std::string(ARTCAL_TEST_DATA) + "/urdf/arm3-masses.urdf";

Eigen::Isometry3d translation(double x, double y, double z) {
  return Eigen::Isometry3d(Eigen::Translation3d(x, y, z));
}
Eigen::Isometry3d turn(double angle, const Eigen::Vector3d& axis) {
  return Eigen::Isometry3d(Eigen::AngleAxisd(angle, axis));
}

TEST(UrdfCompliance, MassesFoldIntoTheMovingLinks) {
  const nlohmann::json machine = importUrdfWithCompliance(kUrdf, "base_link", {"tool"});
  const nlohmann::json& masses = machine.at("compliance").at("masses");
  EXPECT_FALSE(masses.contains("base_link"));
  EXPECT_EQ(masses.size(), 4u);  // j1, j2 (link2 + sensor), j3, tool_mount (tool + camera)
  EXPECT_DOUBLE_EQ(masses.at("j1").at("mass").get<double>(), 4.0);
  const auto centre = [&](const char* joint, int i) {
    return masses.at(joint).at("centre")[static_cast<std::size_t>(i)].get<double>();
  };
  EXPECT_NEAR(centre("j1", 0), 10.0, 1e-9);  // the inertial's rpy does not move it
  EXPECT_NEAR(centre("j1", 1), 20.0, 1e-9);
  EXPECT_NEAR(centre("j1", 2), 80.0, 1e-9);
  // link2 (3 kg at 150, 0, 20) and the sensor (0.5 kg: 50, 20, 0 then Rz(90) of 0, 0, 10).
  EXPECT_DOUBLE_EQ(masses.at("j2").at("mass").get<double>(), 3.5);
  EXPECT_NEAR(centre("j2", 0), (3.0 * 150 + 0.5 * 50) / 3.5, 1e-9);
  EXPECT_NEAR(centre("j2", 1), (0.5 * 20) / 3.5, 1e-9);
  EXPECT_NEAR(centre("j2", 2), (3.0 * 20 + 0.5 * 10) / 3.5, 1e-9);
  EXPECT_NEAR(masses.at("tool_mount").at("mass").get<double>(), 1.1, 1e-12);
  EXPECT_NEAR(centre("tool_mount", 0), 0.3 * 20 / 1.1, 1e-9);
  EXPECT_NEAR(centre("tool_mount", 1), 0.3 * 50 / 1.1, 1e-9);
  EXPECT_NEAR(centre("tool_mount", 2), 0.8 * 30 / 1.1, 1e-9);
}

// tau_i = sum over the bodies beyond joint i of ((r_k - o_i) x m_k g) . z_i (metres), every
// frame built here from the URDF's numbers.
Eigen::Vector3d explicitTorques(const Eigen::Vector3d& q, double payload_mass,
                                const Eigen::Vector3d& payload_centre_m) {
  const Eigen::Vector3d g(0, 0, -9.81);
  const Eigen::Isometry3d F1 = translation(0, 0, 0.1) * turn(q[0], Eigen::Vector3d::UnitZ());
  const Eigen::Isometry3d F2_fixed =
      F1 * translation(0, 0, 0.2) * turn(0.1, Eigen::Vector3d::UnitX());
  const Eigen::Isometry3d F2 = F2_fixed * turn(q[1], Eigen::Vector3d::UnitY());
  const Eigen::Isometry3d F3 = F2 * translation(0.3, 0, 0) * turn(q[2], Eigen::Vector3d::UnitY());
  const Eigen::Isometry3d tool = F3 * translation(0.2, 0, 0) * turn(0.5, Eigen::Vector3d::UnitY());
  const Eigen::Isometry3d sensor =
      F2 * translation(0.05, 0.02, 0) * turn(std::numbers::pi / 2, Eigen::Vector3d::UnitZ());
  struct Body {
    Eigen::Vector3d r;
    double m;
    int beyond;  // the last joint (0-based) that moves it
  };
  const std::vector<Body> bodies = {
      {F1 * Eigen::Vector3d(0.01, 0.02, 0.08), 4.0, 0},
      {F2 * Eigen::Vector3d(0.15, 0.0, 0.02), 3.0, 1},
      {sensor * Eigen::Vector3d(0, 0, 0.01), 0.5, 1},
      {F3 * Eigen::Vector3d(0.1, 0.01, 0.0), 2.0, 2},
      {tool * Eigen::Vector3d(0, 0, 0.03), 0.8, 2},
      {tool * translation(0, 0.05, 0) * Eigen::Vector3d(0.02, 0, 0), 0.3, 2},
      {tool * payload_centre_m, payload_mass, 2}};
  const Eigen::Vector3d o[3] = {Eigen::Vector3d(0, 0, 0.1), F1 * Eigen::Vector3d(0, 0, 0.2),
                                F2 * Eigen::Vector3d(0.3, 0, 0)};
  const Eigen::Vector3d z[3] = {Eigen::Vector3d::UnitZ(),
                                F2_fixed.linear() * Eigen::Vector3d::UnitY(),
                                F2.linear() * Eigen::Vector3d::UnitY()};
  Eigen::Vector3d tau = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i)
    for (const Body& b : bodies)
      if (b.beyond >= i) tau[i] += (b.r - o[i]).cross(b.m * g).dot(z[i]);
  return tau;
}

TEST(UrdfCompliance, ChainTorquesMatchExplicitCrossProducts) {
  const nlohmann::json machine = importUrdfWithCompliance(kUrdf, "base_link", {"tool"});
  const MachineBlock block = readChainMachine(machine, "arm3-masses");
  const JointCompliance* compliance = block.mechanism->jointCompliance();
  ASSERT_NE(compliance, nullptr);
  EXPECT_EQ(block.mechanism->parameters().back().name, "j3.compliance");
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> angle(-2.5, 2.5);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Vector3d q(angle(rng), angle(rng), angle(rng));
    const Payload payload{trial % 2 ? 2.5 : 0.0, Eigen::Vector3d(30.0, -10.0, 40.0)};
    const Eigen::VectorXd tau = compliance->gravityTorques(block.nominal, q, payload);
    const Eigen::Vector3d expected = explicitTorques(q, payload.mass, payload.centre / 1000.0);
    ASSERT_EQ(tau.size(), 3);
    EXPECT_GT(expected.cwiseAbs().maxCoeff(), 1.0);
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(tau[i], expected[i], 1e-9 * expected.cwiseAbs().maxCoeff())
          << "joint " << i + 1 << " trial " << trial;
  }
}

TEST(UrdfCompliance, ImportWithoutTheFlagCarriesNoCompliance) {
  EXPECT_FALSE(importUrdf(kUrdf, "base_link", std::string("tool")).contains("compliance"));
}

// A URDF cannot carry compliance (docs/compliance.md section 5): the export writes it apart.
TEST(UrdfCompliance, TheExportWritesTheCompliancesApart) {
  nlohmann::json machine = importUrdfWithCompliance(kUrdf, "base_link", {"tool"});
  machine["compliance"]["values"] = {{"j2", 0.0025}};
  const CalibratedUrdf urdf = calibratedUrdf(machine, "cal.json", kUrdf);
  // The URDF text gains nothing of it (its comments name the tests, once).
  const auto count = [](const std::string& text) {
    std::size_t n = 0;
    for (auto at = text.find("compliance"); at != std::string::npos;
         at = text.find("compliance", at + 1))
      ++n;
    return n;
  };
  std::ifstream in(kUrdf);
  const std::string original((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
  EXPECT_EQ(count(urdf.text), count(original));
  EXPECT_NE(urdf.compliance_yaml.find("j2: {compliance: 0.0025, unit: \"deg/(N m)\"}"),
            std::string::npos)
      << urdf.compliance_yaml;
  EXPECT_NE(urdf.compliance_yaml.find("j1: {compliance: 0,"), std::string::npos);
  EXPECT_TRUE(calibratedUrdf(importUrdf(kUrdf, "base_link", std::string("tool")), "cal.json", kUrdf)
                  .compliance_yaml.empty());
}

}  // namespace urdf_compliance_test
}  // namespace artcal
