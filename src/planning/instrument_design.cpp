#include "artcal/planning/instrument_design.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <mutex>
#include <numeric>

#include "artcal/core/error.hpp"
#include "artcal/core/parallel.hpp"
#include "artcal/core/random.hpp"
#include "artcal/estimation/design_matrix.hpp"
#include "artcal/estimation/normal_matrix.hpp"
#include "artcal/estimation/tip.hpp"
#include "artcal/planning/design_space.hpp"

namespace artcal {

namespace {

constexpr double kNoDesign = std::numeric_limits<double>::infinity();
// Exchange: candidates tried per reading and pass (all of them when the pool is smaller), and
// the candidates refuted by the full criterion before a reading is left as it is.
constexpr int kSlotCandidates = 256;
constexpr int kStationConfirmations = 24;
// Random streams (core/random.hpp seededGenerator): starts, and each start's slot subsets.
constexpr std::uint64_t kStartStream = 21;

using SearchClock = std::chrono::steady_clock;

const Artifact& designInstrument(const Plan& spec) {
  return spec.artifacts[static_cast<std::size_t>(spec.design->artifact)];
}

/// One start's design: the candidate indices of each station's readings, and each station's
/// information over (p, r) (the sum of its readings' terms).
struct StationDesign {
  std::vector<std::vector<int>> readings;
  std::vector<Eigen::MatrixXd> augmented;
};

class InstrumentSearch {
 public:
  InstrumentSearch(const Plan& spec, const OptimizerOptions& options,
                   const std::vector<std::vector<Placement>>& seed_designs)
      : spec_(spec),
        options_(options),
        start_time_(SearchClock::now()),
        candidates_(instrumentCandidates(spec)),
        n_p_(spec.machine.calibratedCount()),
        n_r_(designInstrument(spec).fullRigidDof()) {
    pool_ = static_cast<int>(candidates_.size());
    // The seed designs' configurations join the pool, so that their starts can keep them.
    for (const std::vector<Placement>& seed : seed_designs) {
      std::vector<std::vector<int>> stations;
      for (const Placement& station : seed) {
        std::vector<int> kept;
        for (const Measurement& m : station.measurements) {
          kept.push_back(static_cast<int>(candidates_.size()));
          candidates_.push_back(m.joints);
        }
        stations.push_back(std::move(kept));
      }
      seeds_.push_back(std::move(stations));
    }
    threads_ = threadCount(options.threads, std::numeric_limits<int>::max());
    for (int t = 0; t < threads_; ++t) criteria_.emplace_back(spec, options.criterion);
    buildRows();
  }

  OptimizerSummary run();

 private:
  double remaining() const {
    return options_.time_limit -
           std::chrono::duration<double>(SearchClock::now() - start_time_).count();
  }
  void buildRows();
  Eigen::MatrixXd readingTerm(int candidate) const;
  Eigen::MatrixXd reduced(const Eigen::MatrixXd& augmented) const;
  Eigen::MatrixXd total(const StationDesign& design) const;
  StationDesign initialDesign(int start, std::mt19937_64& rng, DesignCriterion& criterion);
  void complete(StationDesign& design, DesignCriterion& criterion);
  double exchange(StationDesign& design, double value, std::mt19937_64& rng,
                  DesignCriterion& criterion);
  std::vector<int> slotSubset(std::mt19937_64& rng) const;
  std::vector<Placement> placementsOf(const StationDesign& design) const;

  const Plan& spec_;
  const OptimizerOptions& options_;
  SearchClock::time_point start_time_;
  std::vector<Eigen::VectorXd> candidates_;
  int pool_ = 0;  ///< the spec's candidates (the seed designs' configurations follow them)
  std::vector<std::vector<std::vector<int>>> seeds_;  ///< per seeded start: station readings
  int n_p_, n_r_;
  int threads_ = 1;
  std::deque<DesignCriterion> criteria_;
  Eigen::MatrixXd rows_;   ///< rowsPerReading() rows per candidate: whitened [A_p | A_r]
  Eigen::MatrixXd fixed_;  ///< the spec's own placements, over g
  std::atomic<bool> timed_out_{false};
};

void InstrumentSearch::buildRows() {
  const Machine& machine = spec_.machine;
  const Artifact& instrument = designInstrument(spec_);
  std::vector<Measurement> readings(candidates_.size());
  for (std::size_t c = 0; c < candidates_.size(); ++c) {
    readings[c].joints = candidates_[c];
    setNominalReading(machine, instrument, readings[c]);  // a pose's orientation rows need it
  }
  DesignMatrixBuilder builder(machine, spec_.noise);
  ObservationBlock block;
  builder.build(instrument, readings, machine.nominal,
                RigidTransform::identity(instrument.dimension), Eigen::VectorXd(), false, block);
  rows_.resize(block.rows(), n_p_ + n_r_);
  rows_.leftCols(n_p_) = block.A_p;
  rows_.rightCols(n_r_) = block.A_r;
  DesignCriterion& criterion = criteria_.front();
  fixed_ = Eigen::MatrixXd::Zero(criterion.globalSize(), criterion.globalSize());
  for (const Placement& p : spec_.placements) fixed_ += criterion.contribution(p);
}

Eigen::MatrixXd InstrumentSearch::readingTerm(int candidate) const {
  const int k = designInstrument(spec_).rowsPerReading();
  const auto a = rows_.middleRows(k * candidate, k);
  return a.transpose() * a;
}

// The station's information of g: its r eliminated (the rank policy's pseudo-inverse).
Eigen::MatrixXd InstrumentSearch::reduced(const Eigen::MatrixXd& augmented) const {
  const int n_g = criteria_.front().globalSize();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n_g, n_g);
  const Eigen::MatrixXd pinv =
      symmetricPseudoInverse(augmented.bottomRightCorner(n_r_, n_r_), kRigidObservedTolerance);
  out.topLeftCorner(n_p_, n_p_) =
      augmented.topLeftCorner(n_p_, n_p_) -
      augmented.topRightCorner(n_p_, n_r_) * pinv * augmented.bottomLeftCorner(n_r_, n_p_);
  return out;
}

Eigen::MatrixXd InstrumentSearch::total(const StationDesign& design) const {
  Eigen::MatrixXd sum = fixed_;
  for (const Eigen::MatrixXd& augmented : design.augmented) sum += reduced(augmented);
  return sum;
}

std::vector<int> InstrumentSearch::slotSubset(std::mt19937_64& rng) const {
  const int pool = static_cast<int>(candidates_.size());
  std::vector<int> subset;
  if (pool <= kSlotCandidates) {
    subset.resize(static_cast<std::size_t>(pool));
    std::iota(subset.begin(), subset.end(), 0);
    return subset;
  }
  for (int i = 0; i < kSlotCandidates; ++i) subset.push_back(static_cast<int>(rng() % pool));
  return subset;
}

// Each station completed to `readings` readings, one at a time, by the candidate whose addition
// gives the smallest criterion: ranked by the active-set bound over the whole pool, the best
// confirmed by the full criterion (a bound never above it: a confirmed equal is the best).
void InstrumentSearch::complete(StationDesign& design, DesignCriterion& criterion) {
  const int readings = spec_.design->instrument->readings;
  const int pool = static_cast<int>(candidates_.size());
  criterion.activate(total(design));  // the seed design's worst configurations start the set
  for (std::size_t s = 0; s < design.readings.size(); ++s) {
    std::vector<int>& chosen = design.readings[s];
    while (static_cast<int>(chosen.size()) < readings) {
      const Eigen::MatrixXd others = total(design) - reduced(design.augmented[s]);
      int taken = -1;
      double taken_value = kNoDesign;
      for (int attempt = 0; attempt < kStationConfirmations; ++attempt) {
        int best = -1;
        double bound = kNoDesign;
        for (int c = 0; c < pool; ++c) {
          if (std::find(chosen.begin(), chosen.end(), c) != chosen.end()) continue;
          const double v =
              criterion.activeValue(others + reduced(design.augmented[s] + readingTerm(c)));
          if (best < 0 || v < bound) {
            best = c;
            bound = v;
          }
        }
        const double confirmed =
            criterion.activate(others + reduced(design.augmented[s] + readingTerm(best)));
        if (taken < 0 || confirmed < taken_value) {
          taken = best;
          taken_value = confirmed;
        }
        if (!(confirmed > bound * (1.0 + 1e-9))) break;
      }
      chosen.push_back(taken);
      design.augmented[s] += readingTerm(taken);
    }
  }
}

StationDesign InstrumentSearch::initialDesign(int start, std::mt19937_64& rng,
                                              DesignCriterion& criterion) {
  const DesignSpec& design_spec = *spec_.design;
  const int stations = design_spec.placements;
  const int readings = design_spec.instrument->readings;
  const int width = n_p_ + n_r_;
  StationDesign design;
  design.readings.resize(static_cast<std::size_t>(stations));
  design.augmented.assign(static_cast<std::size_t>(stations), Eigen::MatrixXd::Zero(width, width));
  if (start < static_cast<int>(seeds_.size())) {
    const auto& seed = seeds_[static_cast<std::size_t>(start)];
    for (std::size_t s = 0; s < design.readings.size() && s < seed.size(); ++s) {
      for (int c : seed[s]) {
        if (static_cast<int>(design.readings[s].size()) == readings) break;
        design.readings[s].push_back(c);
        design.augmented[s] += readingTerm(c);
      }
    }
    complete(design, criterion);
    return design;
  }
  // Distinct candidates per station when the pool has them (a partial Fisher-Yates shuffle).
  const int pool = static_cast<int>(candidates_.size());
  for (int s = 0; s < stations; ++s) {
    std::vector<int> order(static_cast<std::size_t>(pool));
    std::iota(order.begin(), order.end(), 0);
    for (int i = 0; i < readings; ++i) {
      const int left = pool - std::min(i, pool - 1);
      const int pick = static_cast<int>(rng() % static_cast<std::uint64_t>(left));
      design.readings[static_cast<std::size_t>(s)].push_back(order[static_cast<std::size_t>(pick)]);
      design.augmented[static_cast<std::size_t>(s)] +=
          readingTerm(order[static_cast<std::size_t>(pick)]);
      std::swap(order[static_cast<std::size_t>(pick)], order[static_cast<std::size_t>(left - 1)]);
    }
  }
  return design;
}

double InstrumentSearch::exchange(StationDesign& design, double value, std::mt19937_64& rng,
                                  DesignCriterion& criterion) {
  for (int pass = 0; pass < options_.exchange_passes; ++pass) {
    bool improved = false;
    for (std::size_t s = 0; s < design.readings.size(); ++s) {
      std::vector<int>& chosen = design.readings[s];
      for (std::size_t slot = 0; slot < chosen.size(); ++slot) {
        if (remaining() <= 0.0) {
          timed_out_ = true;
          return value;
        }
        const Eigen::MatrixXd others = total(design) - reduced(design.augmented[s]);
        const Eigen::MatrixXd without = design.augmented[s] - readingTerm(chosen[slot]);
        const std::vector<int> subset = slotSubset(rng);
        // Ranked by the active-set bound, the best confirmed by the full criterion; a refuted
        // one has grown the active set, so the ranking is redone (optimizer.cpp, exchange).
        for (int attempt = 0; attempt < kStationConfirmations; ++attempt) {
          int best = -1;
          double best_bound = value * (1.0 - 1e-9);
          for (int c : subset) {
            if (std::find(chosen.begin(), chosen.end(), c) != chosen.end()) continue;
            const double v = criterion.activeValue(others + reduced(without + readingTerm(c)));
            if (v < best_bound || (!std::isfinite(value) && best < 0 && std::isfinite(v))) {
              best_bound = v;
              best = c;
            }
          }
          if (best < 0) break;
          const Eigen::MatrixXd augmented = without + readingTerm(best);
          const double confirmed = criterion.activate(others + reduced(augmented));
          if (confirmed < value * (1.0 - 1e-9) ||
              (!std::isfinite(value) && std::isfinite(confirmed))) {
            chosen[slot] = best;
            design.augmented[s] = augmented;
            value = confirmed;
            improved = true;
            break;
          }
        }
      }
    }
    if (!improved) break;
  }
  return value;
}

std::vector<Placement> InstrumentSearch::placementsOf(const StationDesign& design) const {
  const Machine& machine = spec_.machine;
  std::vector<Placement> out;
  int stations_before = 0;
  for (const Placement& p : spec_.placements)
    if (p.artifact == spec_.design->artifact) ++stations_before;
  for (std::size_t s = 0; s < design.readings.size(); ++s) {
    Placement station;
    station.artifact = spec_.design->artifact;
    station.name = "station " + std::to_string(stations_before + static_cast<int>(s) + 1);
    for (int c : design.readings[s]) {
      Measurement m;
      m.joints = candidates_[static_cast<std::size_t>(c)];
      // The nominal tip, the station at the machine frame: planning only.
      setNominalReading(machine, designInstrument(spec_), m);
      m.point_given = false;
      station.measurements.push_back(std::move(m));
    }
    out.push_back(std::move(station));
  }
  return out;
}

OptimizerSummary InstrumentSearch::run() {
  checkDesignCount(spec_);
  const int starts = std::max(options_.starts, static_cast<int>(seeds_.size()));
  std::vector<StartResult> results(static_cast<std::size_t>(starts));
  std::vector<StationDesign> designs(static_cast<std::size_t>(starts));
  // Progress as the generic optimizer reports it (issue 32: an instrument design printed none and
  // Python's progress= was never called).
  std::mutex progress_mutex;
  int starts_done = 0;
  double best = std::numeric_limits<double>::infinity();
  parallelFor(starts, threads_, [&](int start, int worker) {
    if (start > 0 && remaining() <= 0.0) {  // start 0 always runs: there is a result
      timed_out_ = true;
      return;
    }
    DesignCriterion& criterion = criteria_[static_cast<std::size_t>(worker)];
    std::mt19937_64 rng =
        seededGenerator(options_.seed, kStartStream, static_cast<std::uint64_t>(start));
    criterion.resetActive();
    StationDesign design = initialDesign(start, rng, criterion);
    StartResult& result = results[static_cast<std::size_t>(start)];
    result.initial = criterion.activate(total(design));
    result.exchanged = exchange(design, result.initial, rng, criterion);
    result.refined = result.exchanged;  // no continuous refinement: the candidates are discrete
    result.done = true;
    designs[static_cast<std::size_t>(start)] = std::move(design);
    if (options_.progress) {
      const std::lock_guard lock(progress_mutex);
      best = std::min(best, result.refined);
      options_.progress({++starts_done, starts, best,
                         std::chrono::duration<double>(SearchClock::now() - start_time_).count()});
    }
  });
  OptimizerSummary summary = OptimizerSummary::ofStarts(
      options_.criterion, results, pool_, timed_out_,
      std::chrono::duration<double>(SearchClock::now() - start_time_).count());
  if (summary.best_start < 0) return summary;
  summary.placements = placementsOf(designs[static_cast<std::size_t>(summary.best_start)]);
  summary.message = summary.briefReport();
  return summary;
}

}  // namespace

std::vector<Eigen::VectorXd> instrumentCandidates(const Plan& spec) {
  const DesignSpec& design = *spec.design;
  const InstrumentDesignSpec& instrument = *design.instrument;
  WorkspaceSpec sampling;
  sampling.kind =
      instrument.task_space ? WorkspaceSpec::Kind::TaskSpace : WorkspaceSpec::Kind::Samples;
  sampling.samples = instrument.candidates;
  sampling.seed = instrument.candidate_seed;
  sampling.region = design.region;
  std::vector<Eigen::VectorXd> candidates =
      workspaceConfigurations(withJointMargin(spec.machine, design.joint_margin), sampling);
  if (static_cast<int>(candidates.size()) < instrument.readings) {
    throw InputError(spec.source, instrument.task_space ? "/design/region" : "/design/candidates",
                     "only " + std::to_string(candidates.size()) + " of " +
                         std::to_string(instrument.candidates) +
                         " candidate configurations reach their point within the joint limits, "
                         "fewer than the " +
                         std::to_string(instrument.readings) +
                         " readings of a station: widen the region or draw more candidates");
  }
  return candidates;
}

OptimizerSummary optimizeInstrumentDesign(const Plan& spec, const OptimizerOptions& options,
                                          const std::vector<Placement>* start_design) {
  if (!spec.design || !spec.design->instrument)
    throw std::logic_error("optimizeInstrumentDesign: the spec has no instrument design");
  // Seeded starts first: the sweep's design for one reading fewer, then (criterion G) the
  // D-optimal design of the same pool, so that the G choice is never worse in G than it.
  const auto started = std::chrono::steady_clock::now();
  std::vector<std::vector<Placement>> seeds;
  if (start_design) seeds.push_back(*start_design);
  if (options.criterion == Criterion::WorstTip) {
    OptimizerOptions d_options = options;
    d_options.criterion = Criterion::D;
    d_options.progress = nullptr;  // D's values are not the criterion's: the G search reports
    const OptimizerSummary d_choice = InstrumentSearch(spec, d_options, {}).run();
    if (d_choice.best_start >= 0) seeds.push_back(d_choice.placements);
  }
  InstrumentSearch search(spec, options, seeds);
  OptimizerSummary summary = search.run();
  // The run's time is the whole run's, the D-optimal seeding included (it printed 5.86 s of 21).
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (summary.best_start >= 0) summary.message = summary.briefReport();
  return summary;
}

void appendDesignedPlacements(Plan& plan, const std::vector<Placement>& designed) {
  for (Placement placement : designed) {
    Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    if (artifact.kind().readings_are_features) {
      for (Measurement& m : placement.measurements) {
        if (m.point.size() == 0) setNominalReading(plan.machine, artifact, m);
        m.feature = artifact.appendFeature(m.point);
      }
    }
    plan.placements.push_back(std::move(placement));
  }
}

}  // namespace artcal
