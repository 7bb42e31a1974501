// The calibrator reuses what it has built (issues 18 and 21): the rank rule's information and the
// probe-noise misfits read back from its last linearisation, a linearisation re-whitened for a new
// probe noise or for its own state's weights instead of built again. Each reuse must equal the
// computation it replaces, done independently: planInformation at the rigid fits of the readings,
// DesignMatrixBuilder::misfits, a calibrator that builds everything afresh.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "artcal/artcal.hpp"
#include "artcal/calibration/calibrator.hpp"
#include "artcal/io/plan_io.hpp"
#include "plan_builders.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace calibrator_reuse_test {

// Real readings (MUKCa Panda, one tool position, encoder noise stated): the weights depend on p.
Plan frontCenter() {
  return loadPlan(test_support::planFile("panda-position-front-center.json"));
}

// A pose tracker (6 rows per reading, encoder noise stated) whose readings a machine 3 u off
// nominal gave: the reuse must hold for a pose's 6 x 6 whitening factors too.
Plan poseTracker() {
  Plan plan = parsePlan(testing::poseTrackerDocument(), "pose-tracker.json");
  const Evaluation prediction = evaluatePlan(plan);
  const Eigen::VectorXd truth = testing::shiftedTruth(plan, prediction.covariance->u);
  NormalSource normal(11);
  plan.placements = Simulator(plan).simulate(truth, normal).placements;
  return plan;
}

double relativeDifference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(a.cwiseAbs().maxCoeff(), 1e-300);
}

TEST(CalibratorReuse, InformationAtTheEstimateIsPlanInformationAtTheRigidFits) {
  const Plan plan = frontCenter();
  Calibrator calibrator(plan);
  const Calibration c = calibrator.run(plan.placements);
  ASSERT_TRUE(c.summary.converged());
  const PlanInformation reused = calibrator.information(plan.placements);
  // The reference builds the blocks again at the Umeyama fits of the readings, not at the
  // calibrated poses: every coordinate is valued, so the reduced information does not depend on
  // the poses.
  const PlanInformation rebuilt =
      planInformation(plan, plan.placements, c.parameters, /*with_estimable=*/false);
  EXPECT_EQ(reused.rigid_ranks, rebuilt.rigid_ranks);
  EXPECT_LT(relativeDifference(reused.unreduced_diagonal, rebuilt.unreduced_diagonal), 1e-9);
  // The rank rule reads the scaled matrix: its entries are fractions of order 1.
  EXPECT_LT((scaledInformation(reused) - scaledInformation(rebuilt)).cwiseAbs().maxCoeff(), 1e-9);
  const CalibratedSetChoice a = chooseIdentifiableSet(reused, kWeakInformationTolerance);
  const CalibratedSetChoice b = chooseIdentifiableSet(rebuilt, kWeakInformationTolerance);
  EXPECT_EQ(a.kept, b.kept);
  EXPECT_EQ(a.dropped, b.dropped);
}

TEST(CalibratorReuse, MisfitsAreTheBuildersMisfitsAtTheEstimate) {
  // The pose tracker with its probe noise estimated: its orientation rows join the misfits.
  Plan estimated = poseTracker();
  estimated.noise.estimate_probe = true;
  estimated.name += " (probe estimated)";
  for (const Plan& plan : {frontCenter(), poseTracker(), estimated}) {
    SCOPED_TRACE(plan.name);
    Calibrator calibrator(plan);
    const Calibration c = calibrator.run(plan.placements);
    ASSERT_TRUE(c.summary.converged());
    const std::vector<ReadingMisfit> reused = calibrator.misfits(plan.placements);
    std::vector<ReadingMisfit> built;
    const DesignMatrixBuilder builder(plan.machine, plan.noise);
    const GlobalLayout layout = GlobalLayout::of(plan);
    for (std::size_t j = 0; j < plan.placements.size(); ++j) {
      const Placement& placement = plan.placements[j];
      const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
      const int offset =
          layout.artifact_offset[static_cast<std::size_t>(placement.artifact)] - layout.parameters;
      builder.misfits(artifact, placement.measurements, c.parameters, c.poses[j],
                      c.systematic.segment(offset, artifact.systematicCount()), built);
    }
    ASSERT_EQ(reused.size(), built.size());
    for (std::size_t i = 0; i < built.size(); ++i) {
      ASSERT_EQ(reused[i].residual.size(), built[i].residual.size()) << i;
      EXPECT_LT((reused[i].residual - built[i].residual).cwiseAbs().maxCoeff(), 1e-12) << i;
      EXPECT_LT(relativeDifference(reused[i].encoder_covariance, built[i].encoder_covariance), 1e-9)
          << i;
    }
  }
}

// A run from where another converged, the probe noise changed in between (the noise estimate's
// refit): the re-whitened linearisation must give what a calibrator building everything gives.
TEST(CalibratorReuse, RunAfterANewProbeNoiseEqualsAFreshCalibrator) {
  Plan estimated = poseTracker();  // the orientation rows carry their share of s_p^2 too
  estimated.noise.estimate_probe = true;
  estimated.name += " (probe estimated)";
  for (const Plan& original : {frontCenter(), poseTracker(), estimated}) {
    SCOPED_TRACE(original.name);
    const Plan reusing = original;
    Calibrator calibrator(reusing);
    const Calibration first = calibrator.run(reusing.placements);
    ASSERT_TRUE(first.summary.converged());
    CalibrationState state;
    state.p = first.parameters;
    state.c = first.systematic;
    state.poses = first.poses;
    calibrator.setProbeNoise(2.5 * original.noise.probe);  // the calibrator's own noise
    EXPECT_EQ(reusing.noise.probe, original.noise.probe);  // the plan's is not touched
    const Calibration reused = calibrator.run(reusing.placements, state);

    Plan fresh = original;
    fresh.noise.probe = 2.5 * original.noise.probe;
    const Calibration rebuilt = Calibrator(fresh).run(fresh.placements, state);
    ASSERT_TRUE(rebuilt.summary.converged());
    EXPECT_TRUE(reused.summary.converged());
    EXPECT_EQ(reused.summary.iterations, rebuilt.summary.iterations);
    EXPECT_NEAR(reused.chi2, rebuilt.chi2, 1e-9 * rebuilt.chi2);
    ASSERT_TRUE(rebuilt.covariance.has_value() && reused.covariance.has_value());
    const Eigen::VectorXd moved = (fresh.machine.calibratedValues(reused.parameters) -
                                   fresh.machine.calibratedValues(rebuilt.parameters))
                                      .cwiseQuotient(rebuilt.covariance->u);
    EXPECT_LT(moved.cwiseAbs().maxCoeff(), 1e-6);  // in standard uncertainties
    EXPECT_LT(relativeDifference(reused.covariance->u, rebuilt.covariance->u), 1e-7);
  }
}

// The weak rule held parameters after prepare() (calibrate_readings.cpp): the narrowed
// calibrator's linearisation from the prepared one's blocks must be the one a calibrator builds
// for the narrowed set at the same state, and so must the calibration that starts from it.
TEST(CalibratorReuse, PreparedWithoutHeldParametersEqualsAFreshPrepare) {
  for (const Plan& original : {frontCenter(), poseTracker()}) {
    SCOPED_TRACE(original.name);
    Plan plan = original;
    Calibrator wide(plan);
    const CalibrationState start = wide.initialState(plan.placements, plan.machine.nominal);
    ASSERT_TRUE(wide.prepare(plan.placements, start));
    std::vector<int> columns, kept;  // every third parameter held
    for (int k = 0; k < static_cast<int>(plan.machine.calibrated.size()); ++k) {
      if (k % 3 == 1) continue;
      columns.push_back(k);
      kept.push_back(plan.machine.calibrated[static_cast<std::size_t>(k)]);
    }
    plan.machine.calibrated = kept;
    Calibrator narrowed(plan);
    ASSERT_TRUE(narrowed.prepareFrom(wide, columns, plan.placements));
    Calibrator fresh(plan);
    ASSERT_TRUE(fresh.prepare(plan.placements, start));
    const Linearization& a = narrowed.linearization();
    const Linearization& b = fresh.linearization();
    ASSERT_EQ(a.N.rows(), static_cast<int>(kept.size()));
    EXPECT_EQ(a.cost, b.cost);
    EXPECT_TRUE(a.N == b.N);
    EXPECT_TRUE(a.b == b.b);
    EXPECT_EQ(a.rigid_reduction, b.rigid_reduction);
    const Calibration from_narrowed = narrowed.run(plan.placements, start);
    const Calibration from_fresh = fresh.run(plan.placements, start);
    ASSERT_TRUE(from_fresh.summary.converged());
    EXPECT_EQ(from_narrowed.summary.iterations, from_fresh.summary.iterations);
    EXPECT_TRUE(from_narrowed.parameters == from_fresh.parameters);
    EXPECT_EQ(from_narrowed.chi2, from_fresh.chi2);
  }
}

}  // namespace calibrator_reuse_test
}  // namespace artcal
