#include "artcal/acceptance/monte_carlo.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "artcal/calibration/simulation.hpp"
#include "artcal/core/parallel.hpp"

namespace artcal {

double sampleQuantile(std::vector<double>& values, double prob) {
  if (values.empty()) return 0.0;
  const double position = prob * static_cast<double>(values.size() - 1);
  const auto below = static_cast<std::size_t>(std::floor(position));
  const std::size_t above = std::min(below + 1, values.size() - 1);
  std::nth_element(values.begin(), values.begin() + static_cast<long>(below), values.end());
  const double low = values[below];
  if (above == below) return low;
  const double high = *std::min_element(values.begin() + static_cast<long>(above), values.end());
  return low + (position - static_cast<double>(below)) * (high - low);
}

namespace {

/// Per worker: the shared normals, the systematic part and one result's noise draw.
struct TrialScratch {
  Eigen::VectorXd z, s, w, v;
};

/// One trial: the statistic, and each result's r_i into `results` when not null.
double drawTrial(const LinearGaussianTest& test, NormalSource& normal, TrialScratch& scratch,
                 double* results) {
  for (Eigen::Index k = 0; k < scratch.z.size(); ++k) scratch.z[k] = normal();
  scratch.s.noalias() = test.A * scratch.z;
  double statistic = 0.0;
  for (std::size_t i = 0; i < test.results.size(); ++i) {
    const TestResult& result = test.results[i];
    double r = 0.0;
    if (result.size == 1) {
      r = std::abs(scratch.s[result.first_row] + result.noise_factor(0, 0) * normal());
    } else {
      scratch.w.resize(result.size);
      for (int k = 0; k < result.size; ++k) scratch.w[k] = normal();
      scratch.v = scratch.s.segment(result.first_row, result.size);
      scratch.v.noalias() += result.noise_factor * scratch.w;
      r = scratch.v.norm();
    }
    r *= result.scale;
    if (results) results[i] = r;
    statistic = std::max(statistic, r);
  }
  return statistic;
}

/// Trials [first, first + count) (first a multiple of kChunkTrials) into the stores.
void runTrials(const LinearGaussianTest& test, const MonteCarloOptions& options, long first,
               long count, std::vector<double>& statistics, std::vector<double>& results) {
  const long first_chunk = first / kChunkTrials;
  const int chunks = static_cast<int>((count + kChunkTrials - 1) / kChunkTrials);
  const int threads = threadCount(options.threads, chunks);
  std::vector<TrialScratch> scratch(static_cast<std::size_t>(threads));
  for (TrialScratch& s : scratch) s.z.resize(test.A.cols());
  const auto per_trial = static_cast<long>(test.results.size());
  parallelFor(chunks, threads, [&](int chunk, int worker) {
    const long chunk_index = first_chunk + chunk;
    NormalSource normal(trialSeed(options.seed, static_cast<std::uint64_t>(chunk_index)));
    const long begin = chunk_index * kChunkTrials;
    const long end = std::min(begin + kChunkTrials, first + count);
    for (long t = begin; t < end; ++t) {
      double* row = test.record_results ? results.data() + t * per_trial : nullptr;
      statistics[static_cast<std::size_t>(t)] =
          drawTrial(test, normal, scratch[static_cast<std::size_t>(worker)], row);
    }
  });
}

double passFraction(const std::vector<double>& statistics, long begin, long end) {
  const long passed = std::count_if(statistics.begin() + begin, statistics.begin() + end,
                                    [](double value) { return value <= 1.0; });
  return static_cast<double>(passed) / static_cast<double>(end - begin);
}

Quantiles quantilesOf(std::vector<double> values) {
  Quantiles q;
  if (values.empty()) return q;
  q.mean = std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
  q.median = sampleQuantile(values, 0.5);
  q.q95 = sampleQuantile(values, 0.95);
  return q;
}

/// GUM S1 7.9.4: twice the standard deviation of the batches' mean 95 % quantile within the
/// tolerance, relative to it.
bool quantileStable(const std::vector<double>& batch_q95, double tolerance) {
  const auto h = static_cast<double>(batch_q95.size());
  if (batch_q95.size() < 2) return false;
  const double mean = std::accumulate(batch_q95.begin(), batch_q95.end(), 0.0) / h;
  double sum2 = 0.0;
  for (double q : batch_q95) sum2 += (q - mean) * (q - mean);
  const double standard_deviation_of_mean = std::sqrt(sum2 / (h * (h - 1.0)));
  return 2.0 * standard_deviation_of_mean <= tolerance * std::abs(mean);
}

double binomialStandardError(double p, long trials) {
  return std::sqrt(std::max(p * (1.0 - p), 0.0) / static_cast<double>(trials));
}

/// How many trials: the fixed count, or batches until GUM S1 7.9's criteria hold.
long runAllTrials(const LinearGaussianTest& test, const MonteCarloOptions& options,
                  std::vector<double>& statistics, std::vector<double>& results, bool& stable) {
  const auto per_trial = static_cast<std::size_t>(test.results.size());
  auto reserve = [&](long total) {
    statistics.resize(static_cast<std::size_t>(total));
    if (test.record_results) results.resize(static_cast<std::size_t>(total) * per_trial);
  };
  if (options.trials > 0) {
    reserve(options.trials);
    runTrials(test, options, 0, options.trials, statistics, results);
    stable = true;
    return options.trials;
  }
  const long batch = std::max<long>(kChunkTrials, options.batch / kChunkTrials * kChunkTrials);
  std::vector<double> batch_q95;
  long done = 0;
  stable = false;
  while (done + batch <= std::max(options.max_trials, batch)) {
    reserve(done + batch);
    runTrials(test, options, done, batch, statistics, results);
    std::vector<double> values(statistics.begin() + done, statistics.begin() + done + batch);
    batch_q95.push_back(sampleQuantile(values, 0.95));
    done += batch;
    const double p = passFraction(statistics, 0, done);
    if (quantileStable(batch_q95, options.quantile_tolerance) &&
        binomialStandardError(p, done) <= options.max_standard_error) {
      stable = true;
      break;
    }
  }
  return done;
}

}  // namespace

MonteCarloSummary runMonteCarlo(const LinearGaussianTest& test, const MonteCarloOptions& options) {
  if (test.results.empty()) throw std::invalid_argument("runMonteCarlo: no results");
  MonteCarloSummary summary;
  summary.adaptive = options.trials <= 0;
  std::vector<double> statistics, results;
  summary.trials = runAllTrials(test, options, statistics, results, summary.stable);
  summary.p_pass = passFraction(statistics, 0, summary.trials);
  summary.p_pass_standard_error = binomialStandardError(summary.p_pass, summary.trials);
  summary.statistic = quantilesOf(std::move(statistics));
  if (test.record_results) {
    const std::size_t n = test.results.size();
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<double> values(static_cast<std::size_t>(summary.trials));
      for (std::size_t t = 0; t < values.size(); ++t) values[t] = results[t * n + i];
      summary.results.push_back(quantilesOf(std::move(values)));
    }
  }
  return summary;
}

double conditionalPassProbability(const LinearGaussianTest& test, const Eigen::VectorXd& s) {
  double probability = 1.0;
  for (const TestResult& result : test.results) {
    if (result.size != 1)
      throw std::invalid_argument("conditionalPassProbability: scalar results only");
    const double limit = 1.0 / result.scale;
    const double sigma = std::abs(result.noise_factor(0, 0));
    const double mean = s.size() > 0 ? s[result.first_row] : 0.0;
    if (sigma == 0.0) {
      probability *= std::abs(mean) <= limit ? 1.0 : 0.0;
      continue;
    }
    const double k = 1.0 / (sigma * std::sqrt(2.0));
    probability *= 0.5 * (std::erf((limit - mean) * k) + std::erf((limit + mean) * k));
  }
  return probability;
}

double passProbabilityWithoutSystematic(const LinearGaussianTest& test) {
  return conditionalPassProbability(test, Eigen::VectorXd::Zero(test.A.rows()));
}

}  // namespace artcal
