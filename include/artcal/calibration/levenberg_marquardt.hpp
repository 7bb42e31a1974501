#pragma once
// The damping strategy of the calibrator, apart from its iteration loop (as Ceres keeps
// levenberg_marquardt_strategy.h apart from its minimizer). Given the normal equations of the
// reduced problem, N dg = b, it proposes the damped step
//
//   (D N D + mu I) y = D b,   dg = D y,   D = diag(N)^-1/2   (Marquardt's scaling),
//
// and adapts mu from the gain ratio rho = actual / predicted cost reduction (Nielsen's rule:
// accepted: mu *= max(1/3, 1 - (2 rho - 1)^3), nu = 2; rejected: mu *= nu, nu *= 2).
// The cost is sum e^T e (no factor 1/2), so the linear model predicts a reduction of
// 2 b^T dg - dg^T N dg.

#include <Eigen/Core>
#include <string>

namespace artcal {

struct DampingOptions {
  double initial_mu = 1e-4;  ///< damping relative to the scaled (unit-diagonal) normal matrix
  double min_mu = 1e-15;
  double max_mu = 1e16;  ///< beyond this the strategy gives up (no descent step exists)
  bool isValid(std::string* error) const;
};

class LevenbergMarquardtStrategy {
 public:
  explicit LevenbergMarquardtStrategy(const DampingOptions& options = {});

  /// The damped step for N dg = b; false when the damped system cannot be solved.
  bool computeStep(const Eigen::MatrixXd& N, const Eigen::VectorXd& b, Eigen::VectorXd& dg);
  /// 2 b^T dg - dg^T N dg: the reduction of the cost the linearised model predicts.
  static double predictedReduction(const Eigen::MatrixXd& N, const Eigen::VectorXd& b,
                                   const Eigen::VectorXd& dg);
  /// Updates mu after a step whose gain ratio was rho (accepted when rho > 0).
  void stepAccepted(double rho);
  void stepRejected();
  /// True once mu has grown past max_mu: no step reduces the cost any more.
  bool exhausted() const { return mu_ > options_.max_mu; }
  double mu() const { return mu_; }
  void reset();

 private:
  DampingOptions options_;
  double mu_;
  double nu_ = 2.0;
  Eigen::MatrixXd scaled_;
  Eigen::VectorXd scale_;
};

}  // namespace artcal
