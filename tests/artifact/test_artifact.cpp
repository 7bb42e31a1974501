// Artifacts: N(r_j) per kind and dimension (method.md section 1), the rigid Jacobian against
// finite differences of RigidTransform::perturbed, the directions left out moving no valued
// coordinate, and the systematic errors c (section 2).

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "artcal/artcal.hpp"
#include "finite_difference.hpp"

namespace artcal {
namespace artifact_test {

using testing::centralDifferenceJacobian;
using testing::expectJacobianNear;

std::vector<Artifact> everyKind(int dimension) {
  Eigen::MatrixXd centers(dimension, 4);
  if (dimension == 2) {
    centers << 0, 60, 0, 60,  //
        0, 0, 40, 40;
  } else {
    centers << 0, 60, 0, 60,  //
        0, 0, 40, 40,         //
        0, 0, 0, 10;
  }
  return {Artifact::ballBar("bar", dimension, 80.0, 0.001),
          Artifact::ballPlate("plate", centers, 0.002),
          Artifact::stepGauge("gauge", dimension, {0.0, 20.0, 50.0, 110.0}, 0.0005)};
}

RigidTransform somePlacement(int dimension) {
  if (dimension == 2) return placePlanar(Eigen::Vector2d(120.0, -35.0), 0.7);
  return placeSpatial(Eigen::Vector3d(300.0, 150.0, -80.0), Eigen::Vector3d(0.3, -0.5, 0.8), 0.4);
}

TEST(Artifact, RigidDegreesOfFreedom) {
  const auto planar = everyKind(2);
  EXPECT_EQ(planar[0].rigidDof(), 3);
  EXPECT_EQ(planar[1].rigidDof(), 3);
  EXPECT_EQ(planar[2].rigidDof(), 2);
  const auto spatial = everyKind(3);
  EXPECT_EQ(spatial[0].rigidDof(), 5);
  EXPECT_EQ(spatial[1].rigidDof(), 6);
  EXPECT_EQ(spatial[2].rigidDof(), 3);
  EXPECT_EQ(spatial[0].valuedPerFeature(), 3);
  EXPECT_EQ(spatial[2].valuedPerFeature(), 1);
}

// dW_valued/dr at each feature against finite differences of the valued coordinates of
// perturbed(expandRigidStep(step)) applied to the feature's machine-frame point.
TEST(Artifact, RigidJacobianMatchesFiniteDifferencesOfPerturbed) {
  for (int dimension : {2, 3}) {
    const RigidTransform T = somePlacement(dimension);
    const RigidTransform toMachine = T.inverse();
    for (const Artifact& artifact : everyKind(dimension)) {
      const int k = artifact.valuedPerFeature();
      for (int i = 0; i < artifact.featureCount(); ++i) {
        // A point near the feature (a real reading is off by the machine's errors).
        Eigen::VectorXd W = artifact.features.col(i);
        W += Eigen::VectorXd::Constant(dimension, 0.3);
        const Eigen::VectorXd x = toMachine.apply(W);
        const auto F = [&](const Eigen::VectorXd& step) {
          return Eigen::VectorXd(T.perturbed(artifact.expandRigidStep(step)).apply(x).head(k));
        };
        Eigen::MatrixXd J(k, artifact.rigidDof());
        artifact.rigidJacobian(T.apply(x), J);
        const Eigen::VectorXd zero = Eigen::VectorXd::Zero(artifact.rigidDof());
        expectJacobianNear(J, centralDifferenceJacobian(F, zero, 1e-6), 1e-7,
                           artifactTypeName(artifact) + " " + std::to_string(dimension) +
                               "-D feature " + std::to_string(i));
      }
    }
  }
}

// The rigid directions an artifact leaves out do not move any valued coordinate of its features
// to first order (that is why they are not estimated).
TEST(Artifact, DirectionsLeftOutMoveNoValuedCoordinate) {
  for (int dimension : {2, 3}) {
    const RigidTransform T = RigidTransform::identity(dimension);
    for (const Artifact& artifact : everyKind(dimension)) {
      const auto& kept = artifact.rigidDirections();
      const int k = artifact.valuedPerFeature();
      for (int direction = 0; direction < rigidMotionSize(dimension); ++direction) {
        if (std::find(kept.begin(), kept.end(), direction) != kept.end()) continue;
        for (int i = 0; i < artifact.featureCount(); ++i) {
          const Eigen::VectorXd W = artifact.features.col(i);
          const auto F = [&](const Eigen::VectorXd& s) {
            Eigen::VectorXd delta = Eigen::VectorXd::Zero(rigidMotionSize(dimension));
            delta[direction] = s[0];
            return Eigen::VectorXd(T.perturbed(delta).apply(W).head(k));
          };
          const Eigen::MatrixXd d = centralDifferenceJacobian(F, Eigen::VectorXd::Zero(1), 1e-6);
          EXPECT_LT(d.cwiseAbs().maxCoeff(), 1e-7)
              << artifactTypeName(artifact) << " direction " << direction;
        }
      }
      // ... and every kept direction moves a valued coordinate of some feature (a step gauge's
      // tilts only when the face is probed off its axis).
      for (std::size_t c = 0; c < kept.size(); ++c) {
        double largest = 0.0;
        Eigen::MatrixXd J(k, artifact.rigidDof());
        for (int i = 0; i < artifact.featureCount(); ++i) {
          Eigen::VectorXd W = artifact.features.col(i);
          if (artifact.kind().one_valued_coordinate) W.tail(dimension - 1).array() += 5.0;
          artifact.rigidJacobian(W, J);
          largest = std::max(largest, J.col(static_cast<int>(c)).cwiseAbs().maxCoeff());
        }
        EXPECT_GT(largest, 0.5) << artifactTypeName(artifact) << " kept " << kept[c];
      }
    }
  }
}

TEST(Artifact, BallBarFeaturesAndLengthError) {
  const Artifact bar = Artifact::ballBar("bar", 3, 300.0, 0.002);
  ASSERT_EQ(bar.featureCount(), 2);
  EXPECT_EQ(bar.features.col(0), Eigen::Vector3d::Zero());
  EXPECT_EQ(bar.features.col(1), Eigen::Vector3d(300.0, 0.0, 0.0));
  ASSERT_EQ(bar.systematicCount(), 1);  // one length error: the second ball along X
  EXPECT_EQ(bar.systematic[0].feature, 1);
  EXPECT_EQ(bar.systematic[0].coordinate, 0);
  EXPECT_DOUBLE_EQ(bar.systematic[0].sigma, 0.002);
  const Eigen::VectorXd c = Eigen::VectorXd::Constant(1, 0.01);
  EXPECT_EQ(bar.feature(1, c), Eigen::Vector3d(300.01, 0.0, 0.0));
  EXPECT_EQ(bar.feature(0, c), Eigen::Vector3d::Zero());
  EXPECT_EQ(Artifact::ballBar("exact", 2, 80.0, 0.0).systematicCount(), 0);
}

TEST(Artifact, PlateAndGaugeSystematicErrors) {
  const auto kinds = everyKind(2);
  EXPECT_EQ(kinds[1].systematicCount(), 8);  // every coordinate of every centre
  EXPECT_EQ(kinds[2].systematicCount(), 4);  // one per face, along X
  const Eigen::VectorXd c = Eigen::VectorXd::LinSpaced(8, 1.0, 8.0);
  EXPECT_EQ(kinds[1].feature(2, c), Eigen::Vector2d(0.0 + 5.0, 40.0 + 6.0));
  const Eigen::VectorXd g = Eigen::VectorXd::LinSpaced(4, 0.1, 0.4);
  EXPECT_NEAR(kinds[2].feature(3, g)[0], 110.4, 1e-12);
}

TEST(RigidTransform, PerturbedComposesOnTheArtifactSide) {
  const RigidTransform T = somePlacement(3);
  Eigen::VectorXd delta(6);
  delta << 1.0, -2.0, 0.5, 0.0, 0.0, 0.3;
  const RigidTransform P = T.perturbed(delta);
  const Eigen::Vector3d x(10.0, 20.0, 30.0);
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_LT((P.apply(x) - (Rz * T.apply(x) + delta.head(3))).norm(), 1e-12);
  EXPECT_LT((T.inverse().apply(T.apply(x)) - x).norm(), 1e-12);
}

TEST(RigidTransform, FitRigidRecoversAKnownTransform) {
  const RigidTransform T = somePlacement(3);
  Eigen::MatrixXd machine(3, 4), artifact(3, 4);
  machine << 0, 100, 0, 30,  //
      0, 0, 50, 20,          //
      0, 0, 0, 70;
  for (int i = 0; i < 4; ++i) artifact.col(i) = T.apply(machine.col(i));
  const RigidTransform fit = fitRigid(machine, artifact);
  EXPECT_LT((fit.R - T.R).norm(), 1e-12);
  EXPECT_LT((fit.t - T.t).norm(), 1e-9);
}

}  // namespace artifact_test
}  // namespace artcal
