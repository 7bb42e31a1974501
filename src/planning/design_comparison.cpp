#include "artcal/planning/design_comparison.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <optional>
#include <sstream>

#include "artcal/calibration/calibrate_readings.hpp"
#include "artcal/calibration/station_verification.hpp"
#include "artcal/core/error.hpp"

namespace artcal {

namespace {

using ComparisonClock = std::chrono::steady_clock;

/// Each held-out station scored in the station the calibration estimated for the recorded
/// placement of the same artifact (the first such): the instrument did not move (verify
/// --frame-of).
std::vector<std::optional<CalibrationFrame>> calibrationFrames(const Plan& calibrated,
                                                               const Calibration& calibration,
                                                               const Plan& held_out) {
  std::vector<std::optional<CalibrationFrame>> frames;
  for (const Placement& held : held_out.placements) {
    std::optional<CalibrationFrame> frame;
    const std::string& id = held_out.artifacts[static_cast<std::size_t>(held.artifact)].id;
    for (std::size_t j = 0; j < calibrated.placements.size() && !frame; ++j) {
      const Placement& placement = calibrated.placements[j];
      if (calibrated.artifacts[static_cast<std::size_t>(placement.artifact)].id == id)
        frame = CalibrationFrame{placementLabel(calibrated.placements, j), calibration.poses[j]};
    }
    frames.push_back(frame);
  }
  return frames;
}

/// Calibrates `subset` of the pool alone and scores it on the held-out readings.
SubsetScore scoreSubset(const ReadingPool& pool, const Plan& held_out, std::vector<int> subset,
                        ReadingPool::CalibratedSet set) {
  SubsetScore score;
  score.readings = std::move(subset);
  score.criterion = pool.value(score.readings, Criterion::WorstTip);
  try {
    const Plan plan = pool.subsetPlan(score.readings, set);
    const CalibrationRun run = calibrateReadings(plan);
    const StationsVerification verified =
        verifyStations(held_out, run.calibration.parameters, std::nullopt,
                       calibrationFrames(plan, run.calibration, held_out));
    if (!verified.in_frame_all) {
      score.failure = "no held-out station was scored in the calibration's station";
      return score;
    }
    score.calibrated = true;
    score.held_out_mean = verified.in_frame_all->mean;
    score.held_out_rms = verified.in_frame_all->rms;
  } catch (const std::exception& e) {
    score.failure = e.what();
  }
  return score;
}

void summarizeMethod(MethodScore& method) {
  std::vector<double> means;
  for (const SubsetScore& s : method.subsets) {
    if (s.calibrated) {
      means.push_back(s.held_out_mean);
    } else {
      ++method.failed;
    }
  }
  if (means.empty()) {
    method.median = method.min = method.max = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  std::sort(means.begin(), means.end());
  const std::size_t n = means.size();
  method.median = n % 2 == 1 ? means[n / 2] : 0.5 * (means[n / 2 - 1] + means[n / 2]);
  method.min = means.front();
  method.max = means.back();
}

void reportMethod(const ComparisonOptions& options, int size, const MethodScore& method) {
  if (!options.progress) return;
  std::ostringstream line;
  line << "compare-designs: N = " << size << ", " << method.method << ": held-out mean "
       << method.median << " mm";
  if (method.failed > 0) line << " (" << method.failed << " calibration(s) failed)";
  options.progress(line.str());
}

SizeComparison compareSize(const ReadingPool& pool, const Plan& held_out, int size,
                           const ComparisonOptions& options) {
  SizeComparison out;
  out.size = size;
  for (Criterion criterion : options.criteria) {
    MethodScore method;
    method.method = criterionName(criterion);
    PoolOptions pool_options = options.pool;
    pool_options.criterion = criterion;
    const auto started = ComparisonClock::now();
    const PoolChoice choice = chooseReadings(pool, size, pool_options);
    method.seconds = std::chrono::duration<double>(ComparisonClock::now() - started).count();
    method.subsets.push_back(scoreSubset(pool, held_out, choice.chosen, options.calibrated_set));
    summarizeMethod(method);
    reportMethod(options, size, method);
    out.methods.push_back(std::move(method));
  }
  MethodScore farthest;
  farthest.method = "farthest";
  farthest.subsets.push_back(
      scoreSubset(pool, held_out, farthestReadings(pool, size), options.calibrated_set));
  summarizeMethod(farthest);
  reportMethod(options, size, farthest);
  out.methods.push_back(std::move(farthest));
  MethodScore random;
  random.method = "random";
  for (int draw = 0; draw < options.draws; ++draw)
    random.subsets.push_back(scoreSubset(
        pool, held_out, randomReadings(pool, size, options.seed, draw), options.calibrated_set));
  summarizeMethod(random);
  reportMethod(options, size, random);
  out.methods.push_back(std::move(random));
  return out;
}

}  // namespace

DesignComparison compareDesigns(const Plan& recorded, const Plan& held_out,
                                const ComparisonOptions& options) {
  const ReadingPool pool(recorded, options.prior_tolerance, options.workspace);
  bool stations = false;
  for (const Placement& p : held_out.placements)
    stations =
        stations ||
        held_out.artifacts[static_cast<std::size_t>(p.artifact)].kind().readings_are_features;
  if (!stations) {
    throw InputError(held_out.source, "/placements",
                     "compare-designs scores held-out instrument readings (a tracker's, a total "
                     "station's): this plan has no instrument station");
  }
  for (int size : options.sizes) {
    if (size < 1 || size >= pool.size()) {
      throw InputError(recorded.source, "/placements",
                       "cannot compare subsets of " + std::to_string(size) + " of the " +
                           std::to_string(pool.size()) + " recorded readings: sizes from 1 to " +
                           std::to_string(pool.size() - 1));
    }
  }
  DesignComparison out;
  out.pool = pool.size();
  for (const Placement& p : held_out.placements)
    out.held_out += static_cast<int>(p.measurements.size());
  std::vector<int> every(static_cast<std::size_t>(pool.size()));
  for (int i = 0; i < pool.size(); ++i) every[static_cast<std::size_t>(i)] = i;
  out.all = scoreSubset(pool, held_out, every, options.calibrated_set);
  for (int size : options.sizes) out.sizes.push_back(compareSize(pool, held_out, size, options));
  return out;
}

}  // namespace artcal
