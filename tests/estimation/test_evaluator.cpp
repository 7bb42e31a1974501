// The evaluator (method.md sections 2-4): invariance under rigid motions of the whole plan and
// of an artifact's frame, the systematic length error, the Schur reduction against the dense
// inverse of the full normal matrix, and the prepared evaluation against the plain one.

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <numbers>

#include "artcal/internal.hpp"
#include "finite_difference.hpp"
#include "plan_builders.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace evaluator_test {

using testing::aacmmPlan;
using testing::loadTestPlan;
using testing::randomPlanarBar;
using testing::randomPlanarBars;
using testing::randomSpatialBars;
using testing::seedPlanar2RPlan;

// Every result of two evaluations agrees to `tolerance` (relative).
void expectSameEvaluation(const Evaluation& a, const Evaluation& b, double tolerance) {
  ASSERT_EQ(a.identifiability.rank, b.identifiability.rank);
  ASSERT_EQ(a.identifiability.deficiency, b.identifiability.deficiency);
  ASSERT_TRUE(a.identifiable());
  ASSERT_TRUE(b.identifiable());
  const auto& ua = a.covariance->u;
  const auto& ub = b.covariance->u;
  for (int i = 0; i < ua.size(); ++i) EXPECT_NEAR(ua[i], ub[i], tolerance * ua[i]) << "u " << i;
  EXPECT_LT((a.covariance->correlation - b.covariance->correlation).cwiseAbs().maxCoeff(),
            tolerance);
  ASSERT_TRUE(a.tip && b.tip);
  EXPECT_EQ(a.tip->worst_index, b.tip->worst_index);
  EXPECT_NEAR(a.tip->worst.total, b.tip->worst.total, tolerance * a.tip->worst.total);
  EXPECT_NEAR(a.tip->worst.kinematic, b.tip->worst.kinematic, tolerance * a.tip->worst.kinematic);
  EXPECT_NEAR(a.tip->worst.encoder, b.tip->worst.encoder, tolerance * a.tip->worst.encoder);
  EXPECT_NEAR(a.tip->mean, b.tip->mean, tolerance * a.tip->mean);
  EXPECT_NEAR(a.tip->rms, b.tip->rms, tolerance * a.tip->rms);
}

// The plan's workspace made explicit, so that it can be moved with the readings.
void makeWorkspaceExplicit(Plan& plan, int samples) {
  WorkspaceSpec spec;
  spec.kind = WorkspaceSpec::Kind::Samples;
  spec.samples = samples;
  spec.seed = 3;
  plan.workspace.configurations = workspaceConfigurations(plan.machine, spec);
  plan.workspace.kind = WorkspaceSpec::Kind::Configurations;
}

// Turning the whole plan about the base axis: the same angle added to joint 1 of every reading
// and every workspace configuration.
Plan turnedAboutBase(Plan plan, double angle) {
  for (Placement& placement : plan.placements) {
    for (Measurement& m : placement.measurements) m.joints[0] += angle;
  }
  for (Eigen::VectorXd& q : plan.workspace.configurations) q[0] += angle;
  return plan;
}

TEST(Evaluator, Planar2RInvariantUnderTurningThePlanAboutTheBase) {
  Plan plan = loadTestPlan("ref-2r-5bars");
  const Evaluation reference = evaluatePlan(plan);
  for (double degrees : {37.0, -121.0, 180.0}) {
    SCOPED_TRACE(degrees);
    expectSameEvaluation(reference, evaluatePlan(turnedAboutBase(plan, degToRad(degrees))), 1e-9);
  }
}

TEST(Evaluator, SerialArmInvariantUnderTurningThePlanAboutJointOne) {
  Plan plan = loadTestPlan("ref-aacmm-3bars-3postures");
  makeWorkspaceExplicit(plan, 300);
  const Evaluation reference = evaluatePlan(plan);
  for (double degrees : {23.0, -95.0}) {
    SCOPED_TRACE(degrees);
    expectSameEvaluation(reference, evaluatePlan(turnedAboutBase(plan, degToRad(degrees))), 1e-8);
  }
}

// A 2-D ball plate (with a systematic u per coordinate) placed three times on the seed's arm,
// readings by inverse kinematics.
Plan planarPlatePlan(const Eigen::MatrixXd& centers) {
  Plan plan = seedPlanar2RPlan();
  plan.artifacts = {Artifact::ballPlate("plate", centers, 0.002)};
  const std::vector<RigidTransform> toMachine = {
      placePlanar(Eigen::Vector2d(90.0, 60.0), 0.3).inverse(),
      placePlanar(Eigen::Vector2d(-40.0, 150.0), -1.2).inverse(),
      placePlanar(Eigen::Vector2d(20.0, -170.0), 2.0).inverse()};
  for (const RigidTransform& T : toMachine) {
    Placement placement;
    for (int i = 0; i < centers.cols(); ++i) {
      const Eigen::VectorXd x = T.apply(centers.col(i));
      placement.measurements.push_back({i, planar2rInverse(plan.machine.nominal, x).front()});
    }
    plan.placements.push_back(placement);
  }
  makeWorkspaceExplicit(plan, 200);
  return plan;
}

// Redefining the artifact's frame (every centre moved by one rigid motion, the physical plate
// and so the readings unchanged) changes no result.
TEST(Evaluator, InvariantUnderRedefiningAnArtifactFrame) {
  Eigen::MatrixXd centers(2, 4);
  centers << 0, 50, 0, 50,  //
      0, 0, 30, 30;
  const Plan plan = planarPlatePlan(centers);
  const Evaluation reference = evaluatePlan(plan);
  ASSERT_TRUE(reference.identifiable());
  Plan moved = plan;
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(0.9).toRotationMatrix();
  moved.artifacts[0].features = (R * centers).colwise() + Eigen::Vector2d(-12.0, 33.0);
  expectSameEvaluation(reference, evaluatePlan(moved), 1e-9);
}

// The bar's length error c is systematic (method.md section 2). A length error is exactly a
// change of scale of l1 and l2 (dt2 unchanged), so with it V_p = V_0 + s s^T u_L^2,
// s = (l1, l2, 0) / L, whatever the number of placements: it never averages away.
TEST(Evaluator, SystematicLengthErrorAddsAScaleTermThatDoesNotAverageAway) {
  const double u_length = 0.002, L = 80.0;
  const Plan exact = seedPlanar2RPlan(0.0);
  const Plan uncertain = seedPlanar2RPlan(u_length);
  const std::vector<Placement> five = randomPlanarBars(exact, 5, 21);
  std::vector<Placement> many;
  for (int r = 0; r < 64; ++r) many.insert(many.end(), five.begin(), five.end());
  const Eigen::Vector3d s = Eigen::Vector3d(150.0, 100.0, 0.0) / L;
  Eigen::VectorXd u0_five;
  for (const std::vector<Placement>* placements :
       {&five, static_cast<const std::vector<Placement>*>(&many)}) {
    const auto V0 =
        covarianceFromInformation(placementsInformation(exact, *placements, exact.machine.nominal));
    const auto VL = covarianceFromInformation(
        placementsInformation(uncertain, *placements, uncertain.machine.nominal));
    ASSERT_TRUE(V0 && VL);
    const Eigen::Matrix3d expected = V0->V + s * s.transpose() * u_length * u_length;
    EXPECT_LT((VL->V - expected).cwiseAbs().maxCoeff(), 1e-6 * expected.cwiseAbs().maxCoeff());
    EXPECT_GT(VL->u[0], V0->u[0]);
    EXPECT_GT(VL->u[1], V0->u[1]);
    // 64 times the placements: the random part shrinks by 8, the length term stays.
    if (placements == &five) {
      u0_five = V0->u;
    } else {
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(V0->u[i], u0_five[i] / 8.0, 1e-9 * u0_five[i]);
      EXPECT_GT(VL->u[0], 150.0 * u_length / L);
      EXPECT_LT(VL->u[0], 1.01 * std::hypot(150.0 * u_length / L, V0->u[0]));
    }
  }
}

// The Schur-reduced information equals the p block of the inverse of the full normal matrix,
// built densely here (A = [A_p | A_r1 ... A_rm | A_c] stacked, plus Sigma_c^-1), on a small
// plan with two bars, both with a systematic length error.
TEST(Evaluator, SchurReductionEqualsTheDenseFullInverse) {
  Plan plan = seedPlanar2RPlan(0.003);
  plan.artifacts.push_back(Artifact::ballBar("bar120", 2, 120.0, 0.001));
  std::mt19937_64 rng(8);
  std::vector<Placement> placements;
  for (int j = 0; j < 6; ++j) placements.push_back(randomPlanarBar(plan, rng, j % 2));
  const Eigen::VectorXd& p = plan.machine.nominal;
  const auto poses = fitPlacements(plan, placements, p);

  const GlobalLayout layout = GlobalLayout::of(plan);
  DesignMatrixBuilder builder(plan.machine, plan.noise);
  std::vector<ObservationBlock> blocks(placements.size());
  int rows = 0, rigid = 0;
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placements[j].artifact)];
    builder.build(artifact, placements[j].measurements, p, poses[j], Eigen::VectorXd(), false,
                  blocks[j]);
    rows += blocks[j].rows();
    rigid += static_cast<int>(blocks[j].A_r.cols());
  }
  const int n_p = layout.parameters, n_c = layout.systematicCount();
  ASSERT_EQ(n_c, 2);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(rows, n_p + rigid + n_c);
  int row = 0, r_col = n_p;
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const ObservationBlock& b = blocks[j];
    const int c_col =
        rigid + layout.artifact_offset[static_cast<std::size_t>(placements[j].artifact)];
    A.block(row, 0, b.rows(), n_p) = b.A_p;
    A.block(row, r_col, b.rows(), b.A_r.cols()) = b.A_r;
    A.block(row, c_col, b.rows(), b.A_c.cols()) = b.A_c;
    row += b.rows();
    r_col += static_cast<int>(b.A_r.cols());
  }
  Eigen::MatrixXd N = A.transpose() * A;
  for (int i = 0; i < n_c; ++i) {
    N(n_p + rigid + i, n_p + rigid + i) += 1.0 / (layout.c_sigma[i] * layout.c_sigma[i]);
  }
  const Eigen::MatrixXd V_full = N.inverse();
  const Eigen::MatrixXd V_dense = V_full.topLeftCorner(n_p, n_p);

  NormalMatrixReducer reducer(layout);
  for (std::size_t j = 0; j < placements.size(); ++j)
    reducer.add(blocks[j], placements[j].artifact);
  const auto reduced = covarianceFromInformation(reducer.parameterInformation());
  ASSERT_TRUE(reduced);
  for (int a = 0; a < n_p; ++a) {
    for (int b = 0; b < n_p; ++b) {
      EXPECT_NEAR(reduced->V(a, b), V_dense(a, b), 1e-8 * std::sqrt(V_dense(a, a) * V_dense(b, b)));
    }
  }
  // The (p, c) block of the reduced normal matrix with its prior: the same marginal covariance.
  const Eigen::MatrixXd V_pc = reducer.normalWithPrior().inverse();
  EXPECT_NEAR(V_pc(n_p, n_p), V_full(n_p + rigid, n_p + rigid), 1e-8 * V_pc(n_p, n_p));
  EXPECT_NEAR(V_pc(0, n_p + 1), V_full(0, n_p + rigid + 1),
              1e-8 * std::sqrt(V_pc(0, 0) * V_pc(n_p + 1, n_p + 1)));
  // And the same through the evaluator's own entry point.
  const Eigen::MatrixXd info = placementsInformation(plan, placements, p);
  EXPECT_LT((info - reducer.parameterInformation()).cwiseAbs().maxCoeff(),
            1e-12 * info.cwiseAbs().maxCoeff());
}

// A placement's products reduced again (what Calibrator::information does with a linearisation's
// blocks) give exactly what reducing its block gives, under either rank policy: the 6-axis arm
// (21 parameters: the blocked rank updates) with bars that carry a systematic length error, read
// at parameters off nominal so that the bars' roll looks observed without the features' cap.
TEST(Evaluator, BlockProductsReduceAsTheirBlock) {
  Plan plan = aacmmPlan();
  const Artifact& bar = plan.artifacts[0];
  plan.artifacts[0] =
      Artifact::ballBar(bar.id, 3, (bar.features.col(1) - bar.features.col(0)).norm(), 0.002);
  const std::vector<Placement> placements = randomSpatialBars(plan, 4, 3, 5);
  const auto poses = fitPlacements(plan, placements, plan.machine.nominal);
  Eigen::VectorXd p = plan.machine.nominal;
  p[plan.machine.calibrated[0]] += 0.5;
  p[plan.machine.calibrated[5]] += 0.3;
  const GlobalLayout layout = GlobalLayout::of(plan);
  ASSERT_GT(layout.parameters, 8);
  ASSERT_EQ(layout.systematicCount(), 1);

  DesignMatrixBuilder builder(plan.machine, plan.noise);
  NormalMatrixReducer capped(layout), full(layout), capped_again(layout), full_again(layout);
  std::vector<BlockProducts> products(placements.size());
  std::vector<int> caps;
  ObservationBlock block;
  for (std::size_t j = 0; j < placements.size(); ++j) {
    builder.build(plan.artifacts[0], placements[j].measurements, p, poses[j],
                  Eigen::VectorXd::Constant(1, 0.01), true, block);
    caps.push_back(rigidRankOfFeatures(plan.artifacts[0], placements[j].measurements));
    capped.add(block, 0, nullptr, caps.back(), &products[j]);
    full.add(block, 0);
  }
  for (std::size_t j = 0; j < placements.size(); ++j) {
    capped_again.add(products[j], 0, caps[j]);
    full_again.add(products[j], 0);
  }
  ASSERT_NE(full.rigidRanks(), capped.rigidRanks());  // the two policies differ here
  EXPECT_EQ(full_again.rigidRanks(), full.rigidRanks());
  EXPECT_TRUE(full_again.normal() == full.normal());
  EXPECT_TRUE(full_again.unreducedDiagonal() == full.unreducedDiagonal());
  EXPECT_EQ(capped_again.rigidRanks(), capped.rigidRanks());
  EXPECT_TRUE(capped_again.normal() == capped.normal());
}

// The back-substitution of the calibrator: r_j steps recovered from the reduced solution equal
// the r_j part of the dense solution of the full normal equations.
TEST(Evaluator, RigidStepBackSubstitutionMatchesTheDenseSolve) {
  const Plan plan = seedPlanar2RPlan();
  const std::vector<Placement> placements = randomPlanarBars(plan, 4, 5);
  Eigen::VectorXd p = plan.machine.nominal;
  p[0] += 0.05;  // residuals: the readings were planned for nominal
  p[2] += 0.001;
  const auto poses = fitPlacements(plan, placements, plan.machine.nominal);
  DesignMatrixBuilder builder(plan.machine, plan.noise);
  NormalMatrixReducer reducer(GlobalLayout::of(plan));
  std::vector<ObservationBlock> blocks(placements.size());
  std::vector<PlacementElimination> eliminations(placements.size());
  for (std::size_t j = 0; j < placements.size(); ++j) {
    builder.build(plan.artifacts[0], placements[j].measurements, p, poses[j], Eigen::VectorXd(),
                  true, blocks[j]);
    reducer.add(blocks[j], 0, &eliminations[j]);
  }
  const Eigen::VectorXd dp = reducer.normal().ldlt().solve(reducer.rhs());
  // Dense: A = [A_p | A_r blocks], minimise |A d + e|^2.
  const int m = static_cast<int>(placements.size());
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(4 * m, 3 + 3 * m);
  Eigen::VectorXd e(4 * m);
  for (int j = 0; j < m; ++j) {
    A.block(4 * j, 0, 4, 3) = blocks[j].A_p;
    A.block(4 * j, 3 + 3 * j, 4, 3) = blocks[j].A_r;
    e.segment(4 * j, 4) = blocks[j].e;
  }
  const Eigen::VectorXd d = (A.transpose() * A).ldlt().solve(-A.transpose() * e);
  EXPECT_LT((d.head(3) - dp).norm(), 1e-8 * d.head(3).norm());
  for (int j = 0; j < m; ++j) {
    const Eigen::VectorXd dr = eliminations[static_cast<std::size_t>(j)].rigidStep(dp);
    EXPECT_LT((dr - d.segment(3 + 3 * j, 3)).norm(), 1e-8 * (1.0 + d.segment(3 + 3 * j, 3).norm()));
  }
  EXPECT_NEAR(reducer.chi2(), e.squaredNorm(), 1e-12 * e.squaredNorm());
}

// The 6-axis arm with four random bars read in three postures, over `samples` configurations.
Plan fourBarArmPlan(int samples) {
  Plan plan = aacmmPlan();
  plan.placements = randomSpatialBars(plan, 4, 3, 17);
  makeWorkspaceExplicit(plan, samples);
  return plan;
}

TEST(Evaluator, PreparedEvaluationMatchesThePlainOne) {
  const Plan plan = fourBarArmPlan(500);
  const Evaluation plain = evaluatePlan(plan);
  ASSERT_TRUE(plain.identifiable());
  PlanEvaluator prepared(plan);
  const Eigen::MatrixXd& info = prepared.information(plan.placements);
  EXPECT_LT((info - plain.information).cwiseAbs().maxCoeff(),
            1e-10 * plain.information.cwiseAbs().maxCoeff());
  const auto tip = prepared.tip(plan.placements);
  ASSERT_TRUE(tip);
  EXPECT_EQ(tip->worst_index, plain.tip->worst_index);
  EXPECT_NEAR(tip->worst.total, plain.tip->worst.total, 1e-10 * plain.tip->worst.total);
  EXPECT_NEAR(tip->mean, plain.tip->mean, 1e-10 * plain.tip->mean);
  // A second call with the same evaluator (scratch reused) gives the same numbers.
  const auto again = prepared.tip(plan.placements);
  EXPECT_EQ(again->worst.total, tip->worst.total);
}

// What the report draws and does not compute (issue 20): S at every workspace configuration,
// against the unprepared trace of each configuration, with the summary's worst and mean; each
// placement's features where the plan placed them (its pose, built independently by
// placeSpatial) and, without poses, where the fit to the nominal readings puts them (on the
// probe positions of the readings, which the builder solved onto the features).
TEST(Evaluator, CarriesSPerConfigurationAndThePlacedFeatures) {
  const Plan plan = fourBarArmPlan(200);
  const Evaluation evaluation = evaluatePlan(plan);
  ASSERT_TRUE(evaluation.identifiable());
  ASSERT_EQ(evaluation.workspace_total.size(), evaluation.workspace.size());
  double sum = 0.0;
  for (std::size_t g = 0; g < evaluation.workspace.size(); ++g) {
    const TipPoint direct =
        tipUncertainty(plan.machine, plan.noise, evaluation.workspace[g], evaluation.covariance->V);
    EXPECT_NEAR(evaluation.workspace_total[g], direct.total, 1e-10 * direct.total) << g;
    EXPECT_NEAR(evaluation.workspace_kinematic[g], direct.kinematic, 1e-10 * direct.kinematic) << g;
    EXPECT_NEAR(evaluation.workspace_encoder[g], direct.encoder, 1e-12 * direct.encoder) << g;
    sum += evaluation.workspace_total[g];
  }
  const auto worst =
      std::max_element(evaluation.workspace_total.begin(), evaluation.workspace_total.end());
  EXPECT_EQ(worst - evaluation.workspace_total.begin(), evaluation.tip->worst_index);
  EXPECT_NEAR(*worst, evaluation.tip->worst.total, 1e-12 * *worst);
  EXPECT_NEAR(sum / static_cast<double>(evaluation.workspace.size()), evaluation.tip->mean,
              1e-12 * evaluation.tip->mean);

  const Artifact& bar = plan.artifacts[0];
  ASSERT_EQ(evaluation.placed_features.size(), plan.placements.size());
  Plan fitted = plan;
  for (Placement& placement : fitted.placements) placement.pose.reset();
  const Evaluation from_readings = evaluatePlan(fitted);
  ASSERT_EQ(from_readings.placed_features.size(), plan.placements.size());
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const Pose& pose = *plan.placements[j].pose;
    const RigidTransform machine_from_bar =
        placeSpatial(pose.center, pose.direction, pose.roll).inverse();
    ASSERT_EQ(evaluation.placed_features[j].cols(), bar.featureCount());
    for (int i = 0; i < bar.featureCount(); ++i) {
      const Eigen::Vector3d expected = machine_from_bar.apply(bar.features.col(i));
      EXPECT_LT((evaluation.placed_features[j].col(i) - expected).norm(), 1e-9) << j << " " << i;
      EXPECT_LT((from_readings.placed_features[j].col(i) - expected).norm(), 1e-6) << j << " " << i;
    }
  }
}

// S_m^2 over the workspace (Gram form up to 40 parameters, triangular product beyond, the
// factored form where the Jacobians span few matrices) equals tr(J_p V J_p^T) configuration by
// configuration.
void expectKinematicVarianceMatchesDirectTrace(const Machine& machine, const Noise& noise,
                                               int samples = 50, double tolerance = 1e-12) {
  WorkspaceSpec spec;
  spec.samples = samples;
  const TipEvaluator tip(machine, noise, workspaceConfigurations(machine, spec));
  const int n = machine.calibratedCount();
  Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, n);
  const Eigen::MatrixXd V = 1e-6 * (B * B.transpose() + Eigen::MatrixXd::Identity(n, n));
  Eigen::VectorXd S_m2;
  tip.kinematicVariance(V, S_m2);
  ASSERT_EQ(S_m2.size(), samples);
  for (int g = 0; g < samples; g += std::max(1, samples / 50)) {
    Eigen::VectorXd x;
    Eigen::MatrixXd J_x_p;
    forwardOrThrow(*machine.mechanism, machine.nominal,
                   tip.configurations()[static_cast<std::size_t>(g)], x, &J_x_p);
    const Eigen::MatrixXd J = J_x_p(Eigen::all, machine.calibrated);
    const double direct = (J * V * J.transpose()).trace();
    EXPECT_NEAR(S_m2[g], direct, tolerance * direct) << g;
    EXPECT_NEAR(tip.at(g, V).kinematic, std::sqrt(direct), 1e-12 * std::sqrt(direct));
  }
}

TEST(TipEvaluator, FactoredFormOfACartesianCmmMatchesTheDirectTrace) {
  // Degree 3, 50 calibrated coefficients: the Jacobians are polynomials of the three readings and
  // span few matrices, so the factored form is used (r^2 well below 3 x 50^2).
  const Plan plan = loadPlan(test_support::planFile("cmm-plate-3planes-2styli.json"));
  ASSERT_GT(plan.machine.calibratedCount(), 40);
  WorkspaceSpec spec;
  spec.samples = 1000;
  const TipEvaluator tip(plan.machine, plan.noise, workspaceConfigurations(plan.machine, spec));
  EXPECT_GT(tip.factorRank(), 0);
  EXPECT_LT(tip.factorRank(), 40);
  expectKinematicVarianceMatchesDirectTrace(plan.machine, plan.noise, 1000, 1e-10);
  // A serial arm's Jacobians span many matrices: its Gram form stays cheaper.
  const Plan six = aacmmPlan();
  spec.samples = 4 * 63 + 1;
  EXPECT_EQ(
      TipEvaluator(six.machine, six.noise, workspaceConfigurations(six.machine, spec)).factorRank(),
      0);
}

// TipUse::Once (nothing prepared: J_p L by chunks) gives what the prepared forms give, on a
// workspace of several chunks, for a positive definite V_p (Cholesky) and a semi-definite one
// (the symmetric root): against each configuration's own trace.
TEST(TipEvaluator, OneEvaluationWithoutPreparationMatchesTheDirectTrace) {
  const Plan six = aacmmPlan();
  WorkspaceSpec spec;
  spec.samples = 1300;
  const auto configurations = workspaceConfigurations(six.machine, spec);
  const TipEvaluator once(six.machine, six.noise, configurations, 0, TipUse::Once);
  const TipEvaluator prepared(six.machine, six.noise, configurations);
  const int n = six.machine.calibratedCount();
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n);
  const Eigen::MatrixXd full = 1e-6 * (A * A.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n));
  Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, n - 3);
  const Eigen::MatrixXd semidefinite = 1e-6 * B * B.transpose();
  for (const Eigen::MatrixXd* V : {&full, &semidefinite}) {
    Eigen::VectorXd direct, with_preparation;
    once.kinematicVariance(*V, direct);
    prepared.kinematicVariance(*V, with_preparation);
    ASSERT_EQ(direct.size(), once.size());
    for (int g = 0; g < once.size(); ++g) {
      const double expected = std::pow(once.at(g, *V).kinematic, 2);
      EXPECT_NEAR(direct[g], expected, 1e-11 * expected) << g;
      EXPECT_NEAR(with_preparation[g], expected, 1e-11 * expected) << g;
    }
  }
}

// A planar arm whose forward kinematics fails where the first joint exceeds 0.5 rad (a closed
// chain that does not assemble there).
class FailingAboveHalfRadian final : public Mechanism {
 public:
  std::string modelName() const override { return "failing-planar2r"; }
  int dimension() const override { return 2; }
  int jointCount() const override { return 2; }
  JointKind jointKind(int joint) const override { return arm_.jointKind(joint); }
  const std::vector<ParameterInfo>& parameters() const override { return arm_.parameters(); }
  ForwardStatus forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x,
                        Eigen::MatrixXd* J_x_p = nullptr,
                        Eigen::MatrixXd* J_x_q = nullptr) const override {
    if (q[0] > 0.5) return ForwardStatus::NotConverged;
    return arm_.forward(p, q, x, J_x_p, J_x_q);
  }

 private:
  Planar2R arm_;
};

// TipEvaluator::ofSamples leaves out the samples whose forward kinematics fails, as
// workspaceConfigurations does, and counts them the same: the same configurations kept, in order,
// with the same S_m^2.
TEST(TipEvaluator, OfSamplesLeavesOutWhatWorkspaceConfigurationsLeavesOut) {
  Plan plan = seedPlanar2RPlan();
  plan.machine.mechanism = std::make_shared<FailingAboveHalfRadian>();
  WorkspaceSpec spec;
  spec.samples = 400;
  WorkspaceDrops checked, sampled;
  const auto kept = workspaceConfigurations(plan.machine, spec, &checked);
  const TipEvaluator tip = TipEvaluator::ofSamples(
      plan.machine, plan.noise, workspaceSamples(plan.machine, spec, &sampled), sampled);
  ASSERT_GT(checked.failed, 50);
  ASSERT_GT(kept.size(), 50u);
  EXPECT_EQ(sampled.failed, checked.failed);
  ASSERT_EQ(tip.size(), static_cast<int>(kept.size()));
  for (int g = 0; g < tip.size(); ++g) {
    EXPECT_EQ(tip.configurations()[static_cast<std::size_t>(g)], kept[static_cast<std::size_t>(g)]);
  }
  const TipEvaluator of_kept(plan.machine, plan.noise, kept);
  const Eigen::MatrixXd V = 1e-6 * Eigen::MatrixXd::Identity(plan.machine.calibratedCount(),
                                                             plan.machine.calibratedCount());
  Eigen::VectorXd a, b;
  tip.kinematicVariance(V, a);
  of_kept.kinematicVariance(V, b);
  EXPECT_LT((a - b).norm(), 1e-15 * b.norm());
  EXPECT_EQ(tip.encoderVariance(), of_kept.encoderVariance());
}

// No calibrated parameter: no kinematic part, whichever form (the direct product of width 0 was
// a division by zero in Eigen's blocking heuristic); the encoder part as before.
TEST(TipEvaluator, NothingCalibratedHasNoKinematicPart) {
  Plan plan = seedPlanar2RPlan();
  plan.machine.calibrated.clear();
  WorkspaceSpec spec;
  spec.samples = 700;
  const auto configurations = workspaceConfigurations(plan.machine, spec);
  for (TipUse use : {TipUse::Once, TipUse::Repeated}) {
    const TipEvaluator tip(plan.machine, plan.noise, configurations, 0, use);
    Eigen::VectorXd S_m2;
    tip.kinematicVariance(Eigen::MatrixXd(0, 0), S_m2);
    ASSERT_EQ(S_m2.size(), tip.size());
    EXPECT_EQ(S_m2.cwiseAbs().maxCoeff(), 0.0);
    const TipSummary summary = tip.summarize(Eigen::MatrixXd(0, 0));
    EXPECT_NEAR(summary.worst.total, summary.worst.encoder, 1e-15);
    EXPECT_GT(summary.worst.encoder, 0.0);
  }
  const SymmetricEigenSolver empty{Eigen::MatrixXd(0, 0)};
  EXPECT_EQ(empty.info(), Eigen::Success);
  EXPECT_EQ(empty.eigenvalues().size(), 0);
}

TEST(TipEvaluator, KinematicVarianceMatchesTheDirectTrace) {
  const Plan six = aacmmPlan();  // 21 parameters: Gram form
  expectKinematicVarianceMatchesDirectTrace(six.machine, six.noise);
  // 10 joints, all 43 parameters: the triangular product.
  auto arm = std::make_shared<SerialDH>(std::vector<JointKind>(10, JointKind::Revolute));
  Machine machine;
  machine.mechanism = arm;
  machine.nominal = Eigen::VectorXd::LinSpaced(43, 1.0, 43.0);
  for (int i = 0; i < 43; ++i) machine.calibrated.push_back(i);
  machine.joint_limits.assign(10, {-3.0, 3.0});
  Noise noise;
  noise.probe = 0.01;
  noise.encoder = Eigen::VectorXd::Constant(10, 1e-5);
  expectKinematicVarianceMatchesDirectTrace(machine, noise);
}

// A pose instrument's observation rows (design_matrix.hpp) against central differences, off the
// nominal machine and away from a zero residual (the readings are turned and moved so that
// J_l^-1(e) is not the identity): with the whitening held, dF/dp = A_p and dF/dr = A_r over a
// station step exp(delta); and the whitening's covariance is diag(s^2 I, s_angle^2 I) + J_q
// Sigma_q J_q^T with J_q the central differences of the raw rows in the joints.
TEST(Evaluator, PoseObservationRowsMatchCentralDifferences) {
  const Plan plan = parsePlan(testing::poseTrackerDocument(), "tracker-pose.json");
  const Artifact& tracker = plan.artifacts[0];
  ASSERT_EQ(tracker.rowsPerReading(), 6);
  std::vector<Measurement> readings(plan.placements[0].measurements.begin(),
                                    plan.placements[0].measurements.begin() + 4);
  for (std::size_t i = 0; i < readings.size(); ++i) {
    const double turn = 0.3 * static_cast<double>(i + 1);  // residuals from 0.3 to 1.2 rad
    readings[i].orientation += Eigen::Vector3d(turn, -0.5 * turn, 0.2);
    readings[i].point += Eigen::Vector3d(0.1, -0.2, 0.3);
  }
  Eigen::VectorXd p = plan.machine.nominal;
  for (int k = 0; k < plan.machine.calibratedCount(); ++k)
    p[plan.machine.calibrated[k]] += 1e-3 * (k % 3 - 1);
  const RigidTransform station = fitPlacements(plan, plan.placements, p)[0];
  DesignMatrixBuilder builder(plan.machine, plan.noise);
  ObservationBlock block;
  ReadingWeights weights;
  builder.build(tracker, readings, p, station, Eigen::VectorXd(), true, block, nullptr, &weights);
  ASSERT_EQ(block.rows(), 24);
  ASSERT_GT(block.e.segment<3>(3).norm(), 0.1);  // whitened by 0.005 deg: far from zero

  auto whitened = [&](const Eigen::VectorXd& at_p, const RigidTransform& at_r) {
    ObservationBlock b;
    DesignMatrixBuilder(plan.machine, plan.noise)
        .build(tracker, readings, at_p, at_r, Eigen::VectorXd(), true, b, &weights);
    return b.e;
  };
  const Eigen::VectorXd g0 = plan.machine.calibratedValues(p);
  auto over_p = [&](const Eigen::VectorXd& g) {
    return whitened(plan.machine.withCalibrated(p, g), station);
  };
  testing::expectJacobianNear(block.A_p, testing::centralDifferenceJacobian(over_p, g0, 1e-6), 1e-6,
                              "A_p");
  auto over_r = [&](const Eigen::VectorXd& delta) {
    return whitened(p, station.perturbed(tracker.expandFullRigidStep(delta)));
  };
  testing::expectJacobianNear(
      block.A_r, testing::centralDifferenceJacobian(over_r, Eigen::VectorXd::Zero(6), 1e-7), 1e-6,
      "A_r");

  // The whitening: L L^T against the covariance from the raw rows' joint derivatives.
  for (std::size_t i = 0; i < readings.size(); ++i) {
    auto raw = [&](const Eigen::VectorXd& q) {
      std::vector<Measurement> one{readings[i]};
      one[0].joints = q;
      ReadingWeights unit;
      unit.factors.assign(1, Eigen::Matrix<double, 6, 6>::Identity());
      ObservationBlock b;
      DesignMatrixBuilder(plan.machine, plan.noise)
          .build(tracker, one, p, station, Eigen::VectorXd(), true, b, &unit);
      return Eigen::VectorXd(b.e);
    };
    const Eigen::MatrixXd J_q = testing::centralDifferenceJacobian(raw, readings[i].joints, 1e-6);
    Eigen::MatrixXd Sigma =
        J_q * plan.noise.encoder.array().square().matrix().asDiagonal() * J_q.transpose();
    const double s2 = plan.noise.probe * plan.noise.probe + tracker.noise * tracker.noise;
    Sigma.diagonal() += (Eigen::VectorXd(6) << s2, s2, s2,
                         Eigen::Vector3d::Constant(tracker.noise_angle * tracker.noise_angle))
                            .finished();
    // L^-1 Sigma L^-T = I: every row, the orientation's too, at its own scale.
    const Eigen::Matrix<double, 6, 6>& L = weights.factors[i];
    const Eigen::MatrixXd half = L.triangularView<Eigen::Lower>().solve(Sigma);
    const Eigen::MatrixXd unit = L.triangularView<Eigen::Lower>().solve(half.transpose());
    EXPECT_LT((unit - Eigen::MatrixXd::Identity(6, 6)).cwiseAbs().maxCoeff(), 1e-6)
        << "reading " << i;
  }
}

// The confounding index on a hand-made information (evaluation_result.hpp): N = D M D with M
// unit-diagonal, parameters 1 and 2 correlated by r, 3 alone, D scaling mm against rad by 1e10.
// In closed form (M^-1 of the 2x2 block is [[1, -r], [-r, 1]] / (1 - r^2)): u_k = 1 / (D_k
// sqrt(1 - r^2)) for k = 1, 2 and 1 / D_3, so F = 1 / sqrt(1 - r^2), 1 / sqrt(1 - r^2), 1, whatever
// D is.
TEST(Evaluator, ConfoundingIndexOfACorrelatedPairIsOneOverSqrtOneMinusRSquared) {
  const double r = 0.96;
  const Eigen::Vector3d D(1e6, 1.0, 1e-4);
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
  M(0, 1) = M(1, 0) = r;
  const Eigen::MatrixXd N = D.asDiagonal() * M * D.asDiagonal();
  const auto covariance = covarianceFromInformation(N);
  ASSERT_TRUE(covariance.has_value());
  const double paired = 1.0 / std::sqrt(1.0 - r * r);  // 3.571...
  const Eigen::Vector3d F(paired, paired, 1.0);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(covariance->confounding[k], F[k], 1e-12 * F[k]) << k;
    EXPECT_NEAR(covariance->u[k], F[k] / D[k], 1e-12 * F[k] / D[k]) << k;
  }
  EXPECT_NEAR(covariance->correlation(0, 1), -r, 1e-12);
}

}  // namespace evaluator_test
}  // namespace artcal
