// ISO 9283 as the user runs it (issue 43, point 4): the cube given by its centre, edge and
// orientation (its points rebuilt here from a rotation built apart), the arm's configuration given
// by a seed posture (each point's joints checked by forward kinematics and by their distance to
// the seed), the predicted AP against a Monte-Carlo written here (the covariances from central
// differences of the public forward kinematics) and closed forms, the predicted RP against the
// ISO statistic of many simulated cycles, and the command line's and the plan's forms.

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>

#include "artcal/acceptance/pose_acceptance.hpp"
#include "artcal/internal.hpp"
#include "cli_runner.hpp"
#include "finite_difference.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace pose_set_up_test {

constexpr double kDeg = std::numbers::pi / 180.0;

struct Prepared {
  Plan plan;
  AcceptanceInput input;
};

/// The 6-axis arm of plans/aacmm-6axis-3bars.json, optionally with every joint limited to
/// +-`limit` deg (a UR's +-360 holds two equivalents of every angle), and its predicted V_p.
Prepared prepareArm(double limit = 180.0) {
  std::ifstream in(test_support::planFile("aacmm-6axis-3bars.json"));
  nlohmann::json document = nlohmann::json::parse(in);
  document["machine"]["joint_limits"] = nlohmann::json::array();
  for (int j = 0; j < 6; ++j) document["machine"]["joint_limits"].push_back({-limit, limit});
  Prepared prepared{parsePlan(document, "aacmm-6axis-3bars.json"), {}};
  auto input = acceptanceInputFromPlan(prepared.plan, evaluatePlan(prepared.plan));
  EXPECT_TRUE(input.has_value());
  prepared.input = *input;
  prepared.input.machine = &prepared.plan.machine;
  return prepared;
}

Eigen::Vector3d tip(const Machine& machine, const Eigen::VectorXd& q) {
  Eigen::VectorXd x;
  EXPECT_EQ(machine.mechanism->forward(machine.nominal, q, x), ForwardStatus::Ok);
  return x.head<3>();
}

/// Rz(yaw) Ry(pitch) Rx(roll) from Eigen's angle-axis rotations.
Eigen::Matrix3d rotation(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

/// The covariances at `joints` from central differences of the forward kinematics: the
/// systematic part J_p V_p J_p^T and one cycle's noise J_q Sigma_q J_q^T.
struct OracleCovariances {
  Eigen::Matrix3d systematic, cycle;
};

OracleCovariances oracleCovariances(const Prepared& prepared, const Eigen::VectorXd& joints) {
  const Machine& machine = prepared.plan.machine;
  auto at_dp = [&](const Eigen::VectorXd& dp) {
    const Eigen::VectorXd p =
        machine.withCalibrated(machine.nominal, machine.calibratedValues(machine.nominal) + dp);
    Eigen::VectorXd x;
    EXPECT_EQ(machine.mechanism->forward(p, joints, x), ForwardStatus::Ok);
    return Eigen::VectorXd(x.head<3>());
  };
  auto at_q = [&](const Eigen::VectorXd& q) { return Eigen::VectorXd(tip(machine, q)); };
  const Eigen::MatrixXd J_p = testing::centralDifferenceJacobian(
      at_dp, Eigen::VectorXd::Zero(machine.calibratedCount()), 1e-6);
  const Eigen::MatrixXd J_q = testing::centralDifferenceJacobian(at_q, joints, 1e-6);
  const Eigen::VectorXd s2 = prepared.plan.noise.encoder.array().square();
  return {J_p * prepared.input.uncertainty.V * J_p.transpose(),
          J_q * s2.asDiagonal() * J_q.transpose()};
}

/// The cube of the other ISO 9283 tests on this arm: 300 mm at (0, 300, 200).
PoseTestOptions armCube() {
  PoseTestOptions options;
  options.cube = 300.0;
  options.center = Eigen::Vector3d(0.0, 300.0, 200.0);
  return options;
}

/// One draw of N(0, L L^T).
Eigen::Vector3d gaussianDraw(const Eigen::Matrix3d& L, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  const double a = normal(rng), b = normal(rng), c = normal(rng);
  return L * Eigen::Vector3d(a, b, c);
}

// ------------------------------------------------------------------------------------ the cube

TEST(PoseSetUp, TheCubesPointsFromItsCentreEdgeAndOrientation) {
  const Eigen::Vector3d c(420.0, -130.0, 380.0);
  const double edge = 250.0, h = 125.0;
  const Eigen::Matrix3d R = rotation(10.0 * kDeg, -20.0 * kDeg, 35.0 * kDeg);
  // The corners of the diagonal plane, each rotated with the cube about its centre.
  const Eigen::Vector3d Q1 = c + R * Eigen::Vector3d(-h, -h, -h),
                        Q2 = c + R * Eigen::Vector3d(h, h, -h),
                        Q3 = c + R * Eigen::Vector3d(h, h, h),
                        Q4 = c + R * Eigen::Vector3d(-h, -h, h);
  const std::vector<Eigen::Vector3d> expected = {c, Q1 + 0.1 * (Q3 - Q1), Q2 + 0.1 * (Q4 - Q2),
                                                 Q3 + 0.1 * (Q1 - Q3), Q4 + 0.1 * (Q2 - Q4)};
  const std::vector<Eigen::Vector3d> points = poseTestPoints(edge, c, R);
  ASSERT_EQ(points.size(), 5u);
  const Eigen::Vector3d normal = R * Eigen::Vector3d(1.0, -1.0, 0.0).normalized();
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_LT((points[i] - expected[i]).norm(), 1e-12) << "P" << i + 1;
    // In the measuring plane, P2 .. P5 0.8 of a half space diagonal from the centre.
    EXPECT_NEAR(normal.dot(points[i] - c), 0.0, 1e-12);
    if (i > 0) {
      EXPECT_NEAR((points[i] - c).norm(), 0.8 * h * std::sqrt(3.0), 1e-9);
    }
  }
  // Through the prediction: the orientation given as roll, pitch, yaw.
  const Prepared prepared = prepareArm();
  PoseTestOptions options;
  options.cube = 200.0;
  options.center = Eigen::Vector3d(0.0, 300.0, 200.0);
  options.orientation = Eigen::Vector3d(10.0, -20.0, 35.0) * kDeg;
  const PoseTestPrediction prediction = predictPoseTestLinear(prepared.input, options);
  const Eigen::Vector3d k = options.center + R * Eigen::Vector3d(100.0, 100.0, 100.0);
  EXPECT_LT((prediction.points[3].commanded - (k + 0.1 * (2.0 * options.center - 2.0 * k))).norm(),
            1e-9);
  for (const PosePoint& point : prediction.points)
    EXPECT_LT((tip(prepared.plan.machine, point.joints) - point.commanded).norm(), 1e-8);
}

// ------------------------------------------------------------------------------ the seed posture

// A UR-like arm with joint limits of +-360 deg: every angle has two equivalents within them. The
// user sets the cube up around the tip of the posture the arm is in (52 deg on the first joint).
// P1, the cube's centre, is the seed itself; every returned posture reaches its point, no joint
// has an equivalent nearer the seed (|q - seed| <= 180 deg: never -308 where 52 reaches the same
// pose) and every joint stays within 45 deg of the seed (the seed's branch).
TEST(PoseSetUp, TheSeedPostureKeepsEveryPointOnItsBranch) {
  const Prepared prepared = prepareArm(360.0);
  const Machine& machine = prepared.plan.machine;
  Eigen::VectorXd seed(6);
  seed << 52.0, 40.0, -30.0, 60.0, 20.0, 10.0;
  seed *= kDeg;
  PoseTestOptions options;
  options.cube = 200.0;
  options.center = tip(machine, seed);
  options.seed_posture = seed;
  const PoseTestPrediction prediction = predictPoseTestLinear(prepared.input, options);
  ASSERT_EQ(prediction.points.size(), 5u);
  EXPECT_LT((prediction.points[0].joints - seed).cwiseAbs().maxCoeff(), 1e-9);
  for (const PosePoint& point : prediction.points) {
    EXPECT_LT((tip(machine, point.joints) - point.commanded).norm(), 1e-8);
    EXPECT_TRUE(machine.withinLimits(point.joints));
    for (int j = 0; j < 6; ++j) {
      EXPECT_LE(std::abs(point.joints[j] - seed[j]), 180.0 * kDeg) << "joint " << j + 1;
      EXPECT_LE(std::abs(point.joints[j] - seed[j]), 45.0 * kDeg) << "joint " << j + 1;
    }
    EXPECT_GT(point.joints[0], 0.0);
  }
  // A seed beyond the limits by whole turns is the same posture; one that is not is refused.
  Eigen::VectorXd turned = seed;
  turned[0] += 360.0 * kDeg;  // 412 deg: beyond +360, the same as 52
  options.seed_posture = turned;
  const PoseTestPrediction same = predictPoseTestLinear(prepared.input, options);
  for (std::size_t i = 0; i < 5; ++i)
    EXPECT_LT((same.points[i].joints - prediction.points[i].joints).norm(), 1e-9);
  options.seed_posture = Eigen::VectorXd::Zero(5);
  EXPECT_THROW(predictPoseTestLinear(prepared.input, options), InputError);
}

// --------------------------------------------------------------------------- predicted AP, RP

TEST(PoseSetUp, ExpectedNormOfAGaussianMatchesTheChiDistributions) {
  // E|b| for b ~ N(0, sigma^2 I_k): sigma sqrt(2/pi) (k = 1), sigma sqrt(pi/2) (k = 2),
  // 2 sigma sqrt(2/pi) (k = 3); zero eigenvalues for k < 3.
  const double pi = std::numbers::pi;
  for (const double sigma : {1e-4, 0.03, 2.0}) {
    const double s2 = sigma * sigma;
    EXPECT_NEAR(expectedGaussianNorm(Eigen::Vector3d(s2, 0, 0).asDiagonal().toDenseMatrix()),
                sigma * std::sqrt(2.0 / pi), 1e-10 * sigma);
    EXPECT_NEAR(expectedGaussianNorm(Eigen::Vector3d(0, s2, s2).asDiagonal().toDenseMatrix()),
                sigma * std::sqrt(pi / 2.0), 1e-10 * sigma);
    EXPECT_NEAR(expectedGaussianNorm(s2 * Eigen::Matrix3d::Identity()),
                2.0 * sigma * std::sqrt(2.0 / pi), 1e-10 * sigma);
  }
  EXPECT_EQ(expectedGaussianNorm(Eigen::Matrix3d::Zero()), 0.0);
}

// The predicted AP at each point: E|b|, b ~ N(0, J_p V_p J_p^T + J_q Sigma_q J_q^T / 30 +
// u^2 I), against 200 000 draws of b (fixed seed) from the covariances rebuilt here; the
// library's own Monte-Carlo mean agrees too, and the unmodelled term is stated apart.
TEST(PoseSetUp, PredictedApIsTheMeanNormOfTheBiasWithTheUnmodelledTerm) {
  const Prepared prepared = prepareArm();
  PoseTestOptions options = armCube();
  options.unmodelled = 0.02;
  options.monte_carlo.trials = 40000;
  const PoseTestPrediction prediction = predictPoseTest(prepared.input, options);
  std::mt19937_64 rng(43);
  constexpr int kDraws = 200000;
  for (const PosePoint& point : prediction.points) {
    const OracleCovariances oracle = oracleCovariances(prepared, point.joints);
    EXPECT_NEAR(point.sigma_unmodelled, std::sqrt(3.0) * 0.02, 1e-15);
    EXPECT_NEAR(point.sigma_noise, std::sqrt(oracle.cycle.trace() / 30.0),
                1e-6 * point.sigma_noise);
    const Eigen::Matrix3d total =
        oracle.systematic + oracle.cycle / 30.0 + 0.02 * 0.02 * Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d L = total.llt().matrixL();
    double sum = 0.0, sum2 = 0.0;
    for (int d = 0; d < kDraws; ++d) {
      const double norm = gaussianDraw(L, rng).norm();
      sum += norm;
      sum2 += norm * norm;
    }
    const double mean = sum / kDraws;
    const double standard_error = std::sqrt((sum2 / kDraws - mean * mean) / kDraws);
    EXPECT_NEAR(point.ap_expected, mean, 4.0 * standard_error);
    // sqrt(E AP^2) bounds the spread of the library's 40 000 trials.
    EXPECT_NEAR(point.ap.mean, point.ap_expected, 4.0 * std::sqrt(total.trace() / 40000.0));
    // Jensen: E|b| < sqrt(E|b|^2), and the unmodelled term alone already gives 2 u sqrt(2/pi).
    EXPECT_LT(point.ap_expected, std::sqrt(total.trace()));
    EXPECT_GT(point.ap_expected, 2.0 * 0.02 * std::sqrt(2.0 / std::numbers::pi));
  }
}

// RP = mean l + 3 S_l over the cycles (l = |x_c - mean x|): the predicted value against the
// statistic of 200 000 simulated cycles (fixed seed) drawn from one cycle's covariance rebuilt
// here; neither the parameters' covariance nor the unmodelled error (both the same in every
// cycle) nor the number of cycles changes it.
TEST(PoseSetUp, PredictedRpIsTheIsoStatisticOfManyCycles) {
  const Prepared prepared = prepareArm();
  const PoseTestOptions options = armCube();
  const PoseTestPrediction prediction = predictPoseTestLinear(prepared.input, options);
  std::mt19937_64 rng(9283);
  constexpr int kCycles = 200000;
  for (const PosePoint& point : prediction.points) {
    const OracleCovariances oracle = oracleCovariances(prepared, point.joints);
    const Eigen::Matrix3d L = oracle.cycle.llt().matrixL();
    std::vector<Eigen::Vector3d> x(kCycles);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (Eigen::Vector3d& xc : x) {
      xc = gaussianDraw(L, rng);
      mean += xc / kCycles;
    }
    std::vector<double> l(kCycles);
    double l_mean = 0.0;
    for (int c = 0; c < kCycles; ++c) l_mean += (l[c] = (x[c] - mean).norm()) / kCycles;
    double ss = 0.0, s4 = 0.0;
    for (const double v : l) {
      ss += (v - l_mean) * (v - l_mean);
      s4 += std::pow(v - l_mean, 4);
    }
    const double S_l = std::sqrt(ss / (kCycles - 1));
    const double rp = l_mean + 3.0 * S_l;
    // Standard errors: of the mean l, S_l / sqrt(n); of S_l, sqrt(m4 - S_l^4) / (2 S_l sqrt(n)).
    const double se_s =
        std::sqrt(s4 / kCycles - std::pow(S_l, 4)) / (2.0 * S_l * std::sqrt(kCycles));
    const double se = S_l / std::sqrt(kCycles) + 3.0 * se_s;
    EXPECT_NEAR(point.rp, rp, 4.0 * se);
  }
  PoseTestOptions other = options;
  other.unmodelled = 0.5;
  other.cycles = 7;
  Prepared scaled = prepareArm();
  scaled.input.uncertainty.V *= 100.0;
  const PoseTestPrediction unchanged = predictPoseTestLinear(scaled.input, other);
  for (std::size_t i = 0; i < 5; ++i)
    EXPECT_NEAR(unchanged.points[i].rp, prediction.points[i].rp, 1e-12 * prediction.points[i].rp);
}

// --------------------------------------------------------------------------- command and plan

std::string writePlan(const nlohmann::json& acceptance, const std::string& tag) {
  std::ifstream in(test_support::planFile("aacmm-6axis-3bars.json"));
  nlohmann::json document = nlohmann::json::parse(in);
  for (auto& limits : document["machine"]["joint_limits"]) limits = {-360, 360};
  if (!acceptance.is_null()) document["acceptance"] = acceptance;
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("artcal-pose-" + tag + "-" + std::to_string(::getpid()) + ".json"))
                               .string();
  std::ofstream(path) << document.dump();
  return path;
}

// The plan's cube object, seed posture and unmodelled error give what the command line's options
// give; the JSON states them, and the unmodelled term apart from the noise and parameter terms.
TEST(PoseSetUp, ThePlansCubeObjectAndTheCommandLineAgree) {
  const std::string with_block =
      writePlan({{"test", "iso9283"},
                 {"cube", {{"center", {0, 300, 200}}, {"edge", 200}, {"orientation", {0, 0, 30}}}},
                 {"seed_posture", {52, 40, -30, 60, 20, 10}},
                 {"unmodelled", 0.03}},
                "block");
  const std::string without = writePlan(nullptr, "plain");
  const test_support::CliRun a =
      test_support::runCli("acceptance " + with_block + " --trials 2000 --json");
  const test_support::CliRun b = test_support::runCli(
      "acceptance " + without +
      " --test iso9283 --cube 200 --center 0,300,200 --orientation 0,0,30 --seed-posture "
      "52,40,-30,60,20,10 --unmodelled 0.03 --trials 2000 --json");
  std::filesystem::remove(with_block);
  std::filesystem::remove(without);
  ASSERT_EQ(a.status, 0) << a.out;
  ASSERT_EQ(b.status, 0) << b.out;
  const nlohmann::json ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
  EXPECT_EQ(ja, jb);
  ASSERT_EQ(ja["orientation"].size(), 3u);
  EXPECT_NEAR(ja["orientation"][2].get<double>(), 30.0, 1e-12);
  EXPECT_EQ(ja["unmodelled"], 0.03);
  ASSERT_EQ(ja["seed_posture"].size(), 6u);
  EXPECT_NEAR(ja["seed_posture"][0].get<double>(), 52.0, 1e-12);
  for (const auto& item : ja["items"]) {
    EXPECT_NEAR(item["sigma_unmodelled"].get<double>(), std::sqrt(3.0) * 0.03, 1e-15);
    EXPECT_GT(item["rp"].get<double>(), 0.0);
    EXPECT_LE(std::abs(item["joints"][0].get<double>() - 52.0), 180.0);
  }
}

TEST(PoseSetUp, BadSetUpsAreRefusedNamingWhatToCheck) {
  const std::string plain = writePlan(nullptr, "bad-plain");
  const std::string base = "acceptance " + plain + " --test iso9283 --cube 200 --center 0,300,200 ";
  for (const auto& [options, named] : std::vector<std::pair<std::string, std::string>>{
           {"--seed-posture 1,2,3", "--seed-posture"},
           {"--seed-posture 1,2,3,4,5,x", "--seed-posture"},
           {"--seed-posture 0,0,0,0,0,900", "--seed-posture"},
           {"--orientation 1,2", "--orientation"},
           {"--unmodelled -1", "--unmodelled"}}) {
    const test_support::CliRun run =
        test_support::runCli(base + options, test_support::Stderr::Only);
    EXPECT_EQ(run.status, 2) << options << ": " << run.out;
    EXPECT_NE(run.out.find(named), std::string::npos) << run.out;
  }
  std::filesystem::remove(plain);
  for (const auto& [block, pointer] : std::vector<std::pair<nlohmann::json, std::string>>{
           {{{"test", "iso9283"}, {"cube", {{"center", {0, 300, 200}}}}}, "/acceptance/cube/edge"},
           {{{"test", "iso9283"},
             {"cube", {{"center", {0, 300, 200}}, {"edge", 200}}},
             {"center", {0, 0, 0}}},
            "/acceptance/center"},
           {{{"test", "iso9283"},
             {"cube", {{"center", {0, 300, 200}}, {"edge", 200}, {"orientation", {0, 0}}}}},
            "/acceptance/cube/orientation"},
           {{{"test", "iso9283"},
             {"cube", 200},
             {"center", {0, 300, 200}},
             {"seed_posture", {1, 2, 3}}},
            "/acceptance/seed_posture"},
           {{{"test", "iso9283"},
             {"cube", 200},
             {"center", {0, 300, 200}},
             {"seed_posture", {0, 0, 0, 0, 0, 400}}},
            "/acceptance/seed_posture/5"},
           {{{"test", "iso9283"}, {"cube", 200}, {"center", {0, 300, 200}}, {"unmodelled", -0.1}},
            "/acceptance/unmodelled"}}) {
    const std::string path = writePlan(block, "bad");
    const test_support::CliRun run =
        test_support::runCli("check " + path, test_support::Stderr::Only);
    std::filesystem::remove(path);
    EXPECT_EQ(run.status, 2) << block.dump();
    EXPECT_NE(run.out.find(pointer), std::string::npos) << block.dump() << ": " << run.out;
  }
}

}  // namespace pose_set_up_test
}  // namespace artcal
