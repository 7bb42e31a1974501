// Mimic joints and prismatic axes from URDF (instruments.md, "Mimic joints and prismatic axes"):
// a lifting column whose one reading (a virtual joint off the base-to-tip chain) drives two
// coupled prismatic segments, then a 6-axis arm and a prism. It imports with one reading per
// driving joint, its forward kinematics equals hand-composed transforms and an uncoupled chain
// driven by the coupled values, a plan of simulated tracker readings calibrates to the truth
// within 3 u, and the exported URDF (couplings written back unchanged) has the calibrated
// machine's forward kinematics to 1e-9 mm.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <random>

#include "artcal/internal.hpp"
#include "artcal/io/chain_codec.hpp"
#include "artcal/io/urdf.hpp"
#include "cli_runner.hpp"
#include "plan_builders.hpp"

namespace artcal {
namespace urdf_mimic_test {

using nlohmann::json;

const std::string kData = ARTCAL_TEST_DATA;
const std::string kColumnUrdf = kData + "/urdf/lifting-column-arm6.urdf";
const std::string kColumnPlan = kData + "/lifting-column-tracker.json";

MachineBlock importColumn(const std::string& urdf = kColumnUrdf) {
  return readChainMachine(importUrdf(urdf, "base_link", "prism_link"), "machine");
}

const Chain& chainOf(const MachineBlock& block) {
  return static_cast<const Chain&>(*block.mechanism);
}

Eigen::Vector3d tip(const Mechanism& model, const Eigen::VectorXd& p, const Eigen::VectorXd& q) {
  Eigen::VectorXd x;
  forwardOrThrow(model, p, q, x);
  return x;
}

// Readings uniform within the machine's joint limits (internal units), seeded.
std::vector<Eigen::VectorXd> readingsWithinLimits(const Machine& machine, int count,
                                                  std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::VectorXd> out;
  for (int c = 0; c < count; ++c) {
    Eigen::VectorXd q(machine.jointCount());
    for (int i = 0; i < q.size(); ++i) {
      const auto [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
      q[i] = lo + (hi - lo) * unit(rng);
    }
    out.push_back(q);
  }
  return out;
}

std::string temporaryUrdf(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          (name + "-" + std::to_string(::getpid()) + ".urdf"))
      .string();
}

Plan columnPlan() {
  return loadPlan(kColumnPlan);
}

TEST(UrdfMimic, TheColumnIsOneReadingWhereItsFirstMimicStands) {
  const json machine = importUrdf(kColumnUrdf, "base_link", "prism_link");
  const json& joints = machine["joints"];
  ASSERT_EQ(joints.size(), 9u);  // column_middle, column_top, joint1..6, prism
  EXPECT_EQ(joints[0]["name"], "column_middle");
  EXPECT_EQ(joints[0]["mimic"], json({{"joint", "column_prismatic_joint"},
                                      {"multiplier", 0.5},
                                      {"offset", -706.0}}));  // m -> mm, exactly
  EXPECT_EQ(joints[1]["mimic"]["offset"].get<double>(), -736.0);
  EXPECT_FALSE(joints[2].contains("mimic"));
  const json& limits = machine["joint_limits"];
  ASSERT_EQ(limits.size(), 7u);  // the column (the master's <limit>), then joint1..6
  EXPECT_NEAR(limits[0][0].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(limits[0][1].get<double>(), 1412.0, 1e-9);
  EXPECT_NEAR(limits[1][1].get<double>(), radToDeg(2.967), 1e-9);
  const MachineBlock block = importColumn();
  const Chain& chain = chainOf(block);
  ASSERT_EQ(chain.jointCount(), 7);
  EXPECT_EQ(chain.readings()[0].name, "column_prismatic_joint");
  EXPECT_EQ(chain.readings()[0].chain_joint, -1);  // off the chain
  EXPECT_EQ(chain.jointKind(0), JointKind::Prismatic);
  EXPECT_EQ(chain.readings()[1].name, "joint1");
  EXPECT_EQ(chain.jointKind(1), JointKind::Revolute);
  // The mimic joints' origins and offsets are parameters like any other joint's.
  EXPECT_EQ(chain.parameters()[6].name, "column_middle.offset");
  EXPECT_EQ(chain.parameters()[chain.parameterOffset(1) + 3].name, "column_top.roll");
}

// With the arm's joints at zero every frame is a translation: the tip is the sum of the
// origins, the column's segments adding 0.5 q - 706 and 0.5 q - 736 mm along z.
TEST(UrdfMimic, ForwardKinematicsAtZeroIsTheSumOfTheOrigins) {
  const MachineBlock block = importColumn();
  for (const double column : {0.0, 700.0, 1412.0}) {
    Eigen::VectorXd q = Eigen::VectorXd::Zero(7);
    q[0] = column;
    const double z = 1050.0 + (0.5 * column - 706.0) + 980.0 + (0.5 * column - 736.0) + 120.0 +
                     330.0 + 610.0 + 115.0 + 60.0;
    const Eigen::Vector3d expected(150.0 + 100.0 + 520.0 + 90.0 + 85.0, 30.0, z);
    EXPECT_LT((tip(chainOf(block), block.nominal, q) - expected).norm(), 1e-9) << column;
  }
}

// The same machine with the couplings removed (8 readings) driven by the coupled values: equal
// tips at random readings and perturbed parameters.
TEST(UrdfMimic, ForwardKinematicsEqualsTheUncoupledChainAtTheCoupledValues) {
  const MachineBlock block = importColumn();
  json uncoupled = importUrdf(kColumnUrdf, "base_link", "prism_link");
  for (json& joint : uncoupled["joints"]) joint.erase("mimic");
  uncoupled.erase("joint_limits");
  const MachineBlock plain = readChainMachine(uncoupled, "uncoupled");
  ASSERT_EQ(plain.mechanism->jointCount(), 8);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int c = 0; c < 20; ++c) {
    Eigen::VectorXd p = block.nominal;
    for (int k = 0; k < p.size(); ++k) p[k] += 0.05 * uniform(rng);
    Eigen::VectorXd q(7);
    q[0] = 706.0 * (1.0 + uniform(rng));
    for (int i = 1; i < 7; ++i) q[i] = 2.0 * uniform(rng);
    Eigen::VectorXd q_plain(8);
    q_plain << 0.5 * q[0] - 706.0, 0.5 * q[0] - 736.0, q.tail(6);
    EXPECT_LT((tip(chainOf(block), p, q) - tip(*plain.mechanism, p, q_plain)).norm(), 1e-9);
  }
}

// The column reads 0 .. 1412 mm (the master's <limit>); the segments' own limits (-706 .. 0 mm,
// -736 .. 0 mm) are not the reading's: 1400 mm is a valid reading, 1500 mm is not.
TEST(UrdfMimic, AMimicsOwnLimitsDoNotApplyToTheMastersReading) {
  json document = readJsonFile(kColumnPlan);
  auto& first = document["placements"][0]["measurements"][0]["joints"];
  first[0] = 1400.0;
  EXPECT_NO_THROW(parsePlan(document, kColumnPlan));
  first[0] = 1500.0;
  try {
    (void)parsePlan(document, kColumnPlan);
    ADD_FAILURE() << "a column reading beyond the master's limit accepted";
  } catch (const InputError& e) {
    EXPECT_NE(e.describe().find("/placements/0/measurements/0"), std::string::npos) << e.describe();
  }
}

// Station 2 of the plan reads its CSV with "unit": "m": the column's metres become mm (and the
// arm's joints stay in deg).
TEST(UrdfMimic, ColumnReadingsInMetresBecomeMillimetres) {
  const Plan plan = columnPlan();
  ASSERT_EQ(plan.placements.size(), 2u);
  const json document = readJsonFile(kColumnPlan);
  ASSERT_EQ(document["placements"][1]["measurements"][0]["unit"], "m");
  std::ifstream csv(kData + "/lifting-column/station2.csv");
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  const double column_m = std::stod(row.substr(0, row.find(',')));
  const double joint1_deg = std::stod(row.substr(row.find(',') + 1));
  const Measurement& reading = plan.placements[1].measurements[0];
  EXPECT_NEAR(reading.joints[0], column_m * 1000.0, 1e-9);
  EXPECT_NEAR(reading.joints[1], degToRad(joint1_deg), 1e-12);
}

using testing::shiftedTruth;

TEST(UrdfMimic, TrackerReadingsCalibrateWithin3uAndTheExportedUrdfKeepsTheKinematics) {
  Plan plan = columnPlan();
  const Evaluation prediction = evaluatePlan(plan);
  ASSERT_TRUE(prediction.covariance);
  const Machine& machine = plan.machine;
  // The mimic joint's origin is calibrated like any other joint's.
  bool mimic_origin_calibrated = false;
  for (const int k : machine.calibrated) {
    const std::string& name = machine.mechanism->parameters()[static_cast<std::size_t>(k)].name;
    mimic_origin_calibrated = mimic_origin_calibrated || name.starts_with("column_top.");
  }
  EXPECT_TRUE(mimic_origin_calibrated);
  const Eigen::VectorXd truth = shiftedTruth(plan, prediction.covariance->u);
  NormalSource normal(21);
  plan.placements = Simulator(plan).simulate(truth, normal).placements;
  const Calibration calibration = calibratePlan(plan);
  ASSERT_TRUE(calibration.summary.converged());
  ASSERT_TRUE(calibration.covariance);
  const Eigen::VectorXd estimate = calibration.estimate(machine);
  const Eigen::VectorXd error = estimate - machine.calibratedValues(truth);
  for (int k = 0; k < error.size(); ++k) {
    EXPECT_LT(std::abs(error[k]), 3.0 * calibration.covariance->u[k]) << "parameter " << k;
  }
  // Export, import the exported file again: the same tips to 1e-9 mm.
  const Eigen::VectorXd p = machine.withCalibrated(machine.nominal, estimate);
  const auto& chain = static_cast<const Chain&>(*machine.mechanism);
  const std::string text = exportUrdf(chain, p, kColumnUrdf, "machine");
  for (const char* kept :
       {"<mimic joint=\"column_prismatic_joint\" multiplier=\"0.5\" offset=\"-0.706\"/>",
        "<mimic joint=\"column_prismatic_joint\" multiplier=\"0.5\" offset=\"-0.736\"/>",
        "<limit lower=\"0\" upper=\"1.412\" effort=\"5000\" velocity=\"0.05\"/>"}) {
    EXPECT_NE(text.find(kept), std::string::npos) << kept;
  }
  const std::string out = temporaryUrdf("column");
  std::ofstream(out, std::ios::binary) << text;
  const MachineBlock again = importColumn(out);
  std::filesystem::remove(out);
  std::vector<Eigen::VectorXd> readings = readingsWithinLimits(machine, 20, 8);
  for (const Measurement& m : plan.placements[0].measurements) readings.push_back(m.joints);
  for (const Eigen::VectorXd& q : readings) {
    EXPECT_LT((tip(chain, p, q) - tip(chainOf(again), again.nominal, q)).norm(), 1e-9);
  }
}

// Every parameter moved, the mimic joints' offsets and origins included (an offset of a mimic
// joint folds into the next origin as any other): the exported URDF has the same tips.
TEST(UrdfMimic, ExportFoldsTheMimicJointsOffsetsAndOrigins) {
  const MachineBlock block = importColumn();
  std::mt19937_64 rng(33);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd p = block.nominal;
  for (int k = 0; k < p.size(); ++k) p[k] += 0.2 * uniform(rng);
  const std::string out = temporaryUrdf("column-all");
  std::ofstream(out, std::ios::binary) << exportUrdf(chainOf(block), p, kColumnUrdf, "machine");
  const MachineBlock again = importColumn(out);
  std::filesystem::remove(out);
  Machine machine;
  machine.mechanism = block.mechanism;
  machine.joint_limits = {{0.0, 1412.0}};
  for (int i = 1; i < 7; ++i) machine.joint_limits.push_back({-3.0, 3.0});
  for (const Eigen::VectorXd& q : readingsWithinLimits(machine, 20, 34)) {
    EXPECT_LT((tip(chainOf(block), p, q) - tip(chainOf(again), again.nominal, q)).norm(), 1e-9);
  }
}

// A machine whose coupling is not the URDF's is refused on export, naming the joint's mimic.
TEST(UrdfMimic, ExportRefusesACouplingOtherThanTheUrdfs) {
  json machine = importUrdf(kColumnUrdf, "base_link", "prism_link");
  machine["joints"][1]["mimic"]["multiplier"] = 0.25;
  const MachineBlock block = readChainMachine(machine, "cal.json");
  try {
    (void)exportUrdf(chainOf(block), block.nominal, kColumnUrdf, "cal.json");
    ADD_FAILURE() << "another coupling exported";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "/joints/1/mimic");
  }
}

// The plan reader names a mimic it cannot resolve by its pointer.
TEST(UrdfMimic, UnresolvableMimicsInAMachineBlockAreRefusedWithTheirPointer) {
  const json imported = importUrdf(kColumnUrdf, "base_link", "prism_link");
  const auto refusal = [](const json& machine) {
    try {
      (void)readChainMachine(machine, "m.json");
    } catch (const InputError& e) {
      return e.describe();
    }
    return std::string();
  };
  json cycle = imported;  // joint1 mimics column_top, itself a mimic
  cycle["joints"][2]["mimic"] = {{"joint", "column_top"}};
  EXPECT_NE(refusal(cycle).find("/joints/2/mimic/joint"), std::string::npos) << refusal(cycle);
  json self = imported;
  self["joints"][3]["mimic"] = {{"joint", "joint2"}};
  EXPECT_NE(refusal(self).find("cannot mimic itself"), std::string::npos) << refusal(self);
  json fixed = imported;
  fixed["joints"][8]["mimic"] = {{"joint", "joint1"}};
  EXPECT_NE(refusal(fixed).find("/joints/8/mimic"), std::string::npos) << refusal(fixed);
  json types = imported;
  types["joints"][3]["mimic"] = {{"joint", "column_prismatic_joint"}};
  EXPECT_NE(refusal(types).find("/joints/3/mimic/joint"), std::string::npos) << refusal(types);
}

}  // namespace urdf_mimic_test
}  // namespace artcal
