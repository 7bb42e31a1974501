// The reference cases of an independent implementation (tests/data/*.expected.json).

#include <gtest/gtest.h>

#include <fstream>

#include "artcal/internal.hpp"
#include "plan_builders.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace reference_test {

nlohmann::json readExpected(const std::string& name) {
  std::ifstream in(test_support::testDataFile(name + ".expected.json"));
  return nlohmann::json::parse(in);
}

Plan readPlan(const std::string& name) {
  return loadPlan(test_support::testDataFile(name + ".json"));
}

void expectRelative(double actual, double expected, double tolerance, const std::string& what) {
  EXPECT_NEAR(actual, expected, tolerance * std::abs(expected)) << what;
}

void expectMatchesReference(const std::string& name) {
  const Plan plan = readPlan(name);
  const nlohmann::json expected = readExpected(name);
  const Evaluation ev = evaluatePlan(plan);
  const nlohmann::json got = evaluationToJson(plan, ev);
  EXPECT_EQ(got["identifiable"], expected["identifiable"]);
  EXPECT_EQ(got["rank"]["deficiency"], expected["rank"]["deficiency"]);
  for (const char* key : {"N_p", "N_b", "N_r", "satisfied"}) {
    EXPECT_EQ(got["counting"][key], expected["counting"][key]) << key;
  }
  if (expected.contains("parameters")) {
    ASSERT_EQ(got["parameters"].size(), expected["parameters"].size());
    for (std::size_t i = 0; i < expected["parameters"].size(); ++i) {
      const auto& e = expected["parameters"][i];
      const auto& g = got["parameters"][i];
      EXPECT_EQ(g["name"], e["name"]);
      expectRelative(g["u"].get<double>(), e["u"].get<double>(), 1e-6, e["name"]);
    }
  }
  if (expected.contains("tip")) {
    const auto& e = expected["tip"];
    const auto& g = got["tip"];
    for (const char* key : {"total", "kinematic", "encoder"}) {
      expectRelative(g["worst"][key].get<double>(), e["worst"][key].get<double>(), 1e-6, key);
    }
    for (std::size_t j = 0; j < e["worst"]["joints"].size(); ++j) {
      EXPECT_NEAR(g["worst"]["joints"][j].get<double>(), e["worst"]["joints"][j].get<double>(),
                  1e-9);
    }
    expectRelative(g["mean"].get<double>(), e["mean"].get<double>(), 1e-6, "mean");
  }
}

TEST(Reference, Planar2R5Bars) {
  expectMatchesReference("ref-2r-5bars");
}
TEST(Reference, RingLayoutIsDegenerate) {
  expectMatchesReference("ref-2r-ring-degenerate");
}
TEST(Reference, Aacmm3Bars3Postures) {
  expectMatchesReference("ref-aacmm-3bars-3postures");
}

// The new families' references (models.md sections 1 and 2): the chain's identifiable set is
// chosen by the greedy rule ("calibrate": "identifiable") and must be exactly the reference's,
// in order; the dropped parameters too.
void expectResolvedSetMatchesReference(const std::string& name) {
  const Plan plan = readPlan(name);
  const nlohmann::json expected = readExpected(name);
  const nlohmann::json got = evaluationToJson(plan, evaluatePlan(plan));
  ASSERT_TRUE(got.contains("calibrate_resolved"));
  EXPECT_EQ(got["calibrate_resolved"], expected["calibrate_resolved"]);
  EXPECT_EQ(got["calibrate_dropped"], expected["calibrate_dropped"]);
  std::vector<std::string> order;
  for (const ParameterInfo& p : plan.machine.mechanism->parameters()) order.push_back(p.name);
  EXPECT_EQ(nlohmann::json(order), expected["parameter_order"]);
}

TEST(Reference, ChainPanda2Placements) {
  expectMatchesReference("ref-chain-panda-2placements");
  expectResolvedSetMatchesReference("ref-chain-panda-2placements");
}
TEST(Reference, DhBetaArm3) {
  expectMatchesReference("ref-dh-beta-arm3");
}

// The calibration case gives u at the estimate; the evaluator's u at nominal (the readings are
// the same, the estimate is within tens of um and mdeg of nominal) is within a few % of it.
TEST(Reference, CalibrationCaseUncertaintyAtNominalIsCloseToTheEstimate) {
  const Plan plan = readPlan("ref-2r-calibrate");
  const nlohmann::json expected = readExpected("ref-2r-calibrate");
  const Evaluation evaluation = evaluatePlan(plan);
  ASSERT_TRUE(evaluation.identifiable());
  const nlohmann::json got = evaluationToJson(plan, evaluation);
  ASSERT_EQ(got["parameters"].size(), expected["parameters"].size());
  for (std::size_t i = 0; i < expected["parameters"].size(); ++i) {
    const auto& e = expected["parameters"][i];
    EXPECT_EQ(got["parameters"][i]["name"], e["name"]);
    expectRelative(got["parameters"][i]["u"].get<double>(), e["u"].get<double>(), 0.03, e["name"]);
  }
}

// The hexapod (models.md section 3): all 45 parameters leave the 12 combinations of the base and
// platform frames unseparable; "identifiable" keeps exactly the reference's 33.
TEST(Reference, Hexapod6BarsAllParameters) {
  expectMatchesReference("ref-hexapod-6bars");
}
TEST(Reference, Hexapod6BarsIdentifiable) {
  expectMatchesReference("ref-hexapod-6bars-identifiable");
  expectResolvedSetMatchesReference("ref-hexapod-6bars-identifiable");
}

// Instruments (instruments.md): a tracker's two stations, each a full rigid motion eliminated.
TEST(Reference, InstrumentArm6TwoStations) {
  expectMatchesReference("ref-instrument-arm6-2stations");
}

// The same covariance as a ball plate whose centres are the nominal tip points, each read once
// (the seed's equivalence): the plate's rigid placement is the station, the noise the tracker's
// added in quadrature to the probe's.
TEST(Reference, InstrumentEqualsBallPlateOfItsTipPoints) {
  const Plan plan = readPlan("ref-instrument-arm6-2stations");
  const Evaluation tracker = evaluatePlan(plan);
  Plan plate = plan;
  plate.noise.probe = std::hypot(plan.noise.probe, plan.artifacts[0].noise);
  plate.artifacts.clear();
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    Placement& placement = plate.placements[j];
    const Eigen::MatrixXd tips = DesignMatrixBuilder(plan.machine, plan.noise)
                                     .probePositions(placement.measurements, plan.machine.nominal);
    plate.artifacts.push_back(Artifact::ballPlate("plate" + std::to_string(j), tips, 0.0));
    placement.artifact = static_cast<int>(j);
    for (std::size_t i = 0; i < placement.measurements.size(); ++i) {
      placement.measurements[i].feature = static_cast<int>(i);
      placement.measurements[i].point.resize(0);
    }
  }
  const Evaluation balls = evaluatePlan(plate);
  const nlohmann::json a = evaluationToJson(plan, tracker);
  const nlohmann::json b = evaluationToJson(plate, balls);
  ASSERT_EQ(a["parameters"].size(), b["parameters"].size());
  for (std::size_t i = 0; i < a["parameters"].size(); ++i) {
    expectRelative(a["parameters"][i]["u"].get<double>(), b["parameters"][i]["u"].get<double>(),
                   1e-9, a["parameters"][i]["name"]);
  }
}

// A station of collinear points is refused, naming it (the expected file says "collinear").
TEST(Reference, InstrumentCollinearStationIsRefused) {
  ASSERT_EQ(readExpected("ref-instrument-arm6-collinear")["error"], "collinear");
  try {
    readPlan("ref-instrument-arm6-collinear");
    FAIL() << "a collinear station was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("collinear"), std::string::npos) << what;
    EXPECT_NE(what.find("station 2"), std::string::npos) << what;
  }
}

// A pose instrument (instruments.md, "measures": "pose") against a dense oracle built here from
// the model's own Jacobians (Mechanism::forwardPose): per reading the 6 rows [R J_x_p; R J_w_p]
// over p and [I, -[W]x; 0, I] over its station's rigid motion, whitened by the 6 x 6 covariance
// diag(s^2 I, s_angle^2 I) + [R J_x_q; R J_w_q] Sigma_q [...]^T (the orientation residual's
// J_l^-1 is I at the nominal readings), stacked over both stations; the covariance of p is the p
// block of the full inverse (each station's 6 rigid parameters eliminated). u matches to 1e-6.
Eigen::MatrixXd denseOraclePoseCovariance(const Plan& plan) {
  const Machine& machine = plan.machine;
  const Artifact& tracker = plan.artifacts[0];
  const int n_p = machine.calibratedCount();
  const int stations = static_cast<int>(plan.placements.size());
  const std::vector<RigidTransform> fitted = fitPlacements(plan, plan.placements, machine.nominal);
  std::vector<Eigen::MatrixXd> rows;
  for (int j = 0; j < stations; ++j) {
    const RigidTransform& station = fitted[static_cast<std::size_t>(j)];
    for (const Measurement& m : plan.placements[static_cast<std::size_t>(j)].measurements) {
      Eigen::VectorXd x;
      Eigen::Matrix3d R;
      Eigen::MatrixXd J_x_p, J_x_q, J_w_p, J_w_q;
      const ForwardStatus status = machine.mechanism->forwardPose(machine.nominal, m.joints, x, R,
                                                                  &J_x_p, &J_x_q, &J_w_p, &J_w_q);
      EXPECT_EQ(status, ForwardStatus::Ok);
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(6, n_p + 6 * stations);
      for (int k = 0; k < n_p; ++k) {
        A.block(0, k, 3, 1) = station.R * J_x_p.col(machine.calibrated[k]);
        A.block(3, k, 3, 1) = station.R * J_w_p.col(machine.calibrated[k]);
      }
      const Eigen::Vector3d W = station.apply(x);
      Eigen::Matrix3d minus_W_cross;
      minus_W_cross << 0, W.z(), -W.y(), -W.z(), 0, W.x(), W.y(), -W.x(), 0;
      A.block(0, n_p + 6 * j, 3, 3).setIdentity();
      A.block(0, n_p + 6 * j + 3, 3, 3) = minus_W_cross;
      A.block(3, n_p + 6 * j + 3, 3, 3).setIdentity();
      Eigen::MatrixXd J_q(6, J_x_q.cols());
      J_q << station.R * J_x_q, station.R * J_w_q;
      Eigen::MatrixXd Sigma =
          J_q * plan.noise.encoder.array().square().matrix().asDiagonal() * J_q.transpose();
      const double s2 = plan.noise.probe * plan.noise.probe + tracker.noise * tracker.noise;
      for (int k = 0; k < 3; ++k) {
        Sigma(k, k) += s2;
        Sigma(3 + k, 3 + k) += tracker.noise_angle * tracker.noise_angle;
      }
      rows.push_back(Eigen::LLT<Eigen::MatrixXd>(Sigma).matrixL().solve(A));
    }
  }
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(n_p + 6 * stations, n_p + 6 * stations);
  for (const Eigen::MatrixXd& a : rows) N += a.transpose() * a;
  return N.inverse().topLeftCorner(n_p, n_p);
}

TEST(Reference, InstrumentPoseMatchesADenseOracle) {
  const Plan plan = parsePlan(testing::poseTrackerDocument(), "tracker-pose.json");
  ASSERT_TRUE(plan.artifacts[0].measures_pose);
  const Evaluation ev = evaluatePlan(plan);
  ASSERT_TRUE(ev.covariance);
  const Eigen::MatrixXd V = denseOraclePoseCovariance(plan);
  ASSERT_EQ(V.rows(), ev.covariance->u.size());
  for (int k = 0; k < V.rows(); ++k)
    expectRelative(ev.covariance->u[k], std::sqrt(V(k, k)), 1e-6, "parameter " + std::to_string(k));
  // The counting condition with N(b_j) = 6 n_j: 2 stations x 25 readings x 6 - 2 x 6.
  const nlohmann::json got = evaluationToJson(plan, ev);
  EXPECT_EQ(got["counting"]["N_b"], 300);
  EXPECT_EQ(got["counting"]["N_r"], 12);
  // The orientations add information: every u at most the point tracker's.
  const Evaluation points = evaluatePlan(readPlan("ref-instrument-arm6-2stations"));
  for (int k = 0; k < V.rows(); ++k) EXPECT_LE(ev.covariance->u[k], points.covariance->u[k]);
}

}  // namespace reference_test
}  // namespace artcal
