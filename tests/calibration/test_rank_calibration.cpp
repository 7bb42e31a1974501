// The calibrator under the rank policy (method.md section 5): on simulated readings of plans whose
// placements leave rigid directions unseen (tests/support/rank_plans.hpp) it converges, to within
// 0.1 u of a dense weighted least-squares solution written in this test (every unknown at once,
// Gauss-Newton, each placement's rigid motion restricted to the directions its nominal
// measurements observe), and the Monte-Carlo confirmation confirms the predicted u.

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "artcal/artcal.hpp"
#include "rank_plans.hpp"

namespace artcal {
namespace rank_calibration_test {

using namespace testing;

// Machine-frame rigid motion of a placement's points about their centroid c:
// x -> x + t + w x (x - c), as columns over (t, w).
Eigen::MatrixXd rigidColumns(const Eigen::VectorXd& x, const Eigen::VectorXd& c) {
  const int d = static_cast<int>(x.size());
  Eigen::MatrixXd G(d, d == 2 ? 3 : 6);
  const Eigen::VectorXd lever = x - c;
  if (d == 2) {
    G << 1, 0, -lever[1], 0, 1, lever[0];
  } else {
    G.leftCols(3).setIdentity();
    for (int a = 0; a < 3; ++a) G.col(3 + a) = Eigen::Vector3d::Unit(a).cross(lever.head<3>());
  }
  return G;
}

Eigen::MatrixXd rotation(const Eigen::VectorXd& w) {
  if (w.size() == 1) return Eigen::Rotation2Dd(w[0]).toRotationMatrix();
  const double angle = w.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

struct DenseProblem {
  const Plan* plan;
  std::vector<Eigen::MatrixXd> bases;  ///< per placement: observed rigid directions (columns)
  std::vector<Eigen::VectorXd> centroids;
};

Eigen::MatrixXd probePoints(const Plan& plan, const Placement& pl, const Eigen::VectorXd& p) {
  const int d = plan.machine.dimension();
  Eigen::MatrixXd X(d, static_cast<int>(pl.measurements.size()));
  Eigen::VectorXd x(d);
  for (std::size_t i = 0; i < pl.measurements.size(); ++i) {
    forwardOrThrow(*plan.machine.mechanism, p, pl.measurements[i].joints, x);
    X.col(static_cast<int>(i)) = x;
  }
  return X;
}

// The rigid directions the nominal measurements of each placement observe: eigenvectors of
// G^T G over its points with eigenvalues above 1e-10 of the largest.
DenseProblem denseProblem(const Plan& plan) {
  DenseProblem problem{&plan, {}, {}};
  for (const Placement& pl : plan.placements) {
    const Eigen::MatrixXd X = probePoints(plan, pl, plan.machine.nominal);
    const Eigen::VectorXd c = X.rowwise().mean();
    const int k = plan.artifacts[static_cast<std::size_t>(pl.artifact)].valuedPerFeature();
    const Eigen::MatrixXd Rk = poseTransform(*pl.pose).R.topRows(k);
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(X.rows() == 2 ? 3 : 6, X.rows() == 2 ? 3 : 6);
    for (int i = 0; i < X.cols(); ++i) {
      const Eigen::MatrixXd G = Rk * rigidColumns(X.col(i), c);
      M += G.transpose() * G;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(M);
    std::vector<int> observed;
    for (int i = 0; i < M.rows(); ++i) {
      if (eig.eigenvalues()[i] > 1e-10 * eig.eigenvalues().maxCoeff()) observed.push_back(i);
    }
    Eigen::MatrixXd B(M.rows(), static_cast<int>(observed.size()));
    for (std::size_t a = 0; a < observed.size(); ++a) {
      B.col(static_cast<int>(a)) = eig.eigenvectors().col(observed[a]);
    }
    problem.bases.push_back(B);
    problem.centroids.push_back(c);
  }
  return problem;
}

// Dense Gauss-Newton over (p, every placement's observed rigid motion), weights at the current p.
Eigen::VectorXd denseLeastSquares(const DenseProblem& problem,
                                  const std::vector<Placement>& placements) {
  const Plan& plan = *problem.plan;
  const Machine& machine = plan.machine;
  const int d = machine.dimension();
  const int n_p = machine.calibratedCount();
  Eigen::VectorXd p = machine.nominal;
  std::vector<RigidTransform> T;
  // Start from the plan's poses: the dense solution does not share the calibrator's start.
  for (const Placement& pl : placements) T.push_back(poseTransform(*pl.pose));
  int columns = n_p;
  std::vector<int> offset;
  for (const Eigen::MatrixXd& B : problem.bases) {
    offset.push_back(columns);
    columns += static_cast<int>(B.cols());
  }
  Eigen::VectorXd encoder(machine.jointCount());
  for (int i = 0; i < encoder.size(); ++i) {
    encoder[i] = plan.noise.encoder.size() == 1 ? plan.noise.encoder[0] : plan.noise.encoder[i];
  }
  for (int iteration = 0; iteration < 30; ++iteration) {
    Eigen::MatrixXd N = Eigen::MatrixXd::Zero(columns, columns);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(columns);
    for (std::size_t j = 0; j < placements.size(); ++j) {
      const Placement& pl = placements[j];
      const Artifact& a = plan.artifacts[static_cast<std::size_t>(pl.artifact)];
      const int k = a.valuedPerFeature();
      const Eigen::MatrixXd Rk = T[j].R.topRows(k);
      const Eigen::MatrixXd X = probePoints(plan, pl, p);
      const Eigen::VectorXd c = X.rowwise().mean();
      for (std::size_t i = 0; i < pl.measurements.size(); ++i) {
        Eigen::VectorXd x(d);
        Eigen::MatrixXd Jp, Jq;
        forwardOrThrow(*machine.mechanism, p, pl.measurements[i].joints, x, &Jp, &Jq);
        Eigen::MatrixXd A = Eigen::MatrixXd::Zero(k, columns);
        for (int col = 0; col < n_p; ++col) {
          A.col(col) = Rk * Jp.col(machine.calibrated[static_cast<std::size_t>(col)]);
        }
        A.middleCols(offset[j], problem.bases[j].cols()) =
            Rk * rigidColumns(x, c) * problem.bases[j];
        const Eigen::VectorXd e =
            (T[j].apply(x) - a.features.col(pl.measurements[i].feature)).head(k);
        const Eigen::MatrixXd Jqk = Rk * Jq;
        const Eigen::MatrixXd W =
            (plan.noise.probe * plan.noise.probe * Eigen::MatrixXd::Identity(k, k) +
             Jqk * encoder.cwiseAbs2().asDiagonal() * Jqk.transpose())
                .inverse();
        N += A.transpose() * W * A;
        g += A.transpose() * W * e;
      }
    }
    const Eigen::VectorXd s = N.diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::VectorXd step =
        -(s.asDiagonal() * (s.asDiagonal() * N * s.asDiagonal()).ldlt().solve(s.asDiagonal() * g));
    p = machine.withCalibrated(p, machine.calibratedValues(p) + step.head(n_p));
    for (std::size_t j = 0; j < placements.size(); ++j) {
      const Eigen::MatrixXd X = probePoints(plan, placements[j], p);
      const Eigen::VectorXd c = X.rowwise().mean();
      const Eigen::VectorXd motion =
          problem.bases[j] * step.segment(offset[j], problem.bases[j].cols());
      const int translations = d;
      const Eigen::MatrixXd Rw = rotation(motion.tail(motion.size() - translations));
      // T o M, M(x) = Rw (x - c) + c + dt.
      T[j].t = T[j].R * (c + motion.head(translations) - Rw * c) + T[j].t;
      T[j].R = T[j].R * Rw;
    }
    if ((step.cwiseProduct(s.cwiseInverse())).cwiseAbs().maxCoeff() < 1e-10) break;
  }
  return machine.calibratedValues(p);
}

struct CalibrationCase {
  const char* name;
  std::function<Plan()> build;
};

Plan arm3WithoutTheta() {
  Plan plan = arm3ThetaPlan();
  plan.machine.calibrated.erase(plan.machine.calibrated.begin());  // j1.theta
  return plan;
}

const std::vector<CalibrationCase>& calibrationCases() {
  static const std::vector<CalibrationCase> cases = {
      {"step gauge 2-D", stepGauge2DPlan}, {"step gauge 3-D", stepGauge3DPlan},
      {"one ball of a bar", oneBallPlan},  {"plate origin ball", plateOriginPlan},
      {"plate X axis", plateXAxisPlan},    {"3-axis arm without j1.theta", arm3WithoutTheta},
  };
  return cases;
}

const Plan& cachedPlan(std::size_t index) {
  static std::vector<Plan> plans = [] {
    std::vector<Plan> out;
    for (const CalibrationCase& c : calibrationCases()) out.push_back(c.build());
    return out;
  }();
  return plans[index];
}

TEST(RankCalibration, ConvergesToTheDenseLeastSquaresSolution) {
  for (std::size_t c = 0; c < calibrationCases().size(); ++c) {
    SCOPED_TRACE(calibrationCases()[c].name);
    const Plan& plan = cachedPlan(c);
    const Evaluation evaluation = evaluatePlan(plan);
    ASSERT_TRUE(evaluation.identifiable());
    const Eigen::VectorXd& u = evaluation.covariance->u;
    const DenseProblem problem = denseProblem(plan);
    const Simulator simulator(plan);
    for (std::uint64_t seed : {1u, 2u, 3u}) {
      SCOPED_TRACE(seed);
      NormalSource normal(seed);
      Eigen::VectorXd p_true = plan.machine.nominal;
      for (int k = 0; k < plan.machine.calibratedCount(); ++k) {
        p_true[plan.machine.calibrated[static_cast<std::size_t>(k)]] += 3.0 * u[k] * normal();
      }
      const SimulatedRun run = simulator.simulate(p_true, normal);
      Calibrator calibrator(plan);
      const Calibration calibration = calibrator.run(run.placements);
      ASSERT_TRUE(calibration.summary.converged()) << calibration.summary.briefReport();
      const Eigen::VectorXd dense = denseLeastSquares(problem, run.placements);
      const Eigen::VectorXd estimate = calibration.estimate(plan.machine);
      for (int k = 0; k < u.size(); ++k) {
        EXPECT_NEAR(estimate[k], dense[k], 0.1 * u[k]) << "parameter " << k;
      }
    }
  }
}

TEST(RankCalibration, ConfirmationConfirmsThePrediction) {
  for (std::size_t c = 0; c < calibrationCases().size(); ++c) {
    SCOPED_TRACE(calibrationCases()[c].name);
    ConfirmationOptions options;
    options.trials = 400;
    options.seed = 7;
    options.threads = 2;
    const Confirmation confirmation = confirmPlan(cachedPlan(c), options);
    EXPECT_EQ(confirmation.converged_trials, 400);
    EXPECT_TRUE(confirmation.confirmed);
    for (const ConfirmedParameter& p : confirmation.parameters) {
      EXPECT_TRUE(p.inside) << p.name << " ratio " << p.ratio;
    }
  }
}

}  // namespace rank_calibration_test
}  // namespace artcal
