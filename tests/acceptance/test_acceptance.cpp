// artcal acceptance (spec acceptance.md): the ISO 10360-2 prediction's linear statistics against
// an independent dense computation (the spec's layout rebuilt here, central differences of the
// length error through the public forward kinematics, V_p from the evaluator), the shared
// reference case (tests/data/ref-acceptance-cmm-3planes*.json, an independent dense
// implementation), the Monte-Carlo against the closed form without systematic error and against
// the exact conditional expectation E[P(pass | dp)], thread-count invariance, a calibrated machine
// file against its plan, and the ISO 9283 points, joints and statistics.

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include <unistd.h>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "artcal/acceptance/length_acceptance.hpp"
#include "artcal/acceptance/pose_acceptance.hpp"
#include "artcal/internal.hpp"
#include "artcal/io/machine_covariance.hpp"
#include "artcal/model/cartesian.hpp"
#include "cli_runner.hpp"
#include "finite_difference.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace acceptance_test {

const char* kReferencePlan = "ref-acceptance-cmm-3planes.json";

struct Prepared {
  Plan plan;
  AcceptanceInput input;
};

Prepared prepare(const std::string& path) {
  Prepared prepared{loadPlan(path), {}};
  const Evaluation evaluation = evaluatePlan(prepared.plan);
  auto input = acceptanceInputFromPlan(prepared.plan, evaluation);
  EXPECT_TRUE(input.has_value());
  prepared.input = *input;
  prepared.input.machine = &prepared.plan.machine;
  return prepared;
}

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

LengthTestOptions referenceOptions() {
  LengthTestOptions options;
  options.mpe = *parseMpe("2.3 + L/2600");
  return options;
}

// ------------------------------------------------------------------------------ dense oracle

/// The gauges of the spec rebuilt: the tip box from the axis ranges (nominal corners), the 4
/// diagonals then x, y, z, ends at c -+ L/2 u; each end's axis readings solved by Newton on the
/// public forward kinematics.
struct OracleGauge {
  Eigen::Vector3d u, a, b;
  double length;
};

/// Centre and half-extents of the box of stylus `stylus`'s tip over the axis ranges of
/// `machine` (its nominal corners), through `mech`'s public forward kinematics.
std::pair<Eigen::Vector3d, Eigen::Vector3d> cornerBox(const Mechanism& mech, const Machine& machine,
                                                      int stylus) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (int corner = 0; corner < 8; ++corner) {
    Eigen::VectorXd q(3), x;
    for (int k = 0; k < 3; ++k) q[k] = machine.joint_limits[k][(corner >> k) & 1];
    EXPECT_EQ(mech.forwardStylus(stylus, machine.nominal, q, x), ForwardStatus::Ok);
    lo = lo.cwiseMin(x.head<3>());
    hi = hi.cwiseMax(x.head<3>());
  }
  return {0.5 * (lo + hi), 0.5 * (hi - lo)};
}

std::vector<OracleGauge> oracleGauges(const Machine& machine) {
  const auto [c, h] = cornerBox(*machine.mechanism, machine, 0);
  std::vector<Eigen::Vector3d> directions = {Eigen::Vector3d(h.x(), h.y(), h.z()).normalized(),
                                             Eigen::Vector3d(-h.x(), h.y(), h.z()).normalized(),
                                             Eigen::Vector3d(h.x(), -h.y(), h.z()).normalized(),
                                             Eigen::Vector3d(-h.x(), -h.y(), h.z()).normalized(),
                                             Eigen::Vector3d::UnitX(),
                                             Eigen::Vector3d::UnitY(),
                                             Eigen::Vector3d::UnitZ()};
  std::vector<OracleGauge> gauges;
  for (const Eigen::Vector3d& u : directions) {
    double D = 1e300;
    for (int i = 0; i < 3; ++i)
      if (std::abs(u[i]) > 0) D = std::min(D, 2.0 * h[i] / std::abs(u[i]));
    for (double f : {0.1, 0.3, 0.5, 0.7, 0.9})
      gauges.push_back({u, c - 0.5 * f * D * u, c + 0.5 * f * D * u, f * D});
  }
  return gauges;
}

/// Readings putting stylus 0 on `tip` at parameters p: Newton with a finite-difference Jacobian.
Eigen::VectorXd solveReadings(const Mechanism& mech, const Eigen::VectorXd& p,
                              const Eigen::Vector3d& tip) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(3);
  auto f = [&](const Eigen::VectorXd& qq) {
    Eigen::VectorXd x;
    EXPECT_EQ(mech.forwardStylus(0, p, qq, x), ForwardStatus::Ok);
    return Eigen::VectorXd(x.head<3>());
  };
  for (int it = 0; it < 20; ++it) {
    const Eigen::MatrixXd J = testing::centralDifferenceJacobian(f, q, 1e-3);
    q -= J.fullPivLu().solve(f(q) - tip);
  }
  EXPECT_LT((f(q) - tip).norm(), 1e-9);
  return q;
}

TEST(LengthTest, LinearStatisticsMatchADenseFiniteDifferenceComputation) {
  const Prepared prepared = prepare(test_support::planFile("cmm-plate-3planes-2styli.json"));
  const Machine& machine = prepared.plan.machine;
  const Mechanism& mech = *machine.mechanism;
  const Eigen::MatrixXd& V = prepared.input.uncertainty.V;
  const LengthTestPrediction prediction =
      predictLengthTestLinear(prepared.input, referenceOptions());
  const std::vector<OracleGauge> oracle = oracleGauges(machine);
  ASSERT_EQ(prediction.gauges.size(), oracle.size());
  const double s_p = prepared.plan.noise.probe;
  for (std::size_t i = 0; i < oracle.size(); ++i) {
    const OracleGauge& o = oracle[i];
    const Gauge& gauge = prediction.gauges[i];
    EXPECT_LT((gauge.a - o.a).norm(), 1e-9);
    EXPECT_LT((gauge.b - o.b).norm(), 1e-9);
    EXPECT_NEAR(gauge.length, o.length, 1e-9);
    const Eigen::VectorXd q_a = solveReadings(mech, machine.nominal, o.a);
    const Eigen::VectorXd q_b = solveReadings(mech, machine.nominal, o.b);
    // E(p) = u . (x_b - x_a) - L over the calibrated parameters; the model is nearly linear.
    auto lengthError = [&](const Eigen::VectorXd& dp) {
      const Eigen::VectorXd p =
          machine.withCalibrated(machine.nominal, machine.calibratedValues(machine.nominal) + dp);
      Eigen::VectorXd xa, xb;
      EXPECT_EQ(mech.forwardStylus(0, p, q_a, xa), ForwardStatus::Ok);
      EXPECT_EQ(mech.forwardStylus(0, p, q_b, xb), ForwardStatus::Ok);
      return Eigen::VectorXd::Constant(1, o.u.dot((xb - xa).head<3>()) - o.length);
    };
    const Eigen::RowVectorXd g = testing::centralDifferenceJacobian(
        lengthError, Eigen::VectorXd::Zero(machine.calibratedCount()), 1e-6);
    const double sigma_sys = std::sqrt((g * V * g.transpose())(0, 0));
    EXPECT_NEAR(gauge.sigma_sys, sigma_sys, 1e-6 * sigma_sys) << "gauge " << i;
    // Noise: probing at both ends, encoders through dx/dq (central differences).
    double variance = 2.0 * s_p * s_p;
    for (const Eigen::VectorXd* q : {&q_a, &q_b}) {
      auto along = [&](const Eigen::VectorXd& qq) {
        Eigen::VectorXd x;
        EXPECT_EQ(mech.forwardStylus(0, machine.nominal, qq, x), ForwardStatus::Ok);
        return Eigen::VectorXd::Constant(1, o.u.dot(x.head<3>()));
      };
      const Eigen::RowVectorXd dq = testing::centralDifferenceJacobian(along, *q, 1e-3);
      for (int k = 0; k < 3; ++k) {
        const double s_q = prepared.plan.noise.encoder[k];
        variance += dq[k] * dq[k] * s_q * s_q;
      }
    }
    EXPECT_NEAR(gauge.sigma_noise, std::sqrt(variance), 1e-6 * std::sqrt(variance));
  }
}

// E150 rebuilt apart: a machine with two styli, stylus 0 and stylus 0 moved 150 mm along x (then
// y) across the z ram; the box of the moved stylus' tip over the axis ranges; its yz (then xz)
// face diagonal through the box centre; readings by Newton with the moved stylus; g by central
// differences of u . (x_b - x_a) over the calibrated parameters.
TEST(LengthTest, StylusOffsetE150MatchesADenseFiniteDifferenceComputation) {
  const Prepared prepared = prepare(test_support::planFile("cmm-plate-3planes-2styli.json"));
  const Machine& machine = prepared.plan.machine;
  const auto& cmm = dynamic_cast<const Cartesian&>(*machine.mechanism);
  ASSERT_EQ(cmm.axes().back().direction, Eigen::Vector3d::UnitZ());
  LengthTestOptions options = referenceOptions();
  options.stylus_offset = 150.0;
  const LengthTestPrediction prediction = predictLengthTestLinear(prepared.input, options);
  ASSERT_EQ(prediction.lines, 2);
  ASSERT_EQ(prediction.gauges.size(), 10u);
  const Eigen::MatrixXd& V = prepared.input.uncertainty.V;
  for (int position = 0; position < 2; ++position) {
    const Eigen::Vector3d offset = 150.0 * Eigen::Vector3d::Unit(position);  // x, then y
    const Cartesian two(cmm.axes(), cmm.degree(), {cmm.styli()[0], cmm.styli()[0] + offset});
    const auto [c, h] = cornerBox(two, machine, 1);
    const int other = 1 - position;  // the face spanned by the other horizontal axis and z
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    u[other] = h[other];
    u.z() = h.z();
    u.normalize();
    const double D = 2.0 * std::min(h[other] / std::abs(u[other]), h.z() / std::abs(u.z()));
    auto tipOf = [&](const Eigen::VectorXd& p, const Eigen::VectorXd& q) {
      Eigen::VectorXd x;
      EXPECT_EQ(two.forwardStylus(1, p, q, x), ForwardStatus::Ok);
      return Eigen::VectorXd(x.head<3>());
    };
    auto readings = [&](const Eigen::Vector3d& tip) {
      Eigen::VectorXd q = Eigen::VectorXd::Zero(3);
      for (int it = 0; it < 20; ++it) {
        auto f = [&](const Eigen::VectorXd& qq) { return tipOf(machine.nominal, qq); };
        const Eigen::MatrixXd J = testing::centralDifferenceJacobian(f, q, 1e-3);
        q -= J.fullPivLu().solve(f(q) - tip);
      }
      return q;
    };
    for (int i = 0; i < 5; ++i) {
      const Gauge& gauge = prediction.gauges[static_cast<std::size_t>(5 * position + i)];
      const double f = 0.1 + 0.2 * i, length = f * D;
      const Eigen::Vector3d a = c - 0.5 * length * u, b = c + 0.5 * length * u;
      EXPECT_EQ(gauge.line, position);
      EXPECT_EQ(gauge.kind, position == 0 ? "yz-face" : "xz-face");
      EXPECT_LT((gauge.stylus_offset - offset).norm(), 1e-12);
      EXPECT_LT((gauge.direction - u).norm(), 1e-12);
      EXPECT_NEAR(gauge.length, length, 1e-9);
      EXPECT_LT((gauge.a - a).norm(), 1e-9);
      EXPECT_LT((gauge.b - b).norm(), 1e-9);
      const Eigen::VectorXd q_a = readings(a), q_b = readings(b);
      EXPECT_LT((tipOf(machine.nominal, q_a) - a).norm(), 1e-9);
      auto lengthError = [&](const Eigen::VectorXd& dp) {
        const Eigen::VectorXd p =
            machine.withCalibrated(machine.nominal, machine.calibratedValues(machine.nominal) + dp);
        return Eigen::VectorXd::Constant(1, u.dot(tipOf(p, q_b) - tipOf(p, q_a)) - length);
      };
      const Eigen::RowVectorXd g = testing::centralDifferenceJacobian(
          lengthError, Eigen::VectorXd::Zero(machine.calibratedCount()), 1e-6);
      const double sigma_sys = std::sqrt((g * V * g.transpose())(0, 0));
      EXPECT_NEAR(gauge.sigma_sys, sigma_sys, 1e-6 * sigma_sys) << position << " " << i;
    }
  }
}

// The ram's roll about its own axis (z.rz) moves an offset tip across the ram and leaves a tip on
// the ram's line where it is: an uncalibrated z.rz.1 is named by E150 on both positions, by E0 on
// none of its lines.
TEST(LengthTest, StylusOffsetE150NamesTheRamsRollThatE0CannotSee) {
  Prepared prepared = prepare(test_support::planFile("cmm-plate-3planes-2styli.json"));
  const auto& params = prepared.plan.machine.mechanism->parameters();
  const auto roll = std::find_if(params.begin(), params.end(),
                                 [](const ParameterInfo& p) { return p.name == "z.rz.1"; });
  ASSERT_NE(roll, params.end());
  const int k = static_cast<int>(roll - params.begin());
  auto& indices = prepared.input.uncertainty.indices;
  const auto at = std::find(indices.begin(), indices.end(), k);
  if (at != indices.end()) {  // take it out of the covariance: exact, as if never calibrated
    const auto column = static_cast<Eigen::Index>(at - indices.begin());
    std::vector<int> keep;
    for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(indices.size()); ++i)
      if (i != column) keep.push_back(static_cast<int>(i));
    prepared.input.uncertainty.V = Eigen::MatrixXd(prepared.input.uncertainty.V(keep, keep));
    indices.erase(at);
  }
  auto named = [&](const LengthTestPrediction& prediction) {
    for (const UnseenParameter& unseen : prediction.unseen)
      if (unseen.parameter == k) return unseen.lines;
    return std::vector<int>{};
  };
  LengthTestOptions options = referenceOptions();
  EXPECT_TRUE(named(predictLengthTestLinear(prepared.input, options)).empty());
  options.stylus_offset = 150.0;
  EXPECT_EQ(named(predictLengthTestLinear(prepared.input, options)), (std::vector<int>{0, 1}));
}

// --------------------------------------------------------------------------- reference case

TEST(LengthTest, SharedReferenceCase) {
  const Prepared prepared = prepare(test_support::testDataFile(kReferencePlan));
  const nlohmann::json expected =
      readJson(test_support::testDataFile("ref-acceptance-cmm-3planes.expected.json"));
  std::vector<std::string> calibrated;
  for (int k : prepared.input.uncertainty.indices)
    calibrated.push_back(prepared.plan.machine.mechanism->parameters()[k].name);
  EXPECT_EQ(calibrated, expected["calibrated"].get<std::vector<std::string>>());
  LengthTestOptions options = referenceOptions();
  const LengthTestPrediction prediction = predictLengthTest(prepared.input, options);
  const auto& items = expected["items"];
  ASSERT_EQ(prediction.gauges.size(), items.size());
  for (std::size_t i = 0; i < items.size(); ++i) {
    const Gauge& gauge = prediction.gauges[i];
    const auto& item = items[i];
    EXPECT_EQ(gauge.line, item["line"].get<int>());
    EXPECT_EQ(gauge.kind, item["kind"].get<std::string>());
    EXPECT_NEAR(gauge.length, item["length"].get<double>(), 1e-9);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(gauge.a[k], item["a"][k].get<double>(), 1e-9);
      EXPECT_NEAR(gauge.b[k], item["b"][k].get<double>(), 1e-9);
    }
    const double sys = item["sigma_sys"].get<double>();
    EXPECT_NEAR(gauge.sigma_sys, sys, 1e-6 * sys) << "item " << i;
    const double noise = item["sigma_noise"].get<double>();
    EXPECT_NEAR(gauge.sigma_noise, noise, 1e-9 * noise) << "item " << i;
    EXPECT_NEAR(gauge.mpe / kMmPerMicrometre, item["mpe_um"].get<double>(), 1e-12);
  }
  const MonteCarloSummary& mc = prediction.monte_carlo;
  const double se = std::hypot(mc.p_pass_standard_error, expected["p_pass_se"].get<double>());
  EXPECT_NEAR(mc.p_pass, expected["p_pass"].get<double>(), 3.0 * se);
  EXPECT_TRUE(mc.stable);
  EXPECT_LE(mc.p_pass_standard_error, 0.002);
  // The 95 % quantile is stable to 1 % (the adaptive criterion): within 2 % of the reference's.
  EXPECT_NEAR(mc.statistic.q95, expected["quantiles"]["95"].get<double>(),
              0.02 * expected["quantiles"]["95"].get<double>());
  EXPECT_NEAR(mc.statistic.median, expected["quantiles"]["50"].get<double>(),
              0.02 * expected["quantiles"]["50"].get<double>());
}

// ---------------------------------------------------------------------------- Monte-Carlo

TEST(LengthTest, WithoutSystematicErrorMatchesTheClosedForm) {
  Prepared prepared = prepare(test_support::testDataFile(kReferencePlan));
  prepared.input.uncertainty.V.setZero();
  LengthTestOptions options = referenceOptions();
  const LengthTestPrediction linear = predictLengthTestLinear(prepared.input, options);
  // prod_i P(|N(0, s_i)| <= MPE_i) over the 105 results, written out here.
  double closed_form = 1.0;
  for (const Gauge& gauge : linear.gauges)
    closed_form *= std::pow(std::erf(gauge.mpe / (gauge.sigma_noise * std::sqrt(2.0))), 3);
  const LinearGaussianTest model = lengthTestModel(linear, prepared.input);
  EXPECT_NEAR(passProbabilityWithoutSystematic(model), closed_form, 1e-12);
  options.monte_carlo.trials = 100000;
  const MonteCarloSummary mc = runMonteCarlo(model, options.monte_carlo);
  EXPECT_NEAR(mc.p_pass, closed_form, 3.0 * mc.p_pass_standard_error);
}

TEST(LengthTest, PassProbabilityLiesBetweenItsBounds) {
  // docs/method.md section 9: Anderson's theorem bounds P(pass) above by the closed form without
  // systematic error, the Gaussian correlation inequality below by the product of the results'
  // own pass probabilities (each with its total standard deviation).
  const Prepared prepared = prepare(test_support::testDataFile(kReferencePlan));
  const LengthTestPrediction prediction = predictLengthTest(prepared.input, referenceOptions());
  double upper = 1.0, lower = 1.0;
  for (const Gauge& gauge : prediction.gauges) {
    upper *= std::pow(std::erf(gauge.mpe / (gauge.sigma_noise * std::sqrt(2.0))), 3);
    const double total = std::hypot(gauge.sigma_sys, gauge.sigma_noise);
    lower *= std::pow(std::erf(gauge.mpe / (total * std::sqrt(2.0))), 3);
  }
  const MonteCarloSummary& mc = prediction.monte_carlo;
  EXPECT_LT(lower, upper);
  EXPECT_GE(mc.p_pass, lower - 3.0 * mc.p_pass_standard_error);
  EXPECT_LE(mc.p_pass, upper + 3.0 * mc.p_pass_standard_error);
}

/// E[P(pass | dp)] by plain averaging over draws of dp: an estimator of P(pass) whose own
/// standard error is known, independent of the Monte-Carlo's noise draws.
struct ConditionalEstimate {
  double p = 0.0, standard_error = 0.0;
};

ConditionalEstimate conditionalEstimate(const LinearGaussianTest& model, int draws,
                                        std::uint64_t seed) {
  NormalSource normal(seed);
  double sum = 0.0, sum2 = 0.0;
  Eigen::VectorXd z(model.A.cols());
  for (int t = 0; t < draws; ++t) {
    for (Eigen::Index k = 0; k < z.size(); ++k) z[k] = normal();
    const double p = conditionalPassProbability(model, model.A * z);
    sum += p;
    sum2 += p * p;
  }
  const double mean = sum / draws;
  return {mean, std::sqrt(std::max(0.0, sum2 / draws - mean * mean) / draws)};
}

TEST(LengthTest, MonteCarloAgreesWithTheConditionalExpectation) {
  const Prepared prepared = prepare(test_support::testDataFile(kReferencePlan));
  const LengthTestPrediction linear = predictLengthTestLinear(prepared.input, referenceOptions());
  const LinearGaussianTest model = lengthTestModel(linear, prepared.input);
  MonteCarloOptions options;
  const MonteCarloSummary mc = runMonteCarlo(model, options);
  const ConditionalEstimate conditional = conditionalEstimate(model, 20000, 99);
  EXPECT_NEAR(mc.p_pass, conditional.p,
              3.0 * std::hypot(mc.p_pass_standard_error, conditional.standard_error));
}

TEST(LengthTest, SameSeedSameAnswerWhateverTheThreadCount) {
  const Prepared prepared = prepare(test_support::testDataFile(kReferencePlan));
  const LengthTestPrediction linear = predictLengthTestLinear(prepared.input, referenceOptions());
  const LinearGaussianTest model = lengthTestModel(linear, prepared.input);
  MonteCarloOptions options;
  options.trials = 23500;  // not a multiple of the chunk
  options.threads = 1;
  const MonteCarloSummary one = runMonteCarlo(model, options);
  options.threads = 3;
  const MonteCarloSummary three = runMonteCarlo(model, options);
  EXPECT_EQ(one.trials, 23500);
  EXPECT_EQ(one.p_pass, three.p_pass);
  EXPECT_EQ(one.statistic.q95, three.statistic.q95);
  EXPECT_EQ(one.statistic.median, three.statistic.median);
}

TEST(LengthTest, MeanConditionalPassProbabilityOverDrawsAgreesWithTheMonteCarlo) {
  const Prepared prepared = prepare(test_support::testDataFile(kReferencePlan));
  const LengthTestPrediction linear = predictLengthTestLinear(prepared.input, referenceOptions());
  const LinearGaussianTest model = lengthTestModel(linear, prepared.input);
  NormalSource normal(5);
  Eigen::MatrixXd Z(model.A.cols(), 4000);
  for (Eigen::Index m = 0; m < Z.cols(); ++m)
    for (Eigen::Index k = 0; k < Z.rows(); ++k) Z(k, m) = normal();
  const Eigen::MatrixXd S = model.A * Z;
  // Each draw's P(pass | s) as conditionalPassProbability gives it over the 105 results.
  double sum = 0.0, sum2 = 0.0;
  for (Eigen::Index m = 0; m < S.cols(); ++m) {
    const double p = conditionalPassProbability(model, S.col(m));
    sum += p;
    sum2 += p * p;
  }
  const double mean = sum / static_cast<double>(S.cols());
  EXPECT_NEAR(meanConditionalPassProbability(linear, S), mean, 1e-12);
  const double se = std::sqrt((sum2 / static_cast<double>(S.cols()) - mean * mean) /
                              static_cast<double>(S.cols()));
  const double expected =
      readJson(test_support::testDataFile("ref-acceptance-cmm-3planes.expected.json"))["p_pass"]
          .get<double>();
  EXPECT_NEAR(mean, expected, 3.0 * se);
}

TEST(LengthTest, PosteriorScalesTheMachinesCovarianceByItsBirgeRatio) {
  const Prepared prepared = prepare(test_support::testDataFile(kReferencePlan));
  ParameterUncertainty uncertainty = prepared.input.uncertainty;
  uncertainty.birge_ratio = 1.5;
  const AcceptanceInput prior =
      acceptanceInputFromMachine(prepared.plan, prepared.plan.machine.nominal, uncertainty, false);
  const AcceptanceInput posterior =
      acceptanceInputFromMachine(prepared.plan, prepared.plan.machine.nominal, uncertainty, true);
  const LengthTestPrediction a = predictLengthTestLinear(prior, referenceOptions());
  const LengthTestPrediction b = predictLengthTestLinear(posterior, referenceOptions());
  for (std::size_t i = 0; i < a.gauges.size(); ++i) {
    EXPECT_NEAR(b.gauges[i].sigma_sys, 1.5 * a.gauges[i].sigma_sys, 1e-12);
    EXPECT_EQ(b.gauges[i].sigma_noise, a.gauges[i].sigma_noise);  // the plan's noise
  }
}

TEST(LengthTest, MpeParsing) {
  const auto mpe = parseMpe("1.5 + L/333");
  ASSERT_TRUE(mpe);
  EXPECT_DOUBLE_EQ(mpe->at(333.0), 2.5e-3);
  EXPECT_TRUE(parseMpe("2+L/1000"));
  EXPECT_DOUBLE_EQ(parseMpe("3")->at(500.0), 3e-3);
  std::string error;
  for (const char* bad : {"", "L/333", "1.5 + L", "-1 + L/3", "1.5 + L/0", "abc", "1.5 - L/3"})
    EXPECT_FALSE(parseMpe(bad, &error)) << bad;
}

TEST(LengthTest, UncalibratedParametersTheResultsDependOnAreNamed) {
  const Prepared prepared = prepare(test_support::testDataFile(kReferencePlan));
  const LengthTestPrediction linear = predictLengthTestLinear(prepared.input, referenceOptions());
  // Every parameter outside V_p whose derivative is not zero on some line is named, with it.
  for (int j = 0; j < prepared.plan.machine.mechanism->parameterCount(); ++j) {
    const auto& calibrated = prepared.input.uncertainty.indices;
    if (std::find(calibrated.begin(), calibrated.end(), j) != calibrated.end()) continue;
    std::vector<int> lines;
    int column = 0;
    for (int k = 0; k < j; ++k)
      if (std::find(calibrated.begin(), calibrated.end(), k) == calibrated.end()) ++column;
    for (const Gauge& gauge : linear.gauges)
      if (std::abs(gauge.g_exact[column]) > 1e-6 && (lines.empty() || lines.back() != gauge.line))
        lines.push_back(gauge.line);
    const auto named = std::find_if(linear.unseen.begin(), linear.unseen.end(),
                                    [j](const UnseenParameter& u) { return u.parameter == j; });
    if (lines.empty()) {
      EXPECT_EQ(named, linear.unseen.end()) << j;
    } else {
      ASSERT_NE(named, linear.unseen.end()) << j;
      EXPECT_EQ(named->lines, lines);
    }
  }
}

// ------------------------------------------------------------------- machine file vs plan

TEST(LengthTest, CalibratedMachineFileOnPlannedReadingsGivesThePlansAnswer) {
  const Prepared prepared = prepare(test_support::testDataFile(kReferencePlan));
  const Plan& plan = prepared.plan;
  const Calibration calibration = calibratePlan(plan);
  ASSERT_TRUE(calibration.summary.converged());
  ASSERT_TRUE(calibration.covariance.has_value());
  nlohmann::json machine = machineToJson(plan.machine, calibration.parameters);
  machine["covariance"] =
      covarianceToJson(plan.machine, calibration.covariance->V, calibration.birgeRatio());
  const nlohmann::json document = nlohmann::json::parse(machine.dump());
  const AcceptanceInput from_machine =
      acceptanceInputFromMachine(plan, parseTruth(document, "machine.json", plan),
                                 *parseMachineCovariance(document, "machine.json", plan), false);
  LengthTestOptions options = referenceOptions();
  options.monte_carlo.trials = 20000;
  const LengthTestPrediction a = predictLengthTest(prepared.input, options);
  const LengthTestPrediction b = predictLengthTest(from_machine, options);
  ASSERT_EQ(a.gauges.size(), b.gauges.size());
  for (std::size_t i = 0; i < a.gauges.size(); ++i) {
    EXPECT_NEAR(a.gauges[i].sigma_sys, b.gauges[i].sigma_sys, 1e-6 * a.gauges[i].sigma_sys);
    EXPECT_NEAR(a.gauges[i].sigma_noise, b.gauges[i].sigma_noise, 1e-9);
  }
  EXPECT_NEAR(a.monte_carlo.p_pass, b.monte_carlo.p_pass, 1e-3);
}

// -------------------------------------------------------------------------------- ISO 9283

TEST(PoseTest, PointsJointsAndLinearStatistics) {
  const Prepared prepared = prepare(test_support::planFile("aacmm-6axis-3bars.json"));
  const Machine& machine = prepared.plan.machine;
  PoseTestOptions options;
  options.cube = 300.0;
  options.center = Eigen::Vector3d(0.0, 300.0, 200.0);
  options.mpe = 0.05;
  options.monte_carlo.trials = 20000;
  PoseTestPrediction prediction;
  try {
    prediction = predictPoseTest(prepared.input, options);
  } catch (const RunError& e) {
    FAIL() << e.describe();
  }
  ASSERT_EQ(prediction.points.size(), 5u);
  const double h = 150.0;
  const Eigen::Vector3d c = options.center;
  const Eigen::Vector3d q1 = c + Eigen::Vector3d(-h, -h, -h), q3 = c + Eigen::Vector3d(h, h, h);
  EXPECT_LT((prediction.points[0].commanded - c).norm(), 1e-12);
  EXPECT_LT((prediction.points[1].commanded - (q1 + 0.1 * (q3 - q1))).norm(), 1e-12);
  EXPECT_LT((prediction.points[3].commanded - (q3 + 0.1 * (q1 - q3))).norm(), 1e-12);
  const Mechanism& mech = *machine.mechanism;
  for (const PosePoint& point : prediction.points) {
    Eigen::VectorXd x;
    ASSERT_EQ(mech.forward(machine.nominal, point.joints, x), ForwardStatus::Ok);
    EXPECT_LT((x.head<3>() - point.commanded).norm(), 1e-8);
    EXPECT_TRUE(machine.withinLimits(point.joints));
    auto position = [&](const Eigen::VectorXd& dp) {
      const Eigen::VectorXd p =
          machine.withCalibrated(machine.nominal, machine.calibratedValues(machine.nominal) + dp);
      Eigen::VectorXd xx;
      EXPECT_EQ(mech.forward(p, point.joints, xx), ForwardStatus::Ok);
      return Eigen::VectorXd(xx.head<3>());
    };
    const Eigen::MatrixXd J = testing::centralDifferenceJacobian(
        position, Eigen::VectorXd::Zero(machine.calibratedCount()), 1e-6);
    const double sys = std::sqrt((J * prepared.input.uncertainty.V * J.transpose()).trace());
    EXPECT_NEAR(point.sigma_sys, sys, 1e-6 * sys);
    // max AP >= each AP, and the quantiles are ordered.
    EXPECT_LE(point.ap.median, point.ap.q95);
    EXPECT_LE(point.ap.q95, prediction.max_ap.q95 + 1e-15);
  }
  // P(every AP_P <= MPE) <= P(AP_P <= MPE) for each point: the 95 % quantile of the max above the
  // MPE means P(pass) < 0.95.
  const MonteCarloSummary& mc = prediction.monte_carlo;
  EXPECT_EQ(mc.p_pass<0.95, prediction.max_ap.q95> 0.05);
}

TEST(PoseTest, WithoutSystematicErrorTheApIsTheNormOfTheMeanNoise) {
  Prepared prepared = prepare(test_support::planFile("aacmm-6axis-3bars.json"));
  prepared.input.uncertainty.V.setZero();
  PoseTestOptions options;
  options.cube = 300.0;
  options.center = Eigen::Vector3d(0.0, 300.0, 200.0);
  options.monte_carlo.trials = 50000;
  const PoseTestPrediction prediction = predictPoseTest(prepared.input, options);
  // E[AP^2] = trace of the mean noise's covariance = sigma_noise^2.
  for (const PosePoint& point : prediction.points) {
    EXPECT_EQ(point.sigma_sys, 0.0);
    // The mean of AP is below sqrt(E[AP^2]) (Jensen) and above half of it for a 3-D Gaussian.
    EXPECT_LT(point.ap.mean, point.sigma_noise);
    EXPECT_GT(point.ap.mean, 0.5 * point.sigma_noise);
  }
}

// The noise of the mean position at each point against a dense oracle: central differences of
// the public forward kinematics over the joints give J_q, and the mean of `cycles` independent
// readings has covariance J_q Sigma_q J_q^T / cycles (ISO 9283: AP_P is from the mean of the
// cycles), so sigma_noise^2 = sum_j |dx/dq_j|^2 s_j^2 / cycles for 1, 30 and 7 cycles.
TEST(PoseTest, TheNoiseOfTheMeanPositionIsTheEncoderNoiseOverTheCycles) {
  const Prepared prepared = prepare(test_support::planFile("aacmm-6axis-3bars.json"));
  const Machine& machine = prepared.plan.machine;
  const Eigen::VectorXd& s_q = prepared.plan.noise.encoder;
  ASSERT_EQ(s_q.size(), machine.jointCount());
  ASSERT_GT(s_q.maxCoeff(), 0.0);
  for (const int cycles : {1, 30, 7}) {
    PoseTestOptions options;
    options.cube = 300.0;
    options.center = Eigen::Vector3d(0.0, 300.0, 200.0);
    options.cycles = cycles;
    const PoseTestPrediction prediction = predictPoseTestLinear(prepared.input, options);
    ASSERT_EQ(prediction.points.size(), 5u);
    for (const PosePoint& point : prediction.points) {
      auto position = [&](const Eigen::VectorXd& q) {
        Eigen::VectorXd x;
        EXPECT_EQ(machine.mechanism->forward(machine.nominal, q, x), ForwardStatus::Ok);
        return Eigen::VectorXd(x.head<3>());
      };
      const Eigen::MatrixXd J_q = testing::centralDifferenceJacobian(position, point.joints, 1e-6);
      double variance = 0.0;
      for (int j = 0; j < J_q.cols(); ++j) variance += J_q.col(j).squaredNorm() * s_q[j] * s_q[j];
      const double expected = std::sqrt(variance / cycles);
      EXPECT_NEAR(point.sigma_noise, expected, 1e-6 * expected) << cycles << " cycles";
      EXPECT_NEAR(point.noise_covariance.trace(), variance / cycles, 1e-6 * variance / cycles);
    }
  }
}

// ------------------------------------------------------------------------------ command line

TEST(AcceptanceCli, JsonCarriesEveryItemAndTheStatistics) {
  const test_support::CliRun run =
      test_support::runCli("acceptance " + test_support::testDataFile(kReferencePlan) +
                           " --test iso10360-2 --mpe '2.3 + L/2600' --trials 20000 --json");
  ASSERT_EQ(run.status, 0) << run.out;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  ASSERT_EQ(out["items"].size(), 35u);
  for (const char* field : {"a", "b", "length", "sigma_sys", "sigma_noise", "sigma_sys_um"})
    EXPECT_TRUE(out["items"][0].contains(field)) << field;
  EXPECT_EQ(out["results"], 105);
  EXPECT_TRUE(out["p_pass"].is_number());
  EXPECT_TRUE(out["p_pass_standard_error"].is_number());
  EXPECT_TRUE(out["quantiles"]["95"].is_number());
}

TEST(AcceptanceCli, MachineFileFromCalibrateGivesThePlansAnswer) {
  const std::string plan = test_support::testDataFile(kReferencePlan);
  const std::string machine =
      (std::filesystem::temp_directory_path() /
       ("artcal-acceptance-machine-" + std::to_string(::getpid()) + ".json"))
          .string();
  ASSERT_EQ(test_support::runCli("calibrate " + plan + " --write-machine " + machine).status, 0);
  const std::string test = " --test iso10360-2 --mpe '2.3 + L/2600' --trials 20000 --json";
  const test_support::CliRun from_plan = test_support::runCli("acceptance " + plan + test);
  const test_support::CliRun from_machine =
      test_support::runCli("acceptance " + machine + " --plan " + plan + test);
  std::filesystem::remove(machine);
  ASSERT_EQ(from_plan.status, 0);
  ASSERT_EQ(from_machine.status, 0);
  const nlohmann::json a = nlohmann::json::parse(from_plan.out);
  const nlohmann::json b = nlohmann::json::parse(from_machine.out);
  for (std::size_t i = 0; i < a["items"].size(); ++i) {
    const double sys = a["items"][i]["sigma_sys"].get<double>();
    EXPECT_NEAR(b["items"][i]["sigma_sys"].get<double>(), sys, 1e-6 * sys);
  }
  EXPECT_NEAR(a["p_pass"].get<double>(), b["p_pass"].get<double>(), 1e-3);
  EXPECT_EQ(a["calibrated"], b["calibrated"]);
}

/// The reference plan with `block` as its "acceptance" member, written to a temporary file.
std::string planWithAcceptance(const nlohmann::json& block, const std::string& tag) {
  nlohmann::json plan = readJson(test_support::testDataFile(kReferencePlan));
  plan["acceptance"] = block;
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("artcal-acceptance-" + tag + "-" + std::to_string(::getpid()) + ".json"))
          .string();
  std::ofstream(path) << plan.dump();
  return path;
}

TEST(AcceptanceCli, ThePlansAcceptanceBlockNamesTheTest) {
  const std::string path =
      planWithAcceptance({{"test", "iso10360-2"}, {"mpe", "2.3 + L/2600"}}, "block");
  const test_support::CliRun from_block =
      test_support::runCli("acceptance " + path + " --trials 20000 --json");
  const test_support::CliRun from_options = test_support::runCli(
      "acceptance " + path + " --test iso10360-2 --mpe '2.3 + L/2600' --trials 20000 --json");
  std::filesystem::remove(path);
  ASSERT_EQ(from_block.status, 0);
  ASSERT_EQ(from_options.status, 0);
  EXPECT_EQ(nlohmann::json::parse(from_block.out), nlohmann::json::parse(from_options.out));
}

TEST(AcceptanceCli, TheReportShowsThePlansAcceptanceTest) {
  const std::string path =
      planWithAcceptance({{"test", "iso10360-2"}, {"mpe", "2.3 + L/2600"}}, "report");
  const std::string html = path + ".html";
  const test_support::CliRun report = test_support::runCli("report " + path + " -o " + html);
  const test_support::CliRun acceptance = test_support::runCli("acceptance " + path + " --json");
  std::filesystem::remove(path);
  ASSERT_EQ(report.status, 0);
  ASSERT_EQ(acceptance.status, 0);
  std::ifstream in(html);
  const std::string page((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(html);
  EXPECT_NE(page.find("<h2>Acceptance test predicted</h2>"), std::string::npos);
  EXPECT_NE(page.find("id=\"figure-acceptance-e-vs-l\""), std::string::npos);
  // The same prediction as `artcal acceptance` (same default seed and trials).
  char expected[64];
  std::snprintf(expected, sizeof expected, "P(pass) = %.3f",
                nlohmann::json::parse(acceptance.out)["p_pass"].get<double>());
  EXPECT_NE(page.find(expected), std::string::npos) << expected;
}

/// The data-value of `page`'s cell whose data-field is `field`; empty when absent.
std::string dataValue(const std::string& page, const std::string& field) {
  const std::string key = "data-field=\"" + field + "\" data-value=\"";
  const std::size_t at = page.find(key);
  if (at == std::string::npos) return {};
  const std::size_t begin = at + key.size();
  return page.substr(begin, page.find('"', begin) - begin);
}

/// `report --json` and `report` (HTML, text) of `plan`, and `acceptance --json` of the same plan.
struct ReportRun {
  nlohmann::json summary, acceptance;
  std::string page, text;
};

ReportRun reportAndAcceptance(const std::string& plan) {
  const std::string html = plan + ".html";
  const test_support::CliRun json =
      test_support::runCli("report " + plan + " -o " + html + " --json");
  const test_support::CliRun text = test_support::runCli("report " + plan + " -o " + html);
  const test_support::CliRun acceptance = test_support::runCli("acceptance " + plan + " --json");
  std::ifstream in(html);
  ReportRun run;
  run.page.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  std::filesystem::remove(html);
  EXPECT_EQ(json.status, 0) << json.out;
  EXPECT_EQ(text.status, 0) << text.out;
  EXPECT_EQ(acceptance.status, 0) << acceptance.out;
  if (json.status != 0 || acceptance.status != 0) return run;
  run.summary = nlohmann::json::parse(json.out);
  run.acceptance = nlohmann::json::parse(acceptance.out);
  run.text = text.out;
  return run;
}

TEST(AcceptanceCli, TheReportShowsThePlansIso9283Test) {
  // A serial arm (serial-dh) whose plan names an ISO 9283 test.
  nlohmann::json document = readJson(test_support::planFile("aacmm-6axis-3bars.json"));
  document["acceptance"] = {
      {"test", "iso9283"}, {"cube", 300}, {"center", {0, 300, 200}}, {"mpe", 0.05}};
  const std::string plan = (std::filesystem::temp_directory_path() /
                            ("artcal-report-iso9283-" + std::to_string(::getpid()) + ".json"))
                               .string();
  std::ofstream(plan) << document.dump();
  const ReportRun run = reportAndAcceptance(plan);
  std::filesystem::remove(plan);
  ASSERT_TRUE(run.acceptance.is_object());
  // The JSON twin carries exactly what `artcal acceptance --json` prints for the same plan.
  EXPECT_EQ(run.summary["acceptance"], run.acceptance);
  // The HTML shows the 5 points, their joints, AP_P (mean, 50 %, 95 %) and P(pass), with the
  // exact values of `acceptance --json` in data-value.
  EXPECT_NE(run.page.find("<h2>Acceptance test predicted</h2>"), std::string::npos);
  const nlohmann::json& items = run.acceptance["items"];
  ASSERT_EQ(items.size(), 5u);
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string at = "/acceptance/items/" + std::to_string(i);
    for (const char* field : {"/ap/mean", "/ap/50", "/ap/95", "/sigma_sys", "/commanded/1"}) {
      const std::string shown = dataValue(run.page, at + field);
      ASSERT_FALSE(shown.empty()) << at + field;
      EXPECT_EQ(std::stod(shown),
                items[i].at(nlohmann::json::json_pointer(std::string(field))).get<double>())
          << at + field;
    }
    const std::string joints = dataValue(run.page, at + "/joints");
    ASSERT_FALSE(joints.empty());
    EXPECT_EQ(nlohmann::json::parse(joints), items[i]["joints"]);
  }
  for (const char* field : {"/p_pass", "/p_pass_standard_error", "/max_ap/95"}) {
    const std::string shown = dataValue(run.page, std::string("/acceptance") + field);
    ASSERT_FALSE(shown.empty()) << field;
    EXPECT_EQ(std::stod(shown),
              run.acceptance.at(nlohmann::json::json_pointer(field)).get<double>());
  }
  // The text twin prints the `acceptance` table's P(pass) line.
  char line[80];
  std::snprintf(line, sizeof line, "P(every AP_P <= 0.05 mm) = %.4f",
                run.acceptance["p_pass"].get<double>());
  EXPECT_NE(run.text.find(line), std::string::npos) << run.text;
}

TEST(AcceptanceCli, TheReportsJsonTwinCarriesTheIso10360Prediction) {
  const std::string plan =
      planWithAcceptance({{"test", "iso10360-2"}, {"mpe", "2.3 + L/2600"}}, "report-json");
  const ReportRun run = reportAndAcceptance(plan);
  std::filesystem::remove(plan);
  ASSERT_TRUE(run.acceptance.is_object());
  EXPECT_EQ(run.summary["acceptance"], run.acceptance);
  for (const char* field : {"/p_pass", "/quantiles/95"}) {
    const std::string shown = dataValue(run.page, std::string("/acceptance") + field);
    ASSERT_FALSE(shown.empty()) << field;
    EXPECT_EQ(std::stod(shown),
              run.acceptance.at(nlohmann::json::json_pointer(field)).get<double>());
  }
}

TEST(AcceptanceCli, AMalformedAcceptanceBlockIsRefusedAtLoad) {
  for (const auto& [block, pointer] : std::vector<std::pair<nlohmann::json, std::string>>{
           {{{"test", "iso10360"}, {"mpe", "1 + L/3"}}, "/acceptance/test"},
           {{{"test", "iso10360-2"}, {"mpe", "1 + L"}}, "/acceptance/mpe"},
           {{{"test", "iso10360-2"}}, "/acceptance"},
           {{{"test", "iso9283"}, {"cube", -1}, {"center", {0, 0, 0}}}, "/acceptance/cube"},
           {{{"test", "iso10360-2"}, {"mpe", "1"}, {"mpee", 2}}, "/acceptance"}}) {
    const std::string path = planWithAcceptance(block, "bad");
    const test_support::CliRun run =
        test_support::runCli("check " + path, test_support::Stderr::Only);
    std::filesystem::remove(path);
    EXPECT_EQ(run.status, 2) << block.dump();
    EXPECT_NE(run.out.find(pointer), std::string::npos) << run.out;
  }
}

TEST(AcceptanceCli, PoseTestOfASerialArm) {
  const test_support::CliRun run = test_support::runCli(
      "acceptance " + test_support::planFile("aacmm-6axis-3bars.json") +
      " --test iso9283 --cube 300 --center 0,300,200 --mpe 0.05 --trials 10000 --json");
  ASSERT_EQ(run.status, 0) << run.out;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  ASSERT_EQ(out["items"].size(), 5u);
  EXPECT_EQ(out["items"][0]["joints"].size(), 6u);
  EXPECT_TRUE(out["p_pass"].is_number());
  const test_support::CliRun far =
      test_support::runCli("acceptance " + test_support::planFile("aacmm-6axis-3bars.json") +
                               " --test iso9283 --cube 300 --center 0,30000,200",
                           test_support::Stderr::Only);
  EXPECT_EQ(far.status, 1) << far.out;
  EXPECT_NE(far.out.find("P1"), std::string::npos) << far.out;
}

TEST(AcceptanceCli, LinesFileReplacesTheSevenLines) {
  const std::string plan = test_support::testDataFile(kReferencePlan);
  const std::string lines = (std::filesystem::temp_directory_path() /
                             ("artcal-acceptance-lines-" + std::to_string(::getpid()) + ".json"))
                                .string();
  std::ofstream(lines) << "[[1, 0, 0], [0.6, 0.8, 0]]";
  const test_support::CliRun run = test_support::runCli(
      "acceptance " + plan + " --test iso10360-2 --mpe 2 --trials 2000 --json --lines " + lines);
  std::ofstream(lines) << "[[1, 1, 0]]";
  const test_support::CliRun bad =
      test_support::runCli("acceptance " + plan + " --test iso10360-2 --mpe 2 --lines " + lines,
                           test_support::Stderr::Only);
  std::filesystem::remove(lines);
  ASSERT_EQ(run.status, 0) << run.out;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  ASSERT_EQ(out["items"].size(), 10u);
  EXPECT_EQ(out["results"], 30);
  // Along x the box is 1000 mm long; along (0.6, 0.8, 0) the y extent (700 mm) limits it.
  EXPECT_NEAR(out["items"][4]["length"].get<double>(), 900.0, 1e-9);
  EXPECT_NEAR(out["items"][9]["length"].get<double>(), 0.9 * 700.0 / 0.8, 1e-9);
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.out.find("/0"), std::string::npos) << bad.out;
}

TEST(AcceptanceCli, StylusOffsetGivesE150AndRefusesWhatDoesNotGoWithIt) {
  const std::string plan = test_support::testDataFile(kReferencePlan);
  const test_support::CliRun run = test_support::runCli(
      "acceptance " + plan + " --test iso10360-2 --mpe 2 --trials 2000 --json --stylus-offset 150");
  ASSERT_EQ(run.status, 0) << run.out;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  EXPECT_EQ(out["quantity"], "E150");
  EXPECT_EQ(out["stylus_offset"], 150.0);
  EXPECT_EQ(out["results"], 30);
  EXPECT_EQ(out["items"][0]["stylus_offset"], nlohmann::json::parse("[150.0, 0.0, 0.0]"));
  EXPECT_EQ(out["items"][9]["stylus_offset"], nlohmann::json::parse("[0.0, 150.0, 0.0]"));
  for (const std::string& bad :
       {std::string("--test iso10360-2 --mpe 2 --stylus-offset nan"),
        std::string("--test iso10360-2 --mpe 2 --stylus-offset -150"),
        std::string("--test iso9283 --cube 100 --center 0,0,-400 --stylus-offset 150")}) {
    const test_support::CliRun refused =
        test_support::runCli("acceptance " + plan + " " + bad, test_support::Stderr::Only);
    EXPECT_EQ(refused.status, 2) << bad << ": " << refused.out;
    EXPECT_NE(refused.out.find("--stylus-offset"), std::string::npos) << refused.out;
  }
}

TEST(LengthTest, AnAxisOutsideTheMachineFramesDirectionsIsRefused) {
  nlohmann::json document = readJson(test_support::testDataFile(kReferencePlan));
  document["machine"]["axes"][1]["direction"] = {0.8, 0.6, 0.0};
  document["machine"]["calibrate"] = nlohmann::json::array({"x.tx.1", "y.tx.1", "z.tx.1"});
  document.erase("placements");
  const Plan plan = parsePlan(document, "tilted.json", false, false);
  const AcceptanceInput input = acceptanceInputAtNominal(plan, Eigen::MatrixXd::Zero(3, 3));
  try {
    predictLengthTestLinear(input, referenceOptions());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "/machine/axes/1/direction");
  }
}

TEST(AcceptanceCli, OptimizeForThePassProbability) {
  nlohmann::json spec = readJson(test_support::planFile("cmm-plate-2styli.spec.json"));
  spec["design"]["criterion"] = "pass";
  spec["design"]["placements"] = 6;
  spec["workspace"]["samples"] = 500;
  const std::string tag = std::to_string(::getpid());
  const auto temp = std::filesystem::temp_directory_path();
  const std::string without = (temp / ("artcal-pass-spec-no-" + tag + ".json")).string();
  std::ofstream(without) << spec.dump();
  spec["acceptance"] = {{"test", "iso10360-2"}, {"mpe", "1.5 + L/333"}};
  const std::string path = (temp / ("artcal-pass-spec-" + tag + ".json")).string();
  const std::string output = (temp / ("artcal-pass-plan-" + tag + ".json")).string();
  std::ofstream(path) << spec.dump();
  const test_support::CliRun refused =
      test_support::runCli("optimize " + without + " -o " + output, test_support::Stderr::Only);
  const test_support::CliRun run =
      test_support::runCli("optimize " + path + " -o " + output +
                           " --starts 2 --evaluations 40 --pool 60 --seed 3 --quiet --json");
  const test_support::CliRun check =
      test_support::runCli("acceptance " + output + " --trials 40000 --json");
  for (const std::string& f : {without, path, output}) std::filesystem::remove(f);
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.out.find("/design/criterion"), std::string::npos) << refused.out;
  ASSERT_EQ(run.status, 0) << run.out;
  ASSERT_EQ(check.status, 0) << check.out;
  const nlohmann::json optimized = nlohmann::json::parse(run.out);
  const nlohmann::json predicted = nlohmann::json::parse(check.out);
  // The criterion (1 - P(pass) over 256 fixed draws) against the Monte-Carlo of the plan written;
  // the 256 draws' own scatter dominates the tolerance.
  const double fail = optimized["optimization"]["value"].get<double>();
  EXPECT_GT(fail, 0.0);
  EXPECT_LT(fail, 1.0);
  EXPECT_NEAR(1.0 - fail, predicted["p_pass"].get<double>(), 0.05);
}

// ------------------------------------------------------------------------------ pass criterion

/// The test's own P(max |E|/MPE <= t | s) averaged over S's columns (erf of each result, the
/// three repetitions independent).
double mixtureDistribution(const LengthTestPrediction& prediction, const Eigen::MatrixXd& S,
                           double t) {
  double sum = 0.0;
  for (Eigen::Index m = 0; m < S.cols(); ++m) {
    double product = 1.0;
    for (std::size_t k = 0; k < prediction.gauges.size(); ++k) {
      const Gauge& gauge = prediction.gauges[k];
      const double s = S(static_cast<Eigen::Index>(k), m), w = gauge.sigma_noise * std::sqrt(2.0);
      const double p =
          0.5 * (std::erf((t * gauge.mpe - s) / w) + std::erf((t * gauge.mpe + s) / w));
      product *= p * p * p;
    }
    sum += product;
  }
  return sum / static_cast<double>(S.cols());
}

/// t with mixtureDistribution(t) = probability, by plain bisection.
double bisectedQuantile(const LengthTestPrediction& prediction, const Eigen::MatrixXd& S,
                        double probability) {
  double lo = 0.0, hi = 100.0;
  for (int i = 0; i < 200; ++i) {
    const double t = 0.5 * (lo + hi);
    (mixtureDistribution(prediction, S, t) < probability ? lo : hi) = t;
  }
  return 0.5 * (lo + hi);
}

TEST(PassCriterion, QuantileOfMaxEOverMpeAgainstBisection) {
  const Prepared prepared = prepare(test_support::testDataFile(kReferencePlan));
  const LengthTestPrediction prediction =
      predictLengthTestLinear(prepared.input, referenceOptions());
  ASSERT_EQ(prediction.gauges.size(), 35u);
  // No systematic part (V_p = 0): the closed form prod_i erf(t MPE_i / (sigma_i sqrt 2)).
  const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(35, 3);
  const double q0 = conditionalStatisticQuantile(prediction, zero, 0.95);
  EXPECT_NEAR(q0, bisectedQuantile(prediction, zero, 0.95), 1e-9 * q0);
  // Draws of the systematic part from the plan's V_p (the test's own generator and Cholesky).
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  const Eigen::MatrixXd L = prepared.input.uncertainty.V.llt().matrixL();
  Eigen::MatrixXd Z(L.cols(), 64);
  for (Eigen::Index i = 0; i < Z.size(); ++i) Z.data()[i] = normal(rng);
  for (double inflate : {1.0, 30.0}) {  // the plan's V_p, and one that dominates the noise
    const Eigen::MatrixXd S = inflate * gaugeDerivatives(prediction.gauges) * (L * Z);
    for (double probability : {0.5, 0.95}) {
      const double q = conditionalStatisticQuantile(prediction, S, probability);
      EXPECT_NEAR(q, bisectedQuantile(prediction, S, probability), 1e-9 * q);
      EXPECT_NEAR(mixtureDistribution(prediction, S, q), probability, 1e-9);
    }
  }
}

TEST(PassCriterion, SaturationWithinTheStandardErrorSwitchesToTheQuantile) {
  // Saturated: P within its binomial standard error sqrt(P (1 - P) / M) of 1 or 0, M draws.
  const double M = kPassDraws;
  auto saturated = [M](double p) {
    return std::min(p, 1.0 - p) <= std::sqrt(p * (1.0 - p) / M) * (1.0 + 1e-12);
  };
  using Quantity = PassObjective::Quantity;
  for (double p : {0.0, 1e-3, 1.0 / (M + 1.0), 2.0 / (M + 1.0), 0.1, 0.5, 0.97,
                   1.0 - 2.0 / (M + 1.0), 1.0 - 1.0 / (M + 1.0), 1.0 - 1e-6, 1.0}) {
    const double q95 = p > 0.5 ? 0.4 : 1.7;  // the quantile is below 1 when P > 0.95
    const PassObjective objective = passObjectiveOf(passCriterionValue(p, q95));
    if (saturated(p)) {
      EXPECT_EQ(objective.quantity, Quantity::Quantile95) << p;
      EXPECT_NEAR(objective.value, q95, 1e-12) << p;
      EXPECT_EQ(objective.name(), "q95 of max |E|/MPE");
    } else {
      EXPECT_EQ(objective.quantity, Quantity::FailProbability) << p;
      EXPECT_NEAR(objective.value, 1.0 - p, 1e-12) << p;
      EXPECT_EQ(objective.name(), "1 - P(pass)");
    }
  }
  // One ranking: surely passing (smaller quantile first), may pass (larger P first), surely
  // failing (smaller quantile first).
  const std::vector<double> ranked = {
      passCriterionValue(1.0, 0.2),         passCriterionValue(1.0, 0.9),
      passCriterionValue(1.0 - 1e-3, 0.95), passCriterionValue(0.99, 0.0),
      passCriterionValue(0.5, 0.0),         passCriterionValue(0.01, 0.0),
      passCriterionValue(1e-3, 1.01),       passCriterionValue(0.0, 3.0)};
  for (std::size_t i = 1; i < ranked.size(); ++i) EXPECT_LT(ranked[i - 1], ranked[i]) << i;
}

/// `optimize` on the shipped CMM spec (6 placements, criterion pass, MPE `mpe`) and
/// `acceptance` on the plan it wrote.
struct PassRun {
  nlohmann::json optimized, predicted;
};

PassRun optimizeForPass(const std::string& mpe, const std::string& tag) {
  nlohmann::json spec = readJson(test_support::planFile("cmm-plate-2styli.spec.json"));
  spec["design"]["criterion"] = "pass";
  spec["design"]["placements"] = 6;
  spec["workspace"]["samples"] = 500;
  spec["acceptance"] = {{"test", "iso10360-2"}, {"mpe", mpe}};
  const auto temp = std::filesystem::temp_directory_path();
  const std::string id = tag + "-" + std::to_string(::getpid());
  const std::string path = (temp / ("artcal-pass-spec-" + id + ".json")).string();
  const std::string output = (temp / ("artcal-pass-plan-" + id + ".json")).string();
  std::ofstream(path) << spec.dump();
  const test_support::CliRun run =
      test_support::runCli("optimize " + path + " -o " + output +
                           " --starts 1 --evaluations 20 --pool 30 --seed 3 --quiet --json");
  const test_support::CliRun check =
      test_support::runCli("acceptance " + output + " --trials 100000 --json");
  for (const std::string& f : {path, output}) std::filesystem::remove(f);
  EXPECT_EQ(run.status, 0) << run.out;
  EXPECT_EQ(check.status, 0) << check.out;
  if (run.status != 0 || check.status != 0) return {};
  return {nlohmann::json::parse(run.out)["optimization"], nlohmann::json::parse(check.out)};
}

TEST(AcceptanceCli, OptimizeForPassWithALooseMpeMinimisesTheQuantile) {
  // Every design passes surely (P(pass) = 1): the search minimises the 95 % quantile instead.
  const PassRun run = optimizeForPass("20 + L/50", "loose");
  ASSERT_TRUE(run.optimized.is_object());
  EXPECT_EQ(run.optimized["unit"], "q95 of max |E|/MPE");
  EXPECT_EQ(run.optimized["pass"]["objective"], "q95 of max |E|/MPE");
  EXPECT_EQ(run.optimized["pass"]["saturated"], true);
  EXPECT_EQ(run.optimized["pass"]["p_pass"], 1.0);
  EXPECT_EQ(run.optimized["pass"]["stage_objectives"]["best_start_initial"], "q95 of max |E|/MPE");
  const double q95 = run.optimized["value"].get<double>();
  EXPECT_EQ(run.optimized["pass"]["q95"].get<double>(), q95);
  // Improved from the start's random design (1 - P(pass) = 0 for both would give nothing).
  EXPECT_LT(q95, run.optimized["best_start"]["initial"].get<double>() * (1.0 - 1e-3));
  // The written plan, recomputed by `acceptance` (10^5 trials): its 95 % quantile is the one
  // optimised (the 256 fixed draws against the Monte-Carlo), and it passes surely.
  EXPECT_EQ(run.predicted["p_pass"], 1.0);
  EXPECT_NEAR(run.predicted["quantiles"]["95"].get<double>(), q95, 0.02 * q95);
}

TEST(AcceptanceCli, OptimizeForPassNearOneHalfMaximisesThePassProbability) {
  const PassRun run = optimizeForPass("1.4 + L/333", "half");
  ASSERT_TRUE(run.optimized.is_object());
  EXPECT_EQ(run.optimized["unit"], "1 - P(pass)");
  EXPECT_EQ(run.optimized["pass"]["objective"], "1 - P(pass)");
  EXPECT_EQ(run.optimized["pass"]["saturated"], false);
  const double fail = run.optimized["value"].get<double>();
  EXPECT_NEAR(1.0 - fail, run.optimized["pass"]["p_pass"].get<double>(), 1e-12);
  EXPECT_LE(fail, run.optimized["best_start"]["initial"].get<double>());
  // The written plan's P(pass) by `acceptance` (10^5 trials) within the 256 draws' scatter.
  const double p_pass = run.predicted["p_pass"].get<double>();
  EXPECT_GT(p_pass, 0.3);
  EXPECT_LT(p_pass, 0.7);
  EXPECT_NEAR(1.0 - fail, p_pass, 0.05);
}

TEST(AcceptanceCli, BadInputIsOneErrorLineWithStatus2) {
  const std::string plan = test_support::testDataFile(kReferencePlan);
  for (const std::string& arguments :
       {"acceptance " + plan + " --test iso10360-2 --mpe 'L/3'",
        "acceptance " + plan + " --test iso10360-2",
        "acceptance " + plan + " --test iso9283 --cube 100",
        "acceptance " + plan + " --test iso9283 --cube 100 --center 1,2",
        "acceptance " + test_support::planFile("aacmm-6axis-3bars.json") +
            " --test iso10360-2 --mpe '1 + L/100'"}) {
    const test_support::CliRun run = test_support::runCli(arguments, test_support::Stderr::Only);
    EXPECT_EQ(run.status, 2) << arguments;
    EXPECT_EQ(run.out.rfind("error: ", 0), 0u) << run.out;
    EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1) << run.out;
  }
}

}  // namespace acceptance_test
}  // namespace artcal
