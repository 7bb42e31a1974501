#pragma once
// Observation blocks: what one placement contributes to the weighted least-squares problem
// (docs/method.md sections 1-3). The rows are the valued artifact coordinates of its measured
// points, already whitened by Sigma_ij^{-1/2}, Sigma_ij = s_p^2 I_k + J_q Sigma_q J_q^T (eq. of
// section 2), so that the information is simply A^T A. The evaluator, the optimizer and the
// calibrator all build their normal equations from these blocks.

#include <Eigen/Core>
#include <vector>

#include "artcal/artifact/artifact.hpp"
#include "artcal/artifact/rigid_transform.hpp"
#include "artcal/estimation/plane_rows.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

struct ObservationBlock {
  Eigen::MatrixXd A_p;  ///< rows x N(p): whitened dF/dp over the calibrated parameters
  /// rows x the full rigid motion (3 or 6): whitened dF/dr_j. Directions that move no valued
  /// coordinate of the points (a ball bar's roll on consistent readings) are zero columns, left to
  /// the rank policy of the reduction (normal_matrix.hpp).
  Eigen::MatrixXd A_r;
  /// The leading columns of A_r the artifact's table counts (Artifact::rigidDof(), its
  /// fullRigidOrder()); the rest are eliminated only where the points observe them.
  int rigid_primary = 0;
  Eigen::MatrixXd A_c;  ///< rows x the artifact's systematic errors: whitened dF/dc
  Eigen::VectorXd e;    ///< whitened residual F - W* (only when residuals were asked for)
  int rows() const { return static_cast<int>(A_p.rows()); }
};

/// One reading's misfit in its valued artifact coordinates, before whitening: the residual
/// F - W* and the encoders' part of its covariance, J_q Sigma_q J_q^T (the probe adds s_p^2 I).
/// The probe-noise estimate (calibration/calibrate_readings.hpp) solves for s_p from these.
/// A point's 3 valued coordinates or fewer, a pose's 6.
struct ReadingMisfit {
  // At most 6 rows (a pose: the point's, then the orientation's), on the stack.
  Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 6, 1> residual;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, 6> encoder_covariance;
};

/// The whitening factors L of a placement's readings (Sigma_ij = L L^T, section 2), in reading
/// order (the top-left k x k of each). The weights depend on p through J_q: the calibrator holds
/// them while it tries steps (iteratively reweighted least squares), so that a trial's cost is
/// compared with the current one under the same weights.
struct ReadingWeights {
  /// Top-left rows x rows of each: 3 (or fewer) for a point, 6 for a pose (instruments.md).
  std::vector<Eigen::Matrix<double, 6, 6>> factors;
};

/// Builds observation blocks; holds scratch space so that repeated builds do not allocate.
/// A pose instrument's reading (Artifact::measures_pose) gives 6 rows: its point's, then its
/// orientation's, e = log(R_r R(p, q) exp([m]x)^T) (model/rotation_vector.hpp) with the exact
/// derivatives de/dp = J_l^-1(e) R_r J_w_p, de/dq likewise, de/d(rotation of r) = J_l^-1(e),
/// de/d(translation of r) = 0; whitened together, Sigma = diag(s^2 I_3, s_angle^2 I_3) +
/// J_q Sigma_q J_q^T over the 6 rows.
class DesignMatrixBuilder {
 public:
  explicit DesignMatrixBuilder(const Machine& machine, const Noise& noise);

  /// The noise the blocks are whitened with (a copy of the plan's when built).
  const Noise& noise() const { return noise_; }
  /// A new probe noise s_p (mm) for the blocks built from here on (the variance component a
  /// calibration estimates, calibrate_readings.hpp); the plan it came from is not touched.
  void setProbeNoise(double probe) { noise_.probe = probe; }

  /// The block of one placement at parameters `p` (full vector) and artifact pose `r`.
  /// `c` holds the artifact's systematic errors (may be empty: zero).
  /// `held`: whiten with these factors instead of the ones at p; `record`: receives the factors
  /// used; `own`: receives the factors at p also when `held` whitened (what re-whitening the
  /// block for its own state needs, calibrator.cpp).
  void build(const Artifact& artifact, const std::vector<Measurement>& measurements,
             const Eigen::VectorXd& p, const RigidTransform& r, const Eigen::VectorXd& c,
             bool with_residuals, ObservationBlock& block, const ReadingWeights* held = nullptr,
             ReadingWeights* record = nullptr, ReadingWeights* own = nullptr);

  /// Appends the misfit of each measurement at (p, r, c) to `out` (see ReadingMisfit). With
  /// `joint_jacobians`, also each residual's exact derivative in the reading's joints (its rows
  /// scaled as the residual's; what consistentPlacements steps the joints with).
  void misfits(const Artifact& artifact, const std::vector<Measurement>& measurements,
               const Eigen::VectorXd& p, const RigidTransform& r, const Eigen::VectorXd& c,
               std::vector<ReadingMisfit>& out,
               std::vector<Eigen::MatrixXd>* joint_jacobians = nullptr) const;

  /// Machine-frame probe positions f(p, q) of the measurements (dimension x count).
  Eigen::MatrixXd probePositions(const std::vector<Measurement>& measurements,
                                 const Eigen::VectorXd& p) const;

 private:
  /// One reading's covariance is at most 6 x 6 (a pose): on the stack.
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, 6>;
  /// The whitening factor L (Sigma = L L^T) of the reading of the last forward call: `per` rows,
  /// the point's `k` valued rows (rotated by R_valued) then a pose's orientation rows.
  Small readingFactor(const Eigen::Ref<const Eigen::MatrixXd>& R_valued, int per, int k,
                      double sigma_p2, double sigma_angle2, const Artifact& artifact);
  /// readingFactor of a point reading (`k` rows).
  Small pointFactor(const Eigen::Ref<const Eigen::MatrixXd>& R_valued, int k, double sigma_p2);
  /// weights.factors[i] (of `readings`) = L, zero-padded.
  static void storeFactor(ReadingWeights& weights, std::size_t readings, std::size_t i,
                          const Small& L);

  const Machine* machine_;
  Noise noise_;  ///< its own copy: a calibration's re-estimated probe noise is set here
  Eigen::VectorXd x_;
  Eigen::MatrixXd J_x_p_, J_x_q_, J_w_p_, J_w_q_, J_valued_q_, J_r_;
  Eigen::Matrix3d R_tip_, orientation_factor_;
  Eigen::VectorXd W_;

  PlaneRows plane_rows_;
  PlaneRowsScratch plane_scratch_;
  /// A plane reading's rows at `row` (plane_rows.hpp); returns the factor of their covariance.
  Small planeReading(const Artifact& artifact, const Measurement& m, const Eigen::VectorXd& p,
                     const RigidTransform& r, const Eigen::VectorXd& c, int row,
                     bool with_residuals, ObservationBlock& block);

  void orientationRows(const Artifact& artifact, const Measurement& m, const RigidTransform& r,
                       int row, bool with_residuals, ObservationBlock& block);
};

/// Rigid fit of each placement's probed points at parameters `p` onto the artifact's features:
/// the starting (and, for planning, the nominal) r_j.
std::vector<RigidTransform> fitPlacements(const Plan& plan,
                                          const std::vector<Placement>& placements,
                                          const Eigen::VectorXd& p);

}  // namespace artcal
