#pragma once
// The one finite-difference battery every analytic Jacobian goes through (manif / Pinocchio
// style): a central-difference Jacobian of any vector function, and a comparison that reports
// the worst entry relative to the Jacobian's scale.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <functional>
#include <string>

namespace artcal::testing {

using VectorFunction = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

/// dF/dx at x0 by central differences with step h.
inline Eigen::MatrixXd centralDifferenceJacobian(const VectorFunction& F, const Eigen::VectorXd& x0,
                                                 double h) {
  const Eigen::VectorXd f0 = F(x0);
  Eigen::MatrixXd J(f0.size(), x0.size());
  for (int i = 0; i < x0.size(); ++i) {
    Eigen::VectorXd plus = x0, minus = x0;
    plus[i] += h;
    minus[i] -= h;
    J.col(i) = (F(plus) - F(minus)) / (2.0 * h);
  }
  return J;
}

/// Asserts |analytic - numeric| <= tolerance * max(1, |numeric|_max), entry by entry.
inline void expectJacobianNear(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numeric,
                               double tolerance, const std::string& what) {
  ASSERT_EQ(analytic.rows(), numeric.rows()) << what;
  ASSERT_EQ(analytic.cols(), numeric.cols()) << what;
  const double scale = std::max(1.0, numeric.cwiseAbs().maxCoeff());
  for (int r = 0; r < numeric.rows(); ++r) {
    for (int c = 0; c < numeric.cols(); ++c) {
      EXPECT_NEAR(analytic(r, c), numeric(r, c), tolerance * scale)
          << what << " entry (" << r << ", " << c << ")";
    }
  }
}

}  // namespace artcal::testing
