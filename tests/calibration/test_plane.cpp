// Plane artifacts (docs/planes.md): the rows' exact Jacobians against central differences, the
// length scale a single plane cannot give and a gauge block does (a rank deficiency known by
// construction), Monte-Carlo recovery of a simulated truth and confirmation of u, and invariance
// under a rigid motion of the whole plan.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>

#include "artcal/artcal.hpp"
#include "artcal/estimation/plane_rows.hpp"
#include "artcal/planning/plan_completion.hpp"
#include "finite_difference.hpp"
#include "plan_builders.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace plane_test {

using testing::centralDifferenceJacobian;
using testing::expectJacobianNear;
using testing::shiftedTruth;

// The 6-axis arm of ref-instrument-arm6-2stations.json (21 identifiable parameters), its
// artifacts replaced by `artifacts` and its placements by `placements` (posture requests).
nlohmann::json armDocument(const nlohmann::json& artifacts, const nlohmann::json& placements) {
  std::ifstream in(test_support::testDataFile("ref-instrument-arm6-2stations.json"));
  nlohmann::json document = nlohmann::json::parse(in);
  document["artifacts"] = artifacts;
  document["placements"] = placements;
  document["workspace"] = {{"samples", 200}, {"seed", 5}};
  return document;
}

// The plan with its posture requests turned into touches (plan --complete's rule).
Plan completed(const nlohmann::json& document, std::uint64_t seed = 11) {
  Plan plan = parsePlan(document, "plane.json", false);
  const auto readings = plannedReadings(plan, seed);
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    for (const auto& touches : readings[j]) {
      auto& to = plan.placements[j].measurements;
      to.insert(to.end(), touches.begin(), touches.end());
    }
    plan.placements[j].posture_requests.clear();
  }
  return plan;
}

nlohmann::json placement(const std::string& artifact, const Eigen::Vector3d& center,
                         const Eigen::Vector3d& normal, int touches, int faces = 1) {
  nlohmann::json measurements = nlohmann::json::array();
  for (int f = 0; f < faces; ++f) measurements.push_back({{"feature", f}, {"postures", touches}});
  return {{"artifact", artifact},
          {"pose",
           {{"center", {center[0], center[1], center[2]}},
            {"direction", {normal[0], normal[1], normal[2]}},
            {"roll", 0.0}}},
          {"measurements", measurements}};
}

// Three placements of one plane: a table under the arm, a wall, a slanted face.
nlohmann::json threePlanes(const std::string& artifact, int touches) {
  return {placement(artifact, {700, 0, -300}, {0, 0, 1}, touches),
          placement(artifact, {0, 800, 200}, {0, -1, 0}, touches),
          placement(artifact, {-500, -500, 300}, Eigen::Vector3d(0.7, 0.5, -0.5).normalized(),
                    touches)};
}

const nlohmann::json kTable = {
    {"type", "plane"}, {"radius", 3.0}, {"flatness", 0.002}, {"extent", 250.0}};
const nlohmann::json kFlushTable = {{"type", "plane"},
                                    {"measures", "flush"},
                                    {"flatness", 0.002},
                                    {"u_tilt", 0.002},
                                    {"extent", 250.0}};
const nlohmann::json kBlock = {{"type", "plane"},    {"shape", "gauge_block"}, {"length", 100.0},
                               {"u_length", 0.0001}, {"radius", 3.0},          {"extent", 10.0}};
const nlohmann::json kCorner = {
    {"type", "plane"}, {"shape", "cube_corner"}, {"length", 200.0}, {"radius", 3.0}};

// ---- the rows' Jacobians ----------------------------------------------------------------------

void expectRowsMatchCentralDifferences(const Plan& plan) {
  const Machine& machine = plan.machine;
  PlaneRows rows;
  PlaneRowsScratch scratch;
  int checked = 0;
  for (const Placement& placement : plan.placements) {
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    const RigidTransform r = poseTransform(3, *placement.pose);
    const Eigen::VectorXd c = Eigen::VectorXd::Zero(artifact.systematicCount());
    for (std::size_t i = 0; i < placement.measurements.size(); i += 3) {
      Measurement m = placement.measurements[i];
      planeRows(artifact, machine, machine.nominal, m, r, c, true, rows, scratch);
      auto residual = [&](const Eigen::VectorXd& p, const Measurement& reading,
                          const RigidTransform& pose) {
        PlaneRows out;
        PlaneRowsScratch s;
        planeRows(artifact, machine, p, reading, pose, c, false, out, s);
        return out.residual;
      };
      const Eigen::VectorXd p0 = machine.calibratedValues(machine.nominal);
      const Eigen::MatrixXd J_p = centralDifferenceJacobian(
          [&](const Eigen::VectorXd& v) {
            return residual(machine.withCalibrated(machine.nominal, v), m, r);
          },
          p0, 1e-6);
      const Eigen::MatrixXd J_q = centralDifferenceJacobian(
          [&](const Eigen::VectorXd& q) {
            Measurement moved = m;
            moved.joints = q;
            return residual(machine.nominal, moved, r);
          },
          m.joints, 1e-6);
      const Eigen::MatrixXd J_r = centralDifferenceJacobian(
          [&](const Eigen::VectorXd& delta) {
            return residual(machine.nominal, m, r.perturbed(artifact.expandFullRigidStep(delta)));
          },
          Eigen::VectorXd::Zero(artifact.fullRigidDof()), 1e-6);
      expectJacobianNear(rows.J_p, J_p, 1e-6, "dF/dp");
      expectJacobianNear(rows.J_q, J_q, 1e-6, "dF/dq");
      expectJacobianNear(rows.J_r, J_r, 1e-6, "dF/dr");
      ++checked;
    }
  }
  EXPECT_GT(checked, 5);
}

TEST(Plane, PointContactRowsMatchCentralDifferences) {
  const nlohmann::json artifacts = {{"table", kTable}, {"corner", kCorner}};
  nlohmann::json placements = threePlanes("table", 6);
  placements.push_back(placement("corner", {500, 300, 100}, {0, 0, 1}, 4, 3));
  expectRowsMatchCentralDifferences(completed(armDocument(artifacts, placements)));
}

// The derivatives hold at any configuration, flush or not: the point-contact touches' joints
// read as flush contacts (a tool axis off the tip frame's axes), and a cube corner's faces.
TEST(Plane, FlushContactRowsMatchCentralDifferences) {
  Plan plan = completed(armDocument({{"table", kTable}}, threePlanes("table", 6)));
  PlaneGeometry flush;
  flush.flush = true;
  flush.tool_axis = Eigen::Vector3d(0.3, -0.2, 1.0).normalized();
  plan.artifacts[0] = Artifact::planeArtifact("table", 3, flush, 0.002, 1e-4, 0.0);
  ASSERT_EQ(plan.artifacts[0].rowsPerReading(), 3);
  expectRowsMatchCentralDifferences(plan);
  flush.shape = PlaneShape::CubeCorner;
  flush.length = 200.0;
  plan.artifacts[0] = Artifact::planeArtifact("table", 3, flush, 0.002, 1e-4, 0.0);
  for (Placement& placement : plan.placements) {
    for (std::size_t i = 0; i < placement.measurements.size(); ++i)
      placement.measurements[i].feature = static_cast<int>(i % 3);
  }
  expectRowsMatchCentralDifferences(plan);
}

// A machine with two tips (the humanoid of plans/planes/humanoid-table.layout.json, both hands
// on the table, flush): each hand's flush touches are planned, and their rows taken, through
// that hand's own frame. The rows' derivatives hold for either tip, and a planned touch of either
// hand lies flush (its tilts zero): read through the other hand's frame it would not.
TEST(Plane, FlushContactRowsOfEachTipUseThatTipsFrame) {
  std::ifstream in(test_support::planFile("planes/humanoid-table.layout.json"));
  nlohmann::json document = nlohmann::json::parse(in);
  document["artifacts"] = {{"table",
                            {{"type", "plane"},
                             {"measures", "flush"},
                             {"axis", {0, 0, -1}},
                             {"flatness", 0.01},
                             {"u_tilt", 0.01},
                             {"extent", 150.0}}}};
  nlohmann::json placements = nlohmann::json::array();
  for (nlohmann::json placement : document["placements"]) {
    if (placement["artifact"] != "table") continue;
    for (auto& request : placement["measurements"]) request["postures"] = 3;
    placements.push_back(placement);
  }
  document["placements"] = placements;
  document["machine"]["calibrate"] = "identifiable";
  const Plan plan = completed(document, 3);
  const Machine& machine = plan.machine;
  int by_tip[2] = {0, 0};
  PlaneRows rows;
  PlaneRowsScratch scratch;
  for (const Placement& placement : plan.placements) {
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    const RigidTransform r = poseTransform(3, *placement.pose);
    const Eigen::VectorXd c = Eigen::VectorXd::Zero(artifact.systematicCount());
    for (const Measurement& m : placement.measurements) {
      ASSERT_GE(m.stylus, 0);
      ASSERT_LE(m.stylus, 1);
      ++by_tip[m.stylus];
      planeRows(artifact, machine, machine.nominal, m, r, c, false, rows, scratch);
      ASSERT_EQ(rows.residual.size(), 3);
      EXPECT_LT(rows.residual.tail(2).norm(), 1e-6) << "tip " << m.stylus;
      Measurement other = m;
      other.stylus = 1 - m.stylus;
      planeRows(artifact, machine, machine.nominal, other, r, c, false, rows, scratch);
      EXPECT_GT(rows.residual.tail(2).norm(), 1e-3) << "tip " << m.stylus;
    }
  }
  EXPECT_EQ(by_tip[0], 9);
  EXPECT_EQ(by_tip[1], 9);
  expectRowsMatchCentralDifferences(plan);
}

// ---- the length scale --------------------------------------------------------------------------

// The surviving fraction (method.md section 5) of the machine's change of scale: every calibrated
// length parameter moved in proportion to its nominal value, angles unchanged. A uniform scale of
// the machine maps a plane to a parallel plane, which each placement's offset absorbs.
double scaleFraction(const Plan& plan) {
  const Machine& machine = plan.machine;
  Eigen::VectorXd s = Eigen::VectorXd::Zero(machine.calibratedCount());
  for (int k = 0; k < s.size(); ++k) {
    if (!machine.calibratedInfo(k).quantity.isAngle())
      s[k] = machine.nominal[machine.calibrated[static_cast<std::size_t>(k)]];
  }
  const PlanInformation information = planInformation(plan, plan.placements, machine.nominal);
  return s.dot(information.reduced * s) / s.dot(information.unreduced_diagonal.asDiagonal() * s);
}

TEST(Plane, OnePlaneLeavesExactlyTheScaleAndAGaugeBlockGivesIt) {
  // Three placements of one plane, 40 touches each: 120 equations, 9 rigid unknowns, 21 params.
  const Plan planes = completed(armDocument({{"table", kTable}}, threePlanes("table", 40)));
  const Evaluation alone = evaluatePlan(planes);
  EXPECT_EQ(alone.identifiability.counting.N_r, 9);
  for (int n : alone.identifiability.counting.rigid_table) EXPECT_EQ(n, 3);
  EXPECT_TRUE(alone.identifiability.counting.satisfied);
  EXPECT_EQ(alone.identifiability.deficiency, 1);
  EXPECT_LT(scaleFraction(planes), 1e-10);
  // The same planes and a 100 mm gauge block touched on both faces: no deficiency left.
  nlohmann::json placements = threePlanes("table", 40);
  placements.push_back(placement("block", {600, -300, -100}, {1, 0, 0}, 10, 2));
  const Plan with_block =
      completed(armDocument({{"table", kTable}, {"block", kBlock}}, placements));
  const Evaluation both = evaluatePlan(with_block);
  EXPECT_EQ(both.identifiability.deficiency, 0);
  EXPECT_TRUE(both.identifiable());
  EXPECT_GT(scaleFraction(with_block), 1e-6);
}

// The planar arm touching lines (a 2-D plane): l1 and l2 scale together unseen by one line in
// any number of placements; a gauge block's two faces bring the scale.
TEST(Plane, PlanarArmOnLinesLosesTheScale) {
  const nlohmann::json doc = {
      {"format", "artcal-plan/1"},
      {"machine",
       {{"model", "planar2r"},
        {"parameters", {{"l1", 150.0}, {"l2", 100.0}, {"dt2", 0.0}}},
        {"joint_limits", {{-180, 180}, {-170, 170}}}}},
      {"noise", {{"probe", 0.005}, {"encoder", 0.001}}},
      {"artifacts",
       {{"line", {{"type", "plane"}, {"radius", 2.0}, {"extent", 60.0}}},
        {"block",
         {{"type", "plane"}, {"shape", "gauge_block"}, {"length", 60.0}, {"extent", 2.0}}}}},
      {"workspace", {{"samples", 100}, {"seed", 3}}}};
  auto place = [](const std::string& id, double x, double y, double angle, int faces) {
    nlohmann::json m = nlohmann::json::array();
    for (int f = 0; f < faces; ++f) m.push_back({{"feature", f}, {"postures", 8}});
    return nlohmann::json{
        {"artifact", id}, {"pose", {{"center", {x, y}}, {"angle", angle}}}, {"measurements", m}};
  };
  nlohmann::json lines = doc;
  lines["placements"] = {place("line", 150, 0, 0, 1), place("line", 0, 160, 90, 1),
                         place("line", -120, -100, 210, 1), place("line", 100, 120, 45, 1)};
  const Plan plan = completed(lines);
  const Evaluation alone = evaluatePlan(plan);
  EXPECT_EQ(alone.identifiability.deficiency, 1);
  ASSERT_EQ(alone.identifiability.unidentifiable.size(), 1u);
  // The combination is l1 : l2 = 150 : 100 (scaled by the unreduced norms, so compare the
  // fraction instead).
  EXPECT_LT(scaleFraction(plan), 1e-10);
  nlohmann::json with_block = lines;
  with_block["placements"].push_back(place("block", 120, 60, 30, 2));
  const Plan block = completed(with_block);
  const Evaluation both = evaluatePlan(block);
  EXPECT_EQ(both.identifiability.deficiency, 0);
}

// ---- Monte Carlo -------------------------------------------------------------------------------

Plan pointPlan() {
  nlohmann::json placements = threePlanes("table", 30);
  placements.push_back(placement("block", {600, -300, -100}, {1, 0, 0}, 8, 2));
  return completed(armDocument({{"table", kTable}, {"block", kBlock}}, placements));
}

void expectRecovered(Plan plan, std::uint64_t seed) {
  const Evaluation prediction = evaluatePlan(plan);
  ASSERT_TRUE(prediction.identifiable());
  ASSERT_TRUE(prediction.covariance);
  const Eigen::VectorXd truth = shiftedTruth(plan, prediction.covariance->u);
  NormalSource normal(seed);
  plan.placements = Simulator(plan).simulate(truth, normal).placements;
  const Calibration calibration = calibratePlan(plan);
  ASSERT_TRUE(calibration.summary.converged());
  ASSERT_TRUE(calibration.covariance);
  const Eigen::VectorXd error =
      calibration.estimate(plan.machine) - plan.machine.calibratedValues(truth);
  for (int k = 0; k < error.size(); ++k)
    EXPECT_LT(std::abs(error[k]), 3.0 * calibration.covariance->u[k]) << "parameter " << k;
  EXPECT_GT(calibration.chi2_per_dof, 0.6);
  EXPECT_LT(calibration.chi2_per_dof, 1.5);
}

TEST(Plane, SimulatedTouchesCalibrateToTheTruthWithin3u) {
  expectRecovered(pointPlan(), 7);
}

TEST(Plane, ConfirmFindsTheSpreadThePlanPredicts) {
  for (const Plan& plan : {pointPlan()}) {
    ConfirmationOptions options;
    options.trials = 100;
    options.seed = 4;
    const Confirmation confirmation = confirmPlan(plan, options);
    EXPECT_EQ(confirmation.converged_trials, confirmation.trials);
    EXPECT_TRUE(confirmation.confirmed);
    EXPECT_NEAR(confirmation.mean_chi2_per_dof, 1.0, 0.1);
  }
}

// ---- invariance ------------------------------------------------------------------------------

// Turning the whole plan about joint 1's axis (the base z): every reading's joint 1 and every
// placement's pose turned by the same angle.
Plan turned(Plan plan, double angle) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (Placement& placement : plan.placements) {
    for (Measurement& m : placement.measurements) m.joints[0] += angle;
    placement.pose->center = R * placement.pose->center.head<3>();
    placement.pose->direction = R * placement.pose->direction;
  }
  for (Eigen::VectorXd& q : plan.workspace.configurations) q[0] += angle;
  return plan;
}

TEST(Plane, EvaluateAndCalibrateAreInvariantUnderTurningTheWholePlan) {
  for (Plan plan : {pointPlan()}) {
    WorkspaceSpec spec;
    spec.samples = 150;
    spec.seed = 3;
    plan.workspace.configurations = workspaceConfigurations(plan.machine, spec);
    plan.workspace.kind = WorkspaceSpec::Kind::Configurations;
    const Evaluation a = evaluatePlan(plan);
    NormalSource normal(2);
    Plan measured = plan;
    measured.placements =
        Simulator(plan).simulate(shiftedTruth(plan, a.covariance->u), normal).placements;
    const Calibration ca = calibratePlan(measured);
    for (double degrees : {1e-9, 37.0, -121.0}) {
      SCOPED_TRACE(degrees);
      const Evaluation b = evaluatePlan(turned(plan, degToRad(degrees)));
      ASSERT_EQ(a.identifiability.rank, b.identifiability.rank);
      ASSERT_EQ(a.identifiability.deficiency, b.identifiability.deficiency);
      for (int k = 0; k < a.covariance->u.size(); ++k)
        EXPECT_NEAR(a.covariance->u[k], b.covariance->u[k], 1e-8 * a.covariance->u[k]);
      EXPECT_NEAR(a.tip->worst.total, b.tip->worst.total, 1e-8 * a.tip->worst.total);
      const Calibration cb = calibratePlan(turned(measured, degToRad(degrees)));
      const Eigen::VectorXd ea = ca.estimate(plan.machine), eb = cb.estimate(plan.machine);
      for (int k = 0; k < ea.size(); ++k)
        EXPECT_NEAR(ea[k], eb[k], 1e-3 * ca.covariance->u[k]) << "parameter " << k;
      EXPECT_NEAR(ca.chi2_per_dof, cb.chi2_per_dof, 1e-6);
    }
  }
}

// ---- bad input
// -----------------------------------------------------------------------------------

std::string refusal(const nlohmann::json& document) {
  try {
    parsePlan(document, "plane.json");
  } catch (const InputError& e) {
    return e.describe();
  }
  return "";
}

TEST(Plane, BadPlanesAreRefusedNamingTheField) {
  nlohmann::json flush_no_tilt = kFlushTable;
  flush_no_tilt.erase("u_tilt");
  EXPECT_NE(refusal(armDocument({{"t", flush_no_tilt}}, nlohmann::json::array())).find("u_tilt"),
            std::string::npos);
  nlohmann::json block_no_length = kBlock;
  block_no_length.erase("length");
  EXPECT_NE(refusal(armDocument({{"t", block_no_length}}, nlohmann::json::array()))
                .find("/artifacts/t/length"),
            std::string::npos);
  nlohmann::json no_pose = armDocument({{"t", kTable}}, threePlanes("t", 2));
  no_pose["placements"][0].erase("pose");
  no_pose["placements"][0]["measurements"] = {{{"feature", 0}, {"joints", {0, 0, 0, 0, 0, 0}}}};
  EXPECT_NE(refusal(no_pose).find("/placements/0/pose"), std::string::npos);
}

// plans/planes/arm6-flush.layout.json: every contact request is met (before, the wall's 20 and the
// gauge block's far face found none: from a posture that only reaches the point, the two tilt
// rows alone are flat where the tool lies along the face and zero with it pointing out of the
// material too), and each planned table contact lies flush, checked here from the layout's own
// numbers: the stylus end on the plane through the pose's centre, the tool axis (the last frame's
// x) equal to minus the pose's direction, the contact within the face's extent of its centre.
TEST(Plane, PlannedFlushContactsLieFlushWithTheToolPointingIntoTheFace) {
  std::ifstream in(test_support::planFile("planes/arm6-flush.layout.json"));
  const nlohmann::json document = nlohmann::json::parse(in);
  const Plan plan = completed(document, 5);
  ASSERT_EQ(plan.placements.size(), document["placements"].size());
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const nlohmann::json& layout = document["placements"][j];
    int requested = 0;
    for (const auto& request : layout["measurements"]) requested += request["postures"].get<int>();
    ASSERT_EQ(static_cast<int>(plan.placements[j].measurements.size()), requested) << j;
    if (layout["artifact"] != "table") continue;
    const auto& pose = layout["pose"];
    const Eigen::Vector3d center(pose["center"][0].get<double>(), pose["center"][1].get<double>(),
                                 pose["center"][2].get<double>());
    const Eigen::Vector3d normal =
        Eigen::Vector3d(pose["direction"][0].get<double>(), pose["direction"][1].get<double>(),
                        pose["direction"][2].get<double>())
            .normalized();
    const double extent = document["artifacts"]["table"]["extent"].get<double>();
    for (const Measurement& m : plan.placements[j].measurements) {
      Eigen::VectorXd x;
      Eigen::Matrix3d R;
      forwardPoseOrThrow(*plan.machine.mechanism, plan.machine.nominal, m.joints, x, R, nullptr,
                         nullptr, nullptr, nullptr, m.stylus);
      const Eigen::Vector3d tip = x.head<3>();
      EXPECT_NEAR((tip - center).dot(normal), 0.0, 1e-9) << j;
      EXPECT_NEAR((R * Eigen::Vector3d::UnitX()).dot(normal), -1.0, 1e-12) << j;
      const Eigen::Vector3d along = (tip - center) - (tip - center).dot(normal) * normal;
      EXPECT_LE(along.cwiseAbs().maxCoeff(), 1.5 * extent * std::sqrt(2.0)) << j;
      EXPECT_TRUE(plan.machine.withinLimits(m.joints)) << j;
    }
  }
}

}  // namespace plane_test
}  // namespace artcal
