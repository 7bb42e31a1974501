#pragma once
// The ISO 9283 pose accuracy test of an arm or robot predicted from the calibration (docs/method.md
// section 9, "Acceptance tests predicted"):
//
// - the cube: edge e, centre c, axes along the base frame, h = e/2; the measuring plane through
//   Q1 = c + (-h,-h,-h), Q2 = c + (h,h,-h), Q3 = c + (h,h,h), Q4 = c + (-h,-h,h); the points
//   P1 = c, P2 = Q1 + 0.1 (Q3 - Q1), P3 = Q2 + 0.1 (Q4 - Q2), P4 = Q3 + 0.1 (Q1 - Q3),
//   P5 = Q4 + 0.1 (Q2 - Q4);
// - each point's joints by inverse kinematics (model/inverse_kinematics.hpp) from the workspace
//   configuration whose probe is nearest it;
// - AP_P = |J_p(q_P) dp + mean of `cycles` J_q(q_P) eq|: dp ~ N(0, V_p) ONE draw shared by the
//   five points, the encoder noise averaged over the cycles (covariance J_q Sigma_q J_q^T /
//   cycles); its mean, 50 % and 95 % quantiles, those of max_P AP_P and, with an MPE,
//   P(every AP_P <= MPE), by Monte-Carlo (acceptance/monte_carlo.hpp).

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "artcal/acceptance/acceptance.hpp"
#include "artcal/acceptance/monte_carlo.hpp"

namespace artcal {

struct PoseTestOptions {
  double cube = 0.0;  ///< edge, mm
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  std::optional<double> mpe;  ///< mm
  int cycles = 30;
  MonteCarloOptions monte_carlo;
};

struct PosePoint {
  Eigen::Vector3d commanded = Eigen::Vector3d::Zero();              ///< mm
  Eigen::VectorXd joints;                                           ///< internal units
  Eigen::MatrixXd J_p;                                              ///< 3 x calibrated parameters
  Eigen::Matrix3d systematic_covariance = Eigen::Matrix3d::Zero();  ///< mm^2
  Eigen::Matrix3d noise_covariance = Eigen::Matrix3d::Zero();       ///< of the mean, mm^2
  double sigma_sys = 0.0;                                           ///< sqrt(trace), mm
  double sigma_noise = 0.0;                                         ///< sqrt(trace), mm
  Quantiles ap;                                                     ///< AP_P, mm
};

struct PoseTestPrediction {
  std::vector<PosePoint> points;
  std::optional<double> mpe;
  Quantiles max_ap;               ///< max_P AP_P, mm
  MonteCarloSummary monte_carlo;  ///< its statistic is max AP_P / MPE (mm when no MPE)
};

/// The five points of the cube (P1 .. P5).
std::vector<Eigen::Vector3d> poseTestPoints(double cube, const Eigen::Vector3d& center);

/// The points, their joints and their linear statistics (no Monte-Carlo). InputError when the
/// mechanism's probe is not 3-D; RunError naming the point when inverse kinematics finds no
/// joints within the limits.
PoseTestPrediction predictPoseTestLinear(const AcceptanceInput& input,
                                         const PoseTestOptions& options);

/// The Monte-Carlo model: result P is AP_P (3 rows), scaled by 1 / MPE when there is one.
LinearGaussianTest poseTestModel(const PoseTestPrediction& prediction,
                                 const AcceptanceInput& input);

/// predictPoseTestLinear, then the Monte-Carlo.
PoseTestPrediction predictPoseTest(const AcceptanceInput& input, const PoseTestOptions& options);

}  // namespace artcal
