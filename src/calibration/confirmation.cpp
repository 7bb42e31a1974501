#include "artcal/calibration/confirmation.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <optional>

#include "artcal/core/error.hpp"
#include "artcal/core/parallel.hpp"
#include "artcal/estimation/evaluator.hpp"

namespace artcal {

bool ConfirmationOptions::isValid(std::string* error) const {
  auto fail = [error](const char* message) {
    if (error) *error = message;
    return false;
  };
  if (trials < 2) return fail("trials must be at least 2");
  if (threads < 0) return fail("threads must be >= 0");
  if (!(noise_scale > 0.0) || !std::isfinite(noise_scale)) return fail("noise_scale must be > 0");
  if (!(perturbation >= 0.0) || !std::isfinite(perturbation))
    return fail("perturbation must be >= 0");
  if (!(level > 0.0 && level < 1.0)) return fail("level must be in (0, 1)");
  if (!(allowance >= 0.0) || !std::isfinite(allowance)) return fail("allowance must be >= 0");
  return calibration.isValid(error);
}

double bonferroniFactor(double level, int n) {
  // Solve erfc(k / sqrt 2) = level / n (two-sided tail) by bisection: monotone, exact enough.
  const double tail = level / std::max(n, 1);
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::sqrt(2.0)) > tail ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Band confirmationBand(int trials, int n, double level, double allowance) {
  Band band;
  band.coverage_factor = bonferroniFactor(level, n);
  band.sampling = 1.0 / std::sqrt(2.0 * (trials - 1));
  band.allowance = allowance;
  const double half = band.coverage_factor * band.sampling + allowance;
  band.low = std::max(0.0, 1.0 - half);
  band.high = 1.0 + half;
  return band;
}

namespace {

struct TrialResult {
  bool converged = false;
  Eigen::VectorXd error;  ///< estimate - true over the calibrated parameters
  double chi2_per_dof = 0.0;
};

/// One trial: its own generator, its own truth, simulated readings, calibration.
TrialResult runTrial(const Plan& plan, const Simulator& simulator, Calibrator& calibrator,
                     const Eigen::VectorXd& predicted_u, const ConfirmationOptions& options,
                     int trial) {
  const Machine& machine = plan.machine;
  NormalSource normal(trialSeed(options.seed, static_cast<std::uint64_t>(trial)));
  Eigen::VectorXd shift(machine.calibratedCount());
  const Eigen::VectorXd prior_sigma = machine.prior_sigma.size() > 0
                                          ? machine.calibratedValues(machine.prior_sigma)
                                          : Eigen::VectorXd::Zero(shift.size());
  for (int k = 0; k < shift.size(); ++k) {
    // A parameter with a prior is drawn from it (confirmation.hpp).
    const double scale =
        prior_sigma[k] > 0.0 ? prior_sigma[k] : options.perturbation * predicted_u[k];
    shift[k] = scale * normal();
  }
  const Eigen::VectorXd p_true =
      machine.withCalibrated(machine.nominal, machine.calibratedValues(machine.nominal) + shift);
  TrialResult result;
  SimulatedRun run;
  try {
    run = simulator.simulate(p_true, normal);
  } catch (const RunError& e) {
    throw e.within("trial " + std::to_string(trial) + " (seed " + std::to_string(options.seed) +
                   ")");
  }
  const Calibration calibration = calibrator.run(run.placements);
  result.converged = calibration.summary.converged();
  result.error = calibration.estimate(machine) - machine.calibratedValues(p_true);
  result.chi2_per_dof = calibration.chi2_per_dof;
  return result;
}

}  // namespace

SampleStatistics sampleStatistics(const std::vector<Eigen::VectorXd>& samples, int dimension) {
  const auto T = static_cast<int>(samples.size());
  SampleStatistics out{Eigen::VectorXd::Zero(dimension), Eigen::VectorXd::Zero(dimension)};
  if (T == 0) return out;
  for (const Eigen::VectorXd& s : samples) out.mean += s;
  out.mean /= T;
  if (T < 2) return out;
  Eigen::VectorXd sum2 = Eigen::VectorXd::Zero(dimension);
  for (const Eigen::VectorXd& s : samples) sum2 += (s - out.mean).array().square().matrix();
  out.deviation = (sum2 / (T - 1)).cwiseSqrt();
  return out;
}

Confirmation confirmPlan(const Plan& plan, const ConfirmationOptions& options) {
  std::string error;
  if (!options.isValid(&error)) throw std::invalid_argument("confirmation options: " + error);
  const Evaluation prediction = evaluatePlan(plan);
  if (!prediction.identifiable()) {
    throw InputError(plan.source, "/placements",
                     "the plan does not identify every calibrated parameter (see artcal check): "
                     "there is no prediction to confirm");
  }
  const Eigen::VectorXd predicted_u = prediction.covariance->u;
  SimulationOptions simulation;
  simulation.noise_scale = options.noise_scale;
  const Simulator simulator(plan, simulation);
  CalibrationOptions calibration = options.calibration;
  calibration.details = false;

  std::vector<TrialResult> results(static_cast<std::size_t>(options.trials));
  // One calibrator per worker (its buffers are reused from trial to trial).
  const int threads = threadCount(options.threads, options.trials);
  std::vector<std::optional<Calibrator>> calibrators(static_cast<std::size_t>(threads));
  std::atomic<int> done{0};
  std::mutex progress_mutex;
  parallelFor(options.trials, threads, [&](int i, int worker) {
    std::optional<Calibrator>& calibrator = calibrators[static_cast<std::size_t>(worker)];
    if (!calibrator) calibrator.emplace(plan, calibration);
    results[static_cast<std::size_t>(i)] =
        runTrial(plan, simulator, *calibrator, predicted_u, options, i);
    const int finished = ++done;
    if (options.progress) {
      const std::lock_guard lock(progress_mutex);
      options.progress(finished, options.trials);
    }
  });

  // Statistics in trial order (identical for any thread count).
  const int n = plan.machine.calibratedCount();
  Confirmation out;
  out.trials = options.trials;
  std::vector<Eigen::VectorXd> errors;
  double chi2 = 0.0;
  for (const TrialResult& r : results) {
    if (!r.converged || !r.error.allFinite()) continue;
    ++out.converged_trials;
    errors.push_back(r.error);
    chi2 += r.chi2_per_dof;
  }
  const int m = out.converged_trials;
  const SampleStatistics statistics = sampleStatistics(errors, n);
  out.mean_chi2_per_dof = m > 0 ? chi2 / m : 0.0;
  out.band = confirmationBand(std::max(m, 2), n, options.level, options.allowance);
  out.confirmed = m == options.trials;
  for (int k = 0; k < n; ++k) {
    ConfirmedParameter parameter;
    parameter.name = plan.machine.calibratedInfo(k).name;
    parameter.predicted_u = predicted_u[k];
    parameter.empirical_u = statistics.deviation[k];
    parameter.bias = statistics.mean[k];
    parameter.ratio = parameter.empirical_u / parameter.predicted_u;
    parameter.inside = parameter.ratio >= out.band.low && parameter.ratio <= out.band.high;
    out.confirmed = out.confirmed && parameter.inside;
    out.parameters.push_back(parameter);
  }
  return out;
}

}  // namespace artcal
