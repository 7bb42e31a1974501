// URDF import and export of the chain model (models.md section 1): the imported Panda equals the
// reference plan's chain; an exported URDF read back has the calibrated machine's forward
// kinematics to 1e-9 mm (offsets folded, also into joints off the chain) and keeps everything
// else of the input; bad input answers with one line and exit status 2.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <tuple>

#include "artcal/io/chain_codec.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/urdf.hpp"
#include "cli_runner.hpp"
#include "random_vectors.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace urdf_test {

using test_support::runCli;
using test_support::Stderr;

const std::string kData = ARTCAL_TEST_DATA;
const std::string kPandaUrdf = kData + "/mukca/mukca/urdf/panda.urdf";
const std::string kSmallUrdf = kData + "/urdf/arm3-slide.urdf";

MachineBlock readMachine(const nlohmann::json& block) {
  return readChainMachine(block, "machine");
}

const Chain& chainOf(const MachineBlock& block) {
  return static_cast<const Chain&>(*block.mechanism);
}

using test_support::randomVector;

Eigen::Vector3d tip(const Mechanism& model, const Eigen::VectorXd& p, const Eigen::VectorXd& q) {
  Eigen::VectorXd x;
  forwardOrThrow(model, p, q, x);
  return x;
}

// Largest distance between the two models' tips over seeded configurations.
double largestTipDifference(const Mechanism& a, const Eigen::VectorXd& pa, const Mechanism& b,
                            const Eigen::VectorXd& pb, std::uint64_t seed) {
  EXPECT_EQ(a.jointCount(), b.jointCount());
  double worst = 0.0;
  for (int c = 0; c < 20; ++c) {
    const Eigen::VectorXd q = randomVector(a.jointCount(), seed + c, 3.0);
    worst = std::max(worst, (tip(a, pa, q) - tip(b, pb, q)).norm());
  }
  return worst;
}

std::string temporaryPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          (name + "-" + std::to_string(::getpid()) + ".urdf"))
      .string();
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

TEST(UrdfImport, PandaEqualsTheReferencePlansChain) {
  const nlohmann::json machine = importUrdf(kPandaUrdf, "panda_link0", "ball_link");
  const Plan reference = loadPlan(kData + "/ref-chain-panda-2placements.json");
  const nlohmann::json document = readJsonFile(kData + "/ref-chain-panda-2placements.json");
  const nlohmann::json& expected = document["machine"];
  ASSERT_EQ(machine["joints"].size(), expected["joints"].size());
  for (std::size_t i = 0; i < expected["joints"].size(); ++i) {
    const auto& got = machine["joints"][i];
    const auto& want = expected["joints"][i];
    EXPECT_EQ(got["name"], want["name"]);
    EXPECT_EQ(got["type"], want["type"]);
    for (int c = 0; c < 3; ++c) {
      // The reference rounds the ball's offset to 1e-9 mm.
      EXPECT_NEAR(got["origin"]["xyz"][c].get<double>(), want["origin"]["xyz"][c].get<double>(),
                  1e-9);
      EXPECT_NEAR(got["origin"]["rpy"][c].get<double>(), want["origin"]["rpy"][c].get<double>(),
                  1e-12);
    }
  }
  // Metres become mm exactly as the decimal says.
  EXPECT_EQ(machine["joints"][0]["origin"]["xyz"][2].get<double>(), 333.0);
  EXPECT_EQ(machine["joints"][4]["origin"]["xyz"][0].get<double>(), -82.5);
  ASSERT_EQ(machine["joint_limits"].size(), 7u);
  for (std::size_t j = 0; j < 7; ++j) {
    for (std::size_t e = 0; e < 2; ++e) {
      EXPECT_NEAR(machine["joint_limits"][j][e].get<double>(),
                  expected["joint_limits"][j][e].get<double>(), 1e-6);
    }
  }
  EXPECT_EQ(machine["calibrate"], "identifiable");
  const MachineBlock block = readMachine(machine);
  EXPECT_LT(largestTipDifference(chainOf(block), block.nominal, *reference.machine.mechanism,
                                 reference.machine.nominal, 1),
            2e-9);
}

TEST(UrdfImport, ContinuousAndPrismaticJointsAndLimits) {
  const nlohmann::json machine = importUrdf(kSmallUrdf, "world", "probe");
  const auto& joints = machine["joints"];
  ASSERT_EQ(joints.size(), 6u);
  EXPECT_EQ(joints[0]["name"], "mount");  // no <origin>: zeros
  EXPECT_EQ(joints[0]["origin"]["xyz"], nlohmann::json::array({0.0, 0.0, 0.0}));
  EXPECT_EQ(joints[3]["type"], "prismatic");
  EXPECT_EQ(joints[4]["type"], "revolute");  // continuous
  EXPECT_EQ(joints[1]["origin"]["xyz"][2].get<double>(), 300.0);
  const auto& limits = machine["joint_limits"];
  ASSERT_EQ(limits.size(), 4u);
  EXPECT_DOUBLE_EQ(limits[2][1].get<double>(), 250.0);  // prismatic, m -> mm
  EXPECT_DOUBLE_EQ(limits[3][0].get<double>(), -180.0);
  EXPECT_DOUBLE_EQ(limits[0][1].get<double>(), radToDeg(3.0));
}

// A calibrated machine: every origin value and offset moved by up to `size` (mm or rad).
Eigen::VectorXd calibrated(const MachineBlock& block, double size, std::uint64_t seed) {
  return block.nominal + randomVector(static_cast<int>(block.nominal.size()), seed, size);
}

// Exports `p` into `urdf`, imports the result again and compares forward kinematics.
void expectRoundTrip(const std::string& urdf, const std::string& base, const std::string& tip_link,
                     double size, std::uint64_t seed) {
  const MachineBlock block = readMachine(importUrdf(urdf, base, tip_link));
  const Eigen::VectorXd p = calibrated(block, size, seed);
  const std::string out = temporaryPath("roundtrip");
  writeText(out, exportUrdf(chainOf(block), p, urdf, "machine"));
  const MachineBlock again = readMachine(importUrdf(out, base, tip_link));
  std::filesystem::remove(out);
  EXPECT_LT(largestTipDifference(chainOf(block), p, chainOf(again), again.nominal, seed), 1e-9);
}

TEST(UrdfExport, PandaRoundTripKeepsTheCalibratedForwardKinematics) {
  expectRoundTrip(kPandaUrdf, "panda_link0", "ball_link", 0.02, 10);
  expectRoundTrip(kPandaUrdf, "panda_link0", "ball_link", 0.5, 20);  // large tilts too
}

TEST(UrdfExport, SmallArmRoundTripWithPrismaticAndGimbalLockOrigins) {
  expectRoundTrip(kSmallUrdf, "world", "probe", 0.05, 30);
  expectRoundTrip(kSmallUrdf, "world", "probe", 1.0, 40);
}

// j3's origin has rpy (0, 90, 0) deg, as a UR's shoulder and wrist do. Calibrated to a pitch past
// 90 deg it is written with that pitch and the small roll and yaw (the machine's own values), not
// as the other triple of the same rotation, (roll - 180, 180 - pitch, yaw - 180), which
// rpyFromMatrix gives (|pitch| <= 90) and a diff of the URDFs would show as two half turns.
// Below 90 deg likewise; the forward kinematics round-trips either way.
TEST(UrdfExport, AnOriginCalibratedPastPitch90KeepsItsOwnRollPitchYaw) {
  const MachineBlock block = readMachine(importUrdf(kSmallUrdf, "world", "probe"));
  const Chain& chain = chainOf(block);
  int j3 = -1;
  for (int i = 0; i < static_cast<int>(chain.joints().size()); ++i)
    if (chain.joints()[static_cast<std::size_t>(i)].name == "j3") j3 = i;
  ASSERT_GE(j3, 0);
  const int k = chain.parameterOffset(j3) + 3;
  ASSERT_DOUBLE_EQ(block.nominal[k + 1], std::numbers::pi / 2);
  for (const double pitch_deg : {90.7, 89.3, 135.0, -95.0}) {
    SCOPED_TRACE(pitch_deg);
    Eigen::VectorXd p = block.nominal;
    const Eigen::Vector3d rpy(degToRad(0.05), degToRad(pitch_deg), degToRad(-0.08));
    p.segment<3>(k) = rpy;
    const std::string out = temporaryPath("pitch");
    writeText(out, exportUrdf(chain, p, kSmallUrdf, "machine"));
    const nlohmann::json again = importUrdf(out, "world", "probe");
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(degToRad(again["joints"][j3]["origin"]["rpy"][c].get<double>()), rpy[c], 1e-12)
          << c;
    }
    const MachineBlock exported = readMachine(again);
    std::filesystem::remove(out);
    EXPECT_LT(largestTipDifference(chain, p, chainOf(exported), exported.nominal, 80), 1e-9);
  }
}

// The wrist's offset is folded into the origin of every joint hanging from its link, the
// finger's too, which is off the calibrated chain: the finger moves as on the calibrated robot.
TEST(UrdfExport, OffsetIsFoldedIntoJointsOffTheChain) {
  const MachineBlock block = readMachine(importUrdf(kSmallUrdf, "world", "probe"));
  const Eigen::VectorXd p = calibrated(block, 0.05, 50);
  const std::string out = temporaryPath("finger");
  writeText(out, exportUrdf(chainOf(block), p, kSmallUrdf, "machine"));
  // The original URDF's chain to the finger with the calibrated values where the chains share
  // joints (all but the last), against the exported file's chain to the finger.
  const MachineBlock finger = readMachine(importUrdf(kSmallUrdf, "world", "finger"));
  Eigen::VectorXd p_finger = finger.nominal;
  const int shared = chainOf(block).parameterOffset(5);  // mount .. j4, before "tool"
  p_finger.head(shared) = p.head(shared);
  const MachineBlock exported = readMachine(importUrdf(out, "world", "finger"));
  std::filesystem::remove(out);
  ASSERT_EQ(chainOf(finger).jointCount(), 5);
  EXPECT_LT(
      largestTipDifference(chainOf(finger), p_finger, chainOf(exported), exported.nominal, 60),
      1e-9);
}

TEST(UrdfExport, EverythingButTheChainsOriginsIsKept) {
  const MachineBlock block = readMachine(importUrdf(kSmallUrdf, "world", "probe"));
  const std::string text =
      exportUrdf(chainOf(block), calibrated(block, 0.01, 70), kSmallUrdf, "machine");
  for (const char* kept :
       {"A small test robot", "tilted shoulder: the origin carries roll and pitch",
        "package://arm3/meshes/base.stl", "scale=\"0.001 0.001 0.001\"",
        "<origin xyz=\"0 0 0.05\" rpy=\"0 0 0\"/>", "transmission_interface/SimpleTransmission",
        "EffortJointInterface", "Gazebo/Grey", "rgba=\"0.5 0.5 0.5 1\"",
        "<limit lower=\"0.0\" upper=\"0.25\" effort=\"10\" velocity=\"0.1\"/>",
        "<axis xyz=\"0.6 0 0.8\"/>"}) {
    EXPECT_NE(text.find(kept), std::string::npos) << kept;
  }
  // The joint without an <origin> got one (its values changed).
  const std::size_t mount = text.find("<joint name=\"mount\"");
  ASSERT_NE(mount, std::string::npos);
  EXPECT_LT(text.find("<origin", mount), text.find("</joint>", mount));
}

std::string fileText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::vector<std::string> linesOf(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// The nominal machine exported is the input file, byte for byte.
TEST(UrdfExport, NominalMachineReproducesTheInputFile) {
  const MachineBlock block = readMachine(importUrdf(kPandaUrdf, "panda_link0", "ball_link"));
  EXPECT_EQ(exportUrdf(chainOf(block), block.nominal, kPandaUrdf, "machine"), fileText(kPandaUrdf));
  const MachineBlock small = readMachine(importUrdf(kSmallUrdf, "world", "probe"));
  EXPECT_EQ(exportUrdf(chainOf(small), small.nominal, kSmallUrdf, "machine"), fileText(kSmallUrdf));
}

// A diff of input and output shows the calibrated joints' origin lines only: the Panda with
// joints 2 and 5 calibrated (their origin values moved) has every other line byte-identical, the
// same number of lines, and each changed line is an <origin> inside joint 2's or 5's element.
TEST(UrdfExport, TheOutputDiffersFromTheInputInTheCalibratedJointsOriginsOnly) {
  const MachineBlock block = readMachine(importUrdf(kPandaUrdf, "panda_link0", "ball_link"));
  const Chain& chain = chainOf(block);
  Eigen::VectorXd p = block.nominal;
  const std::set<std::string> calibrated = {"panda_joint2", "panda_joint5"};
  for (const std::string& name : calibrated) {
    int joint = -1;
    for (int i = 0; i < static_cast<int>(chain.joints().size()); ++i)
      if (chain.joints()[static_cast<std::size_t>(i)].name == name) joint = i;
    ASSERT_GE(joint, 0) << name;
    p.segment<6>(chain.parameterOffset(joint)) += randomVector(6, 90 + joint, 0.01);
  }
  const std::string input = fileText(kPandaUrdf);
  const std::string output = exportUrdf(chain, p, kPandaUrdf, "machine");
  const std::vector<std::string> a = linesOf(input), b = linesOf(output);
  ASSERT_EQ(a.size(), b.size());
  int changed = 0;
  std::string joint;  // the joint element the line lies in
  for (std::size_t i = 0; i < a.size(); ++i) {
    std::smatch name;
    if (std::regex_search(a[i], name, std::regex("<joint name=\"([^\"]+)\""))) joint = name[1];
    if (a[i].find("</joint>") != std::string::npos) joint.clear();
    if (a[i] == b[i]) continue;
    ++changed;
    EXPECT_TRUE(calibrated.count(joint)) << "line " << i + 1 << ": " << b[i];
    EXPECT_NE(b[i].find("<origin"), std::string::npos) << b[i];
  }
  EXPECT_EQ(changed, 2);
  const std::string out = temporaryPath("diff");
  writeText(out, output);
  const MachineBlock again = readMachine(importUrdf(out, "panda_link0", "ball_link"));
  std::filesystem::remove(out);
  EXPECT_LT(largestTipDifference(chain, p, chainOf(again), again.nominal, 95), 1e-9);
}

// The scanner edits what tinyxml2 reads and nothing else: a joint named in a comment and in a
// CDATA section keeps that text; CRLF line ends stay; an <origin> with xyz only gets rpy added
// after its last attribute; a joint with no <origin> gets one on a line of its own, indented
// below the joint; the result round-trips the forward kinematics.
TEST(UrdfExport, CommentsCrlfAndMissingAttributesAreEditedInPlace) {
  const std::string input =
      "<?xml version=\"1.0\"?>\r\n<robot name='r'>\r\n"
      "  <!-- <joint name=\"a\"><origin xyz=\"9 9 9\"/></joint> -->\r\n"
      "  <link name=\"l0\"/><link name=\"l1\"/><link name=\"l2\"/>\r\n"
      "  <joint name=\"a\" type=\"revolute\">\r\n"
      "    <parent link=\"l0\"/><child link=\"l1\"/>\r\n"
      "    <axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>\r\n"
      "  </joint>\r\n"
      "  <gazebo><![CDATA[ <joint name=\"b\"><origin xyz=\"7 7 7\"/></joint> ]]></gazebo>\r\n"
      "  <joint name=\"b\" type=\"fixed\">\r\n"
      "    <parent link=\"l1\"/><child link=\"l2\"/>\r\n"
      "    <origin   xyz='0.1 0 0' />\r\n"
      "  </joint>\r\n</robot>\r\n";
  const std::string in = temporaryPath("crlf-in");
  writeText(in, input);
  const MachineBlock block = readMachine(importUrdf(in, "l0", "l2"));
  const Eigen::VectorXd p = calibrated(block, 0.02, 97);
  const std::string output = exportUrdf(chainOf(block), p, in, "machine");
  EXPECT_NE(output.find("<!-- <joint name=\"a\"><origin xyz=\"9 9 9\"/></joint> -->\r\n"),
            std::string::npos);
  EXPECT_NE(output.find("<![CDATA[ <joint name=\"b\"><origin xyz=\"7 7 7\"/></joint> ]]>"),
            std::string::npos);
  EXPECT_NE(output.find("<joint name=\"a\" type=\"revolute\">\r\n    <origin xyz=\""),
            std::string::npos)
      << output;
  EXPECT_TRUE(std::regex_search(output, std::regex("<origin   xyz='[^']*' rpy=\"[^\"]*\" />")))
      << output;
  EXPECT_EQ(output.find("\n\n"), std::string::npos);
  for (std::size_t at = output.find('\n'); at != std::string::npos; at = output.find('\n', at + 1))
    EXPECT_EQ(output[at - 1], '\r') << at;
  const std::string out = temporaryPath("crlf-out");
  writeText(out, output);
  const MachineBlock again = readMachine(importUrdf(out, "l0", "l2"));
  std::filesystem::remove(in);
  std::filesystem::remove(out);
  EXPECT_LT(largestTipDifference(chainOf(block), p, chainOf(again), again.nominal, 98), 1e-9);
}

// ---- the command line

// Chains that run against the URDF tree (docs/urdf.md): a chain imported from a link up to a
// common ancestor and down again equals, to 1e-12 mm, the same chain written downward by hand:
// the two downward chains from the ancestor, imported the ordinary way, composed here as
// T(ancestor -> base)^-1 T(ancestor -> tip) with Eigen's inverse, at the same (perturbed)
// parameters, mapped by name, and the same readings.
const std::string kHumanoidUrdf = kData + "/urdf/humanoid-small.urdf";

Eigen::Isometry3d poseOf(const Chain& chain, const Eigen::VectorXd& p, const Eigen::VectorXd& q) {
  Eigen::VectorXd x;
  Eigen::Matrix3d R;
  EXPECT_EQ(chain.forwardPose(p, q, x, R), ForwardStatus::Ok);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = x;
  return T;
}

// `from`'s parameters and readings copied by name into `to`'s (every name must be found).
Eigen::VectorXd byName(const Chain& from, const Eigen::VectorXd& values, const Chain& to,
                       const Eigen::VectorXd& to_values, bool readings) {
  Eigen::VectorXd out = to_values;
  const int n = readings ? to.jointCount() : to.parameterCount();
  for (int i = 0; i < n; ++i) {
    int k = -1;
    if (readings) {
      for (int r = 0; r < from.jointCount(); ++r)
        if (from.readings()[static_cast<std::size_t>(r)].name ==
            to.readings()[static_cast<std::size_t>(i)].name)
          k = r;
    } else {
      k = from.parameterIndex(to.parameters()[static_cast<std::size_t>(i)].name);
    }
    EXPECT_GE(k, 0) << i;
    if (k >= 0) out[i] = values[k];
  }
  return out;
}

// The largest distance (mm) between the imported chain `base` -> `tip` and the hand-written
// T(ancestor -> base)^-1 T(ancestor -> tip), over seeded readings and parameters moved by up
// to `size` (mm, rad; offsets included).
double upwardChainAgainstHand(const std::string& urdf, const std::string& ancestor,
                              const std::string& base, const std::string& tip_link, double size,
                              std::uint64_t seed) {
  const MachineBlock up = readMachine(importUrdf(urdf, base, tip_link));
  const MachineBlock to_base = readMachine(importUrdf(urdf, ancestor, base));
  const bool tip_is_ancestor = tip_link == ancestor;
  const MachineBlock to_tip =
      tip_is_ancestor ? to_base : readMachine(importUrdf(urdf, ancestor, tip_link));
  double worst = 0.0;
  for (int c = 0; c < 10; ++c) {
    const Eigen::VectorXd p = calibrated(up, size, seed + c);
    const Eigen::VectorXd q = randomVector(chainOf(up).jointCount(), seed + 100 + c, 2.5);
    const auto hand = [&](const MachineBlock& down) {
      return poseOf(chainOf(down), byName(chainOf(up), p, chainOf(down), down.nominal, false),
                    byName(chainOf(up), q, chainOf(down),
                           Eigen::VectorXd::Zero(chainOf(down).jointCount()), true));
    };
    const Eigen::Isometry3d expected =
        hand(to_base).inverse() * (tip_is_ancestor ? Eigen::Isometry3d::Identity() : hand(to_tip));
    worst = std::max(worst, (tip(chainOf(up), p, q) - expected.translation()).norm());
  }
  return worst;
}

TEST(UrdfTree, AChainUpTheTreeEqualsTheInverseWrittenByHand) {
  // The humanoid standing on its left sole, to its left gripper: six leg joints and the sole's
  // fixed joint run upward (roll, pitch and yaw in their origins), then torso and arm downward.
  const nlohmann::json machine =
      importUrdf(kHumanoidUrdf, "left_sole_link", "gripper_left_base_link");
  ASSERT_EQ(machine["joints"].size(), 14u);
  EXPECT_EQ(machine["joints"][0]["name"], "left_sole_joint");
  EXPECT_EQ(machine["joints"][0]["reversed"], true);
  EXPECT_EQ(machine["joints"][6]["name"], "leg_left_1_joint");
  EXPECT_EQ(machine["joints"][6]["reversed"], true);
  EXPECT_FALSE(machine["joints"][7].contains("reversed"));  // torso_1_joint, downward
  // The readings are the URDF's joint values, in chain order (leg from the ankle up).
  EXPECT_EQ(chainOf(readMachine(machine)).readings().front().name, "leg_left_6_joint");
  EXPECT_LT(upwardChainAgainstHand(kHumanoidUrdf, "base_link", "left_sole_link",
                                   "gripper_left_base_link", 0.0, 1),
            1e-12);
  EXPECT_LT(upwardChainAgainstHand(kHumanoidUrdf, "base_link", "left_sole_link",
                                   "gripper_left_base_link", 0.05, 2),
            1e-12);
  // From one sole to the other: up one leg, down the other.
  EXPECT_LT(upwardChainAgainstHand(kHumanoidUrdf, "base_link", "left_sole_link", "right_sole_link",
                                   0.05, 3),
            1e-12);
  // A reversed prismatic joint and a reversed continuous one with a gimbal-locked origin: the
  // small arm from its finger up to the world (all upward), and across to its probe.
  EXPECT_LT(upwardChainAgainstHand(kSmallUrdf, "world", "finger", "world", 0.05, 4), 1e-12);
  EXPECT_LT(upwardChainAgainstHand(kSmallUrdf, "probe_mount", "finger", "probe", 0.05, 5), 1e-12);
}

TEST(UrdfTree, ExportOfAnUpwardChainRoundTripsItsCorrections) {
  // Every origin and every offset moved, those of upward joints included: export writes each
  // correction onto the URDF's own joint (an upward joint's offset into its own origin, even the
  // first one's, whose child link is the base and carries no joint), and the file imported again
  // has the calibrated machine's forward kinematics.
  for (const auto& [urdf, base, tip_link] :
       {std::tuple{kHumanoidUrdf, "left_sole_link", "gripper_left_base_link"},
        std::tuple{kSmallUrdf, "finger", "world"}, std::tuple{kSmallUrdf, "finger", "probe"}}) {
    SCOPED_TRACE(base + std::string(" -> ") + tip_link);
    const MachineBlock block = readMachine(importUrdf(urdf, base, tip_link));
    for (const std::uint64_t seed : {50u, 60u}) {
      const Eigen::VectorXd p = calibrated(block, seed == 50u ? 0.02 : 0.5, seed);
      const std::string out = temporaryPath("tree-roundtrip");
      writeText(out, exportUrdf(chainOf(block), p, urdf, "machine"));
      const MachineBlock again = readMachine(importUrdf(out, base, tip_link));
      std::filesystem::remove(out);
      EXPECT_LT(largestTipDifference(chainOf(block), p, chainOf(again), again.nominal, seed),
                1e-12);
    }
  }
}

TEST(UrdfTree, ExportRefusesAMachineWhoseJointsAreNotAPathOfTheTree) {
  nlohmann::json machine = importUrdf(kHumanoidUrdf, "left_sole_link", "gripper_left_base_link");
  machine["joints"][3]["reversed"] = false;  // leg_left_4_joint run downward: no path
  const MachineBlock block = readMachine(machine);
  try {
    (void)exportUrdf(chainOf(block), block.nominal, kHumanoidUrdf, "cal.json");
    ADD_FAILURE() << "exported";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a path of the URDF tree"), std::string::npos)
        << e.what();
  }
}

TEST(UrdfCli, ImportWritesAMachineTheExportReadsBack) {
  const std::string machine = temporaryPath("machine") + ".json";
  const std::string out = temporaryPath("cli-export");
  ASSERT_EQ(
      runCli("import-urdf " + kPandaUrdf + " --base panda_link0 --tip ball_link -o " + machine)
          .status,
      0);
  const auto run = runCli(
      "export-urdf --machine " + machine + " --urdf " + kPandaUrdf + " -o " + out, Stderr::Merge);
  EXPECT_EQ(run.status, 0) << run.out;
  const MachineBlock a = readMachine(readJsonFile(machine));
  const MachineBlock b = readMachine(importUrdf(out, "panda_link0", "ball_link"));
  EXPECT_LT(largestTipDifference(chainOf(a), a.nominal, chainOf(b), b.nominal, 80), 1e-9);
  std::filesystem::remove(machine);
  std::filesystem::remove(out);
}

// The Panda's calibrated machine file (calibrate --write-machine): export-urdf changes the
// origin lines of the joints its "calibrate" list names (panda_joint2 .. panda_joint8) and no
// other line; the ball joint, which the machine file holds rounded to 1e-9 mm but does not
// calibrate, keeps the URDF's text.
TEST(UrdfCli, ExportChangesTheCalibratedJointsLinesOnly) {
  const std::string machine = test_support::planFile("panda-8positions.machine.json");
  const std::string out = temporaryPath("cli-calibrated");
  const auto run = runCli(
      "export-urdf --machine " + machine + " --urdf " + kPandaUrdf + " -o " + out, Stderr::Merge);
  ASSERT_EQ(run.status, 0) << run.out;
  std::set<std::string> calibrated;
  const nlohmann::json document = readJsonFile(machine);  // kept: the loop reads into it
  for (const nlohmann::json& name : document["calibrate"]) {
    const std::string n = name.get<std::string>();
    calibrated.insert(n.substr(0, n.find('.')));
  }
  const std::vector<std::string> a = linesOf(fileText(kPandaUrdf)), b = linesOf(fileText(out));
  std::filesystem::remove(out);
  ASSERT_EQ(a.size(), b.size());
  std::set<std::string> changed;
  std::string joint;
  for (std::size_t i = 0; i < a.size(); ++i) {
    std::smatch name;
    if (std::regex_search(a[i], name, std::regex("<joint name=\"([^\"]+)\""))) joint = name[1];
    if (a[i] == b[i]) continue;
    EXPECT_TRUE(calibrated.count(joint)) << b[i];
    EXPECT_NE(b[i].find("<origin"), std::string::npos) << b[i];
    EXPECT_TRUE(changed.insert(joint).second) << joint;
  }
  EXPECT_EQ(changed, calibrated);
  EXPECT_EQ(changed.size(), 7u);
}

// One line "error: FILE: ..." and exit status 2.
void expectOneLineError(const std::string& arguments, const std::string& file,
                        const std::string& what) {
  const auto run = runCli(arguments, Stderr::Only);
  EXPECT_EQ(run.status, 2) << arguments;
  EXPECT_EQ(run.out.rfind("error: " + file + ": ", 0), 0u) << run.out;
  EXPECT_NE(run.out.find(what), std::string::npos) << run.out;
  EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1) << run.out;
}

TEST(UrdfCli, BadUrdfIsOneLineAndExitStatus2) {
  const std::string broken = temporaryPath("broken");
  writeText(broken, "<robot name=\"x\">\n  <link name=\"a\">\n</robot>\n");
  expectOneLineError("import-urdf " + broken + " --base a --tip a", broken, "line");
  writeText(broken,
            "<robot name=\"x\"><link name=\"a\"/><joint name=\"j\" type=\"revolute\">"
            "<parent link=\"a\"/><child link=\"b\"/></joint></robot>\n");
  expectOneLineError("import-urdf " + broken + " --base a --tip b", broken, "not a valid URDF");
  writeText(broken, "<model/>\n");
  expectOneLineError("import-urdf " + broken + " --base a --tip b", broken, "<robot>");
  // An empty file is named as such (tinyxml2 said "line 0: ... XML_ERROR_EMPTY_DOCUMENT").
  writeText(broken, "");
  expectOneLineError("import-urdf " + broken + " --base a --tip b", broken,
                     "empty: not a URDF file (expected a <robot> root element)");
  // A xacro file (before: "not a valid URDF (No link elements found in urdf file)").
  writeText(broken,
            "<?xml version=\"1.0\"?>\n<robot xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n"
            "  <xacro:macro name=\"arm\" params=\"prefix\">\n    <link name=\"${prefix}a\"/>\n"
            "  </xacro:macro>\n</robot>\n");
  expectOneLineError("import-urdf " + broken + " --base a --tip b", broken,
                     "line 3: <xacro:macro>: a xacro file, not a URDF: expand it first");
  // A URDF xacro wrote keeps the namespace attribute alone: it imports.
  writeText(broken,
            "<robot name=\"x\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\"><link name=\"a\"/>"
            "<link name=\"b\"/><joint name=\"j\" type=\"continuous\"><parent link=\"a\"/>"
            "<child link=\"b\"/><origin xyz=\"0.1 0 0\"/></joint></robot>\n");
  EXPECT_EQ(runCli("import-urdf " + broken + " --base a --tip b -o -", Stderr::Only).status, 0);
  std::filesystem::remove(broken);
  expectOneLineError("import-urdf " + kSmallUrdf + " --base world --tip nowhere", kSmallUrdf,
                     "no link named \"nowhere\"");
  // A tip not below the base is reached up the tree (UrdfTree tests); the same link is refused.
  expectOneLineError("import-urdf " + kSmallUrdf + " --base probe --tip probe", kSmallUrdf,
                     "the same link");
  expectOneLineError("import-urdf /nonexistent.urdf --base a --tip b", "/nonexistent.urdf",
                     "cannot read");
}

TEST(UrdfCli, MachineThatDoesNotFitTheUrdfIsOneLineAndExitStatus2) {
  const std::string machine = temporaryPath("small-machine") + ".json";
  ASSERT_EQ(runCli("import-urdf " + kSmallUrdf + " --base world --tip probe -o " + machine).status,
            0);
  const std::string out = temporaryPath("never-written");
  expectOneLineError("export-urdf --machine " + machine + " --urdf " + kPandaUrdf + " -o " + out,
                     machine, "/joints/0: joint \"mount\" is not in");
  EXPECT_FALSE(std::filesystem::exists(out));
  std::filesystem::remove(machine);
  expectOneLineError(
      "export-urdf --machine " + kData + "/ref-2r-5bars.json --urdf " + kPandaUrdf + " -o " + out,
      kData + "/ref-2r-5bars.json", "/machine/model");
}

}  // namespace urdf_test
}  // namespace artcal
