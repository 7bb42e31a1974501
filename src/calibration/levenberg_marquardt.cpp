#include "artcal/calibration/levenberg_marquardt.hpp"

#include "artcal/core/dense_decompositions.hpp"
#include <algorithm>
#include <cmath>

namespace artcal {

bool DampingOptions::isValid(std::string* error) const {
  auto fail = [error](const char* message) {
    if (error) *error = message;
    return false;
  };
  if (!(initial_mu > 0.0) || !std::isfinite(initial_mu)) return fail("initial_mu must be > 0");
  if (!(min_mu > 0.0) || min_mu > initial_mu) return fail("min_mu must be in (0, initial_mu]");
  if (!(max_mu > initial_mu) || !std::isfinite(max_mu))
    return fail("max_mu must exceed initial_mu");
  return true;
}

LevenbergMarquardtStrategy::LevenbergMarquardtStrategy(const DampingOptions& options)
    : options_(options), mu_(options.initial_mu) {}

void LevenbergMarquardtStrategy::reset() {
  mu_ = options_.initial_mu;
  nu_ = 2.0;
}

bool LevenbergMarquardtStrategy::computeStep(const Eigen::MatrixXd& N, const Eigen::VectorXd& b,
                                             Eigen::VectorXd& dg) {
  const int n = static_cast<int>(N.rows());
  // Marquardt's scaling: a parameter nothing observes keeps a unit scale (and a zero step).
  scale_.resize(n);
  for (int i = 0; i < n; ++i) scale_[i] = N(i, i) > 0.0 ? 1.0 / std::sqrt(N(i, i)) : 1.0;
  scaled_ = scale_.asDiagonal() * N * scale_.asDiagonal();
  scaled_.diagonal().array() += mu_;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(scaled_);
  if (ldlt.info() != Eigen::Success) return false;
  dg = scale_.asDiagonal() * ldlt.solve(scale_.asDiagonal() * b);
  return dg.allFinite();
}

double LevenbergMarquardtStrategy::predictedReduction(const Eigen::MatrixXd& N,
                                                      const Eigen::VectorXd& b,
                                                      const Eigen::VectorXd& dg) {
  return 2.0 * b.dot(dg) - dg.dot(N * dg);
}

void LevenbergMarquardtStrategy::stepAccepted(double rho) {
  const double shrink = 1.0 - std::pow(2.0 * rho - 1.0, 3);
  mu_ = std::max(options_.min_mu, mu_ * std::max(1.0 / 3.0, shrink));
  nu_ = 2.0;
}

void LevenbergMarquardtStrategy::stepRejected() {
  mu_ *= nu_;
  nu_ *= 2.0;
}

}  // namespace artcal
