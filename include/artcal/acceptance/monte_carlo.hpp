#pragma once
// Monte-Carlo of an acceptance test whose results are linear in one shared Gaussian draw plus
// independent Gaussian noise per result (docs/method.md, acceptance; docs/method.md section 9):
//
//   s = A z,  z ~ N(0, I_n)               the systematic part, ONE draw per trial shared by all
//                                          results (A = G chol(V_p): rows are the results'
//                                          systematic components over the calibrated parameters)
//   v_i = s[rows of i] + L_i w_i,  w_i ~ N(0, I_k)   result i: k components (1 for a length
//                                          error, 3 for a pose error), its own noise factor L_i
//   r_i = scale_i |v_i|                    e.g. |E_i| / MPE(L_i), or AP_P / MPE
//   statistic = max_i r_i, pass = statistic <= 1.
//
// Trials run in chunks of kChunkTrials, chunk c drawing from NormalSource(trialSeed(seed, c)), its
// values written by trial index: a fixed seed gives the same figures whatever the thread count.
// Adaptive trials (GUM Supplement 1, 7.9): batches of `batch` trials until the batches' 95 %
// quantiles of the statistic agree to `quantile_tolerance` (relative) at 95 % confidence (twice
// the standard deviation of their mean) and P(pass)'s standard error is at most
// `max_standard_error`, at most `max_trials`.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace artcal {

inline constexpr int kChunkTrials = 1000;

/// One result of the test: `size` consecutive rows of A from `first_row`, its noise factor
/// (size x size, F F^T the noise covariance: noise = F w) and the scale applied to |v|.
struct TestResult {
  int first_row = 0;
  int size = 1;
  Eigen::MatrixXd noise_factor = Eigen::MatrixXd::Zero(1, 1);
  double scale = 1.0;
};

struct LinearGaussianTest {
  Eigen::MatrixXd A;  ///< systematic rows x shared normals
  std::vector<TestResult> results;
  /// Keep every result's r_i per trial (ISO 9283 quantiles per point), not only the statistic.
  bool record_results = false;
};

struct MonteCarloOptions {
  long trials = 0;  ///< 0: adaptive
  std::uint64_t seed = 20261201;
  int threads = 0;  ///< 0: the hardware's
  int batch = 10000;
  long max_trials = 1000000;
  double quantile_tolerance = 0.01;
  double max_standard_error = 0.002;
};

struct Quantiles {
  double mean = 0.0;
  double median = 0.0;
  double q95 = 0.0;
};

struct MonteCarloSummary {
  long trials = 0;
  bool adaptive = false;
  bool stable = false;  ///< adaptive: both criteria met before max_trials
  double p_pass = 0.0;  ///< fraction of trials with statistic <= 1
  double p_pass_standard_error = 0.0;
  Quantiles statistic;
  std::vector<Quantiles> results;  ///< per result, when record_results
};

/// Linear-interpolated quantile (type 7) of `values` (reordered in place), prob in [0, 1].
double sampleQuantile(std::vector<double>& values, double prob);

/// The Monte-Carlo of `test` (above).
MonteCarloSummary runMonteCarlo(const LinearGaussianTest& test, const MonteCarloOptions& options);

/// The exact P(pass) when there is no systematic part (A = 0) and every result is scalar:
/// prod_i P(|N(0, sigma_i)| <= 1 / scale_i) = prod_i erf(1 / (scale_i sigma_i sqrt 2)).
double passProbabilityWithoutSystematic(const LinearGaussianTest& test);

/// P(pass | s) for scalar results: prod_i P(|s_i + sigma_i w| <= 1 / scale_i).
double conditionalPassProbability(const LinearGaussianTest& test, const Eigen::VectorXd& s);

}  // namespace artcal
