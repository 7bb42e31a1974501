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
#include "artcal/plan/plan.hpp"

namespace artcal {

struct ObservationBlock {
  Eigen::MatrixXd A_p;  ///< rows x N(p): whitened dF/dp over the calibrated parameters
  Eigen::MatrixXd A_r;  ///< rows x N(r_j): whitened dF/dr_j
  Eigen::MatrixXd A_c;  ///< rows x the artifact's systematic errors: whitened dF/dc
  Eigen::VectorXd e;    ///< whitened residual F - W* (only when residuals were asked for)
  int rows() const { return static_cast<int>(A_p.rows()); }
};

/// Builds observation blocks; holds scratch space so that repeated builds do not allocate.
class DesignMatrixBuilder {
 public:
  explicit DesignMatrixBuilder(const Machine& machine, const Noise& noise);

  /// The block of one placement at parameters `p` (full vector) and artifact pose `r`.
  /// `c` holds the artifact's systematic errors (may be empty: zero).
  void build(const Artifact& artifact, const std::vector<Measurement>& measurements,
             const Eigen::VectorXd& p, const RigidTransform& r, const Eigen::VectorXd& c,
             bool with_residuals, ObservationBlock& block);

  /// Machine-frame probe positions f(p, q) of the measurements (dimension x count).
  Eigen::MatrixXd probePositions(const std::vector<Measurement>& measurements,
                                 const Eigen::VectorXd& p) const;

 private:
  const Machine* machine_;
  const Noise* noise_;
  Eigen::VectorXd x_;
  Eigen::MatrixXd J_x_p_, J_x_q_, J_valued_q_, sigma_, J_r_;
  Eigen::VectorXd W_;
};

/// Rigid fit of each placement's probed points at parameters `p` onto the artifact's features:
/// the starting (and, for planning, the nominal) r_j.
std::vector<RigidTransform> fitPlacements(const Plan& plan,
                                          const std::vector<Placement>& placements,
                                          const Eigen::VectorXd& p);

}  // namespace artcal
