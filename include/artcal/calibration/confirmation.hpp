#pragma once
// Monte-Carlo confirmation of a plan's predicted covariance (docs/method.md section 6): T simulated
// calibrations, each with
//   p_true = nominal + perturbation * u_pred * z,  z ~ N(0, I)   (over the calibrated parameters),
// readings from Simulator, estimates from Calibrator started at the nominal parameters. For
// every calibrated parameter the empirical standard deviation of (estimate - true) (sample
// standard deviation, T - 1 degrees of freedom) is compared with the predicted u = sqrt(diag V_p)
// of evaluatePlan at nominal: ratio = empirical / predicted.
// A parameter with a prior (machine.prior, nominal tolerance sigma_0) is drawn from that prior
// instead, p_true = nominal + sigma_0 z: V_p = (N_red + Sigma_p0^-1)^-1 is the covariance of
// estimate - true for a machine that is distributed as its prior says (docs/method.md section 3),
// not for one held at a fixed offset (the prior would then bias every estimate alike).
//
// The band. With Gaussian errors, the relative standard error of a sample standard deviation is
// about 1 / sqrt(2 (T - 1)). Each of the n ratios must lie within
//   1 +- (k_n / sqrt(2 (T - 1)) + allowance),
// k_n the two-sided normal quantile at family-wise level `level` over n parameters (Bonferroni:
// Phi^-1(1 - level / (2 n))), `allowance` a stated margin for the non-linearity of the model over
// the perturbation (default 5 %). `confirmed` needs every ratio inside the band and every trial
// converged.
//
// Reproducibility: trial i draws from NormalSource(trialSeed(seed, i)) and writes its own result
// slot; statistics are summed in trial order. The outcome is identical for any thread count.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "artcal/calibration/calibrator.hpp"
#include "artcal/calibration/simulation.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

struct ConfirmationOptions {
  int trials = 200;
  std::uint64_t seed = 1;
  int threads = 0;            ///< 0: std::thread::hardware_concurrency()
  double noise_scale = 1.0;   ///< simulate K times the declared noise (a negative control)
  double perturbation = 3.0;  ///< p_true - nominal, in predicted standard uncertainties
  double level = 0.01;        ///< family-wise probability of a false alarm for the band
  double allowance = 0.05;    ///< relative allowance for non-linearity added to the band
  CalibrationOptions calibration;
  /// Called as trials finish (trials done, total), from worker threads, serialised.
  std::function<void(int, int)> progress;
  bool isValid(std::string* error) const;
};

struct ConfirmedParameter {
  std::string name;
  double predicted_u = 0.0;  ///< internal units
  double empirical_u = 0.0;  ///< internal units
  double bias = 0.0;         ///< mean of (estimate - true), internal units
  double ratio = 0.0;
  bool inside = false;
};

struct Band {
  double low = 0.0;
  double high = 0.0;
  double coverage_factor = 0.0;  ///< k_n
  double sampling = 0.0;         ///< 1 / sqrt(2 (T - 1))
  double allowance = 0.0;
};

struct Confirmation {
  bool confirmed = false;
  int trials = 0;
  int converged_trials = 0;
  Band band;
  std::vector<ConfirmedParameter> parameters;
  double mean_chi2_per_dof = 0.0;  ///< over converged trials: near noise_scale^2 when right
};

/// Per component: the mean and the sample standard deviation (divisor T - 1, the unbiased
/// variance; docs/method.md section 9) of T samples. Zero deviations when T < 2.
struct SampleStatistics {
  Eigen::VectorXd mean;
  Eigen::VectorXd deviation;
};
SampleStatistics sampleStatistics(const std::vector<Eigen::VectorXd>& samples, int dimension);

/// Two-sided coverage factor: Phi^-1(1 - level / (2 n)).
double bonferroniFactor(double level, int n);
/// The band for T trials and n parameters.
Band confirmationBand(int trials, int n, double level, double allowance);

/// Runs the confirmation. InputError when the plan is not identifiable (no prediction exists).
Confirmation confirmPlan(const Plan& plan, const ConfirmationOptions& options);

}  // namespace artcal
