#include "artcal/planning/reading_pool.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "artcal/core/error.hpp"
#include "artcal/core/parallel.hpp"
#include "artcal/core/random.hpp"
#include "artcal/estimation/design_matrix.hpp"
#include "artcal/estimation/identifiability.hpp"
#include "artcal/estimation/normal_matrix.hpp"
#include "artcal/estimation/tip.hpp"

namespace artcal {

namespace {

constexpr double kNoPoolValue = std::numeric_limits<double>::infinity();
// The ridge on the rigid motions, relative to their information in the pool: it only keeps
// M(S) invertible for a placement none of whose readings is chosen (its r is then decoupled).
constexpr double kPoolRigidRidge = 1e-12;
// G: configurations joining the active set at once, and refuted candidates before a slot is left.
constexpr int kPoolJoinAtOnce = 4;
constexpr int kPoolSlotConfirmations = 24;
// Random streams (core/random.hpp seededGenerator).
constexpr std::uint64_t kPoolStartStream = 45;
constexpr std::uint64_t kPoolSlotStream = 46;
constexpr std::uint64_t kPoolRandomStream = 47;

using PoolClock = std::chrono::steady_clock;

bool isPoolCriterion(Criterion c) {
  return c == Criterion::WorstTip || c == Criterion::MeanTip || c == Criterion::D ||
         c == Criterion::A;
}

Eigen::MatrixXd poolInverse(const Eigen::MatrixXd& M) {
  return M.llt().solve(Eigen::MatrixXd::Identity(M.rows(), M.cols()));
}

/// The first `count` entries of a random permutation of 0..n-1 (partial Fisher-Yates).
std::vector<int> drawDistinctReadings(int n, int count, std::mt19937_64& rng) {
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  for (int i = 0; i < count; ++i) {
    const auto left = static_cast<std::uint64_t>(n - i);
    const auto pick = static_cast<std::size_t>(i) + static_cast<std::size_t>(rng() % left);
    std::swap(order[static_cast<std::size_t>(i)], order[pick]);
  }
  order.resize(static_cast<std::size_t>(count));
  return order;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The pool

ReadingPool::ReadingPool(const Plan& plan, double prior_tolerance, PoolWorkspace workspace)
    : criterion_plan_(plan),
      plan_prior_(plan.machine.prior_sigma),
      n_p_(plan.machine.calibratedCount()) {
  if (!(prior_tolerance > 0.0))
    throw InputError(plan.source, "/machine/prior", "the prior tolerance must be positive");
  buildWorkspace(workspace);
  // The tolerance as the machine prior of every parameter that has none (angles at the reach).
  Machine& machine = criterion_plan_.machine;
  if (machine.prior_sigma.size() == 0)
    machine.prior_sigma = Eigen::VectorXd::Zero(machine.nominal.size());
  for (int k = 0; k < n_p_; ++k) {
    double& sigma = machine.prior_sigma[machine.calibrated[static_cast<std::size_t>(k)]];
    if (!(sigma > 0.0)) sigma = prior_tolerance / scale_[k];
  }
  buildRows(plan);
}

void ReadingPool::buildWorkspace(PoolWorkspace workspace) {
  const Machine& machine = criterion_plan_.machine;
  std::vector<Eigen::VectorXd> configurations;
  if (workspace == PoolWorkspace::Pool) {
    for (const Placement& placement : criterion_plan_.placements)
      for (const Measurement& m : placement.measurements) configurations.push_back(m.joints);
  } else {
    configurations = workspaceConfigurations(machine, criterion_plan_.workspace);
  }
  dimension_ = machine.dimension();
  J_.resize(dimension_ * static_cast<int>(configurations.size()), n_p_);
  Eigen::VectorXd x;
  Eigen::MatrixXd J_x_p;
  double reach = 0.0;
  for (std::size_t g = 0; g < configurations.size(); ++g) {
    forwardOrThrow(*machine.mechanism, machine.nominal, configurations[g], x, &J_x_p);
    reach = std::max(reach, x.norm());
    for (int k = 0; k < n_p_; ++k) {
      J_.block(dimension_ * static_cast<int>(g), k, dimension_, 1) =
          J_x_p.col(machine.calibrated[static_cast<std::size_t>(k)]);
    }
  }
  const TipEvaluator tip(machine, criterion_plan_.noise, std::move(configurations), 0,
                         TipUse::Once);
  S_q2_ = tip.encoderVariance();
  const auto count = static_cast<double>(S_q2_.size());
  J_mean_ = (J_.transpose() * J_) / count;
  scale_.resize(n_p_);
  for (int k = 0; k < n_p_; ++k)
    scale_[k] = machine.calibratedInfo(k).quantity.isAngle() && reach > 0.0 ? reach : 1.0;
}

void ReadingPool::buildRows(const Plan& plan) {
  const GlobalLayout layout = GlobalLayout::of(criterion_plan_);
  const int n_g = layout.size();
  std::vector<int> rigid_offset;
  int unknowns = n_g;
  for (const Placement& placement : plan.placements) {
    rigid_offset.push_back(unknowns);
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    unknowns += artifact.fullRigidDof();
    k_ = std::max(k_, artifact.rowsPerReading());
    for (int m = 0; m < static_cast<int>(placement.measurements.size()); ++m)
      readings_.push_back({static_cast<int>(rigid_offset.size()) - 1, m});
  }
  rows_ = Eigen::MatrixXd::Zero(k_ * size(), unknowns);
  const std::vector<RigidTransform> poses =
      fitPlacements(plan, plan.placements, plan.machine.nominal);
  DesignMatrixBuilder builder(plan.machine, plan.noise);
  ObservationBlock block;
  int candidate = 0;
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const Placement& placement = plan.placements[j];
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    builder.build(artifact, placement.measurements, plan.machine.nominal, poses[j],
                  Eigen::VectorXd(), false, block);
    const int k = artifact.rowsPerReading();
    if (block.rows() != k * static_cast<int>(placement.measurements.size())) {
      throw InputError(plan.source, "/placements/" + std::to_string(j),
                       "its readings do not give " + std::to_string(k) +
                           " rows each (plane touches): such a placement cannot be a pool");
    }
    const int c_offset = layout.artifact_offset[static_cast<std::size_t>(placement.artifact)];
    for (std::size_t m = 0; m < placement.measurements.size(); ++m, ++candidate) {
      auto out = rows_.middleRows(k_ * candidate, k);
      const int row = k * static_cast<int>(m);
      out.leftCols(n_p_) = block.A_p.middleRows(row, k);
      // An artifact without systematic errors has no A_c columns (and no data to offset).
      if (block.A_c.cols() > 0)
        out.middleCols(c_offset, block.A_c.cols()) = block.A_c.middleRows(row, k);
      out.middleCols(rigid_offset[j], block.A_r.cols()) = block.A_r.middleRows(row, k);
    }
  }
  prior_ = Eigen::VectorXd::Zero(unknowns);
  prior_.head(n_p_) = layout.p_prior_weight;
  prior_.segment(n_p_, layout.systematicCount()) = layout.c_sigma.array().square().inverse();
  // Each rigid column's ridge relative to its own information in the pool (a translation's is a
  // millionth of a rotation's at a metre): a common one would bias the translations.
  const int n_r = unknowns - n_g;
  const Eigen::ArrayXd information = rows_.rightCols(n_r).colwise().squaredNorm().transpose();
  const double largest = n_r > 0 ? information.maxCoeff() : 0.0;
  prior_.tail(n_r) = kPoolRigidRidge * information.max(kPoolRigidRidge * largest).max(1e-300);
}

Eigen::Ref<const Eigen::MatrixXd> ReadingPool::rows(int candidate) const {
  return rows_.middleRows(k_ * candidate, k_);
}

Eigen::MatrixXd ReadingPool::information(const std::vector<int>& subset) const {
  Eigen::MatrixXd M = prior_.asDiagonal();
  for (int i : subset) M.noalias() += rows(i).transpose() * rows(i);
  return M;
}

Eigen::MatrixXd ReadingPool::covariance(const std::vector<int>& subset) const {
  return poolInverse(information(subset)).topLeftCorner(n_p_, n_p_);
}

Eigen::VectorXd ReadingPool::tipVariance(const Eigen::MatrixXd& V_p) const {
  const Eigen::MatrixXd L = V_p.llt().matrixL();
  const Eigen::MatrixXd JL = J_ * L;
  Eigen::VectorXd S2 = S_q2_;
  for (int g = 0; g < S2.size(); ++g)
    S2[g] += JL.middleRows(dimension_ * g, dimension_).squaredNorm();
  return S2;
}

double ReadingPool::valueOfCovariance(const Eigen::MatrixXd& V_p, Criterion criterion) const {
  const double n = static_cast<double>(n_p_);
  switch (criterion) {
    case Criterion::WorstTip:
      return std::sqrt(tipVariance(V_p).maxCoeff());
    case Criterion::MeanTip:
      return std::sqrt(tipVariance(V_p).mean());
    case Criterion::A:
      return std::sqrt((scale_.array().square() * V_p.diagonal().array()).sum() / n);
    case Criterion::D: {
      const Eigen::MatrixXd Vs = scale_.asDiagonal() * V_p * scale_.asDiagonal();
      const Eigen::LLT<Eigen::MatrixXd> llt(Vs);
      return std::exp(llt.matrixLLT().diagonal().array().log().sum() / n);
    }
    default:
      throw std::logic_error("ReadingPool: criterion " + criterionName(criterion) +
                             " is not one a pool is chosen by");
  }
}

double ReadingPool::value(const std::vector<int>& subset, Criterion criterion) const {
  return valueOfCovariance(covariance(subset), criterion);
}

Plan ReadingPool::subsetPlan(const std::vector<int>& subset, CalibratedSet set) const {
  Plan out = criterion_plan_;
  out.machine.prior_sigma = plan_prior_;
  std::vector<std::vector<bool>> keep(out.placements.size());
  for (std::size_t j = 0; j < keep.size(); ++j)
    keep[j].assign(out.placements[j].measurements.size(), false);
  for (int i : subset) {
    const PoolReading& r = readings_[static_cast<std::size_t>(i)];
    keep[static_cast<std::size_t>(r.placement)][static_cast<std::size_t>(r.measurement)] = true;
  }
  std::vector<Placement> placements;
  for (std::size_t j = 0; j < keep.size(); ++j) {
    Placement placement = out.placements[j];
    placement.measurements.clear();
    for (std::size_t m = 0; m < keep[j].size(); ++m)
      if (keep[j][m]) placement.measurements.push_back(out.placements[j].measurements[m]);
    if (!placement.measurements.empty()) placements.push_back(std::move(placement));
  }
  out.placements = std::move(placements);
  // "calibrate": "identifiable" decided on the subset's own readings, as loading them would.
  if (set == CalibratedSet::Subset && out.calibrate_resolution) {
    out.machine.calibrated = out.calibrate_resolution->listed;
    out.calibrate_resolution.reset();
    resolveCalibratedSet(out);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// The exchange

namespace {

/// A start's design and, for G, its active set: configurations where its designs were worst,
/// whose max is a lower bound of G (docs/optimize.md, "How it searches", point 5).
struct PoolDesign {
  std::vector<int> chosen;
  std::vector<char> in_design;
  double value = kNoPoolValue;
  std::vector<int> active;
  Eigen::MatrixXd J_active;  ///< the active configurations' J_p, stacked
};

/// The best candidate for one slot and its value (for G the active-set bound).
struct SlotCandidate {
  int candidate = -1;
  double value = kNoPoolValue;
  Eigen::MatrixXd V_p;  ///< V_p of the design with the swap made
};

}  // namespace

class PoolSearch {
 public:
  PoolSearch(const ReadingPool& pool, int count, const PoolOptions& options)
      : pool_(pool), count_(count), options_(options), started_(PoolClock::now()) {}

  /// Runs the starts; `seeded` (optional) is start 0's initial design.
  PoolChoice run(const std::vector<int>* seeded);

 private:
  double remaining() const {
    return options_.time_limit - std::chrono::duration<double>(PoolClock::now() - started_).count();
  }
  PoolDesign initialDesign(int start, const std::vector<int>* seeded) const;
  void activate(PoolDesign& design, const Eigen::VectorXd& S2) const;
  double fullValue(PoolDesign& design, const Eigen::MatrixXd& V_p) const;
  SlotCandidate bestSwap(const PoolDesign& design, int slot, std::mt19937_64& rng) const;
  bool improveSlot(PoolDesign& design, int slot, std::mt19937_64& rng) const;
  void exchange(PoolDesign& design, std::mt19937_64& rng);

  const ReadingPool& pool_;
  int count_;
  const PoolOptions& options_;
  PoolClock::time_point started_;
  std::atomic<bool> timed_out_{false};
};

PoolDesign PoolSearch::initialDesign(int start, const std::vector<int>* seeded) const {
  PoolDesign design;
  if (start == 0 && seeded) {
    design.chosen = *seeded;
  } else {
    std::mt19937_64 rng =
        seededGenerator(options_.seed, kPoolStartStream, static_cast<std::uint64_t>(start));
    design.chosen = drawDistinctReadings(pool_.size(), count_, rng);
  }
  design.in_design.assign(static_cast<std::size_t>(pool_.size()), 0);
  for (int i : design.chosen) design.in_design[static_cast<std::size_t>(i)] = 1;
  design.J_active.resize(0, pool_.parameterCount());
  design.value = fullValue(design, pool_.covariance(design.chosen));
  return design;
}

// The few worst configurations above the active set's worst join it.
void PoolSearch::activate(PoolDesign& design, const Eigen::VectorXd& S2) const {
  double active_worst = 0.0;
  for (int g : design.active) active_worst = std::max(active_worst, S2[g]);
  std::vector<int> above;
  for (int g = 0; g < S2.size(); ++g)
    if (S2[g] > active_worst * (1.0 + 1e-12)) above.push_back(g);
  const auto join = std::min<std::size_t>(above.size(), kPoolJoinAtOnce);
  std::partial_sort(above.begin(), above.begin() + static_cast<long>(join), above.end(),
                    [&](int a, int b) { return S2[a] > S2[b] || (S2[a] == S2[b] && a < b); });
  const int d = pool_.dimension();
  for (std::size_t i = 0; i < join; ++i) {
    design.active.push_back(above[i]);
    design.J_active.conservativeResize(design.J_active.rows() + d, Eigen::NoChange);
    design.J_active.bottomRows(d) = pool_.workspaceJacobians().middleRows(d * above[i], d);
  }
}

// The criterion over the whole workspace; for G it also grows the active set.
double PoolSearch::fullValue(PoolDesign& design, const Eigen::MatrixXd& V_p) const {
  if (options_.criterion != Criterion::WorstTip)
    return pool_.valueOfCovariance(V_p, options_.criterion);
  const Eigen::VectorXd S2 = pool_.tipVariance(V_p);
  activate(design, S2);
  return std::sqrt(S2.maxCoeff());
}

// Slot `slot` removed (M_- inverted once), each candidate added by a rank-k update; the
// criterion of each read from B_p and K (reading_pool.hpp).
SlotCandidate PoolSearch::bestSwap(const PoolDesign& design, int slot, std::mt19937_64& rng) const {
  std::vector<int> others = design.chosen;
  others.erase(others.begin() + slot);
  const Eigen::MatrixXd M_inv = poolInverse(pool_.information(others));
  const int n_p = pool_.parameterCount();
  const Eigen::MatrixXd V0 = M_inv.topLeftCorner(n_p, n_p);
  const Criterion criterion = options_.criterion;
  // Per-slot bases of the criteria.
  const Eigen::ArrayXd s2 = pool_.scale().array().square();
  Eigen::MatrixXd weight;  // A: S^2, I: Jbar, D: V0^-1
  double base = 0.0;
  Eigen::VectorXd active_base;
  if (criterion == Criterion::A) {
    weight = s2.matrix().asDiagonal();
    base = (s2 * V0.diagonal().array()).sum();
  } else if (criterion == Criterion::MeanTip) {
    weight = pool_.J_mean_;
    base = pool_.encoderVariance().mean() + (V0.cwiseProduct(weight)).sum();
  } else if (criterion == Criterion::D) {
    const Eigen::LLT<Eigen::MatrixXd> llt(V0);
    weight = llt.solve(Eigen::MatrixXd::Identity(n_p, n_p));
    base = 2.0 * llt.matrixLLT().diagonal().array().log().sum() +
           2.0 * pool_.scale().array().log().sum();
  } else {
    const int d = pool_.dimension();
    const Eigen::MatrixXd JV = design.J_active * V0;
    active_base.resize(static_cast<long>(design.active.size()));
    for (std::size_t a = 0; a < design.active.size(); ++a) {
      const int row = d * static_cast<int>(a);
      active_base[static_cast<long>(a)] =
          pool_.encoderVariance()[design.active[a]] +
          JV.middleRows(row, d).cwiseProduct(design.J_active.middleRows(row, d)).sum();
    }
  }
  const int k = pool_.rowsPerReading();
  const auto tries = [&](int c) {
    const Eigen::Ref<const Eigen::MatrixXd> a = pool_.rows(c);
    const Eigen::MatrixXd B = M_inv * a.transpose();
    const Eigen::MatrixXd K = (Eigen::MatrixXd::Identity(k, k) + a * B).inverse();
    const auto Bp = B.topRows(n_p);
    switch (criterion) {
      case Criterion::A:
        return std::sqrt((base - (K * Bp.transpose() * weight * Bp).trace()) / n_p);
      case Criterion::MeanTip:
        return std::sqrt(base - (K * Bp.transpose() * weight * Bp).trace());
      case Criterion::D: {
        const Eigen::MatrixXd I_minus =
            Eigen::MatrixXd::Identity(k, k) - K * Bp.transpose() * weight * Bp;
        return std::exp((base + std::log(I_minus.determinant())) / (2.0 * n_p));
      }
      default: {
        const Eigen::MatrixXd C = design.J_active * Bp;
        const Eigen::MatrixXd CK = C * K;
        const int d = pool_.dimension();
        double worst = 0.0;
        for (long g = 0; g < active_base.size(); ++g) {
          const double drop = CK.middleRows(d * g, d).cwiseProduct(C.middleRows(d * g, d)).sum();
          worst = std::max(worst, active_base[g] - drop);
        }
        return std::sqrt(worst);
      }
    }
  };
  SlotCandidate best;
  const auto consider = [&](int c) {
    if (design.in_design[static_cast<std::size_t>(c)]) return;
    const double v = tries(c);
    if (std::isfinite(v) && v < best.value) {
      best.candidate = c;
      best.value = v;
    }
  };
  if (options_.slot_candidates > 0 && options_.slot_candidates < pool_.size()) {
    for (int c : drawDistinctReadings(pool_.size(), options_.slot_candidates, rng)) consider(c);
  } else {
    for (int c = 0; c < pool_.size(); ++c) consider(c);
  }
  if (best.candidate >= 0) {
    const Eigen::Ref<const Eigen::MatrixXd> a = pool_.rows(best.candidate);
    const Eigen::MatrixXd B = M_inv * a.transpose();
    const Eigen::MatrixXd K = (Eigen::MatrixXd::Identity(k, k) + a * B).inverse();
    best.V_p = V0 - B.topRows(n_p) * K * B.topRows(n_p).transpose();
  }
  return best;
}

// The slot swapped for its best candidate when that lowers the criterion. For G the ranking is
// by the active-set bound; a candidate the full criterion refutes has grown the set, and the
// ranking is redone (at most kPoolSlotConfirmations times).
bool PoolSearch::improveSlot(PoolDesign& design, int slot, std::mt19937_64& rng) const {
  const double threshold = design.value * (1.0 - 1e-9);
  for (int attempt = 0; attempt < kPoolSlotConfirmations; ++attempt) {
    const SlotCandidate best = bestSwap(design, slot, rng);
    if (best.candidate < 0 || !(best.value < threshold)) return false;
    const double confirmed = fullValue(design, best.V_p);
    if (confirmed < threshold) {
      const auto s = static_cast<std::size_t>(slot);
      design.in_design[static_cast<std::size_t>(design.chosen[s])] = 0;
      design.in_design[static_cast<std::size_t>(best.candidate)] = 1;
      design.chosen[s] = best.candidate;
      design.value = confirmed;
      return true;
    }
    if (options_.criterion != Criterion::WorstTip) return false;
  }
  return false;
}

void PoolSearch::exchange(PoolDesign& design, std::mt19937_64& rng) {
  for (int pass = 0; pass < options_.exchange_passes; ++pass) {
    bool improved = false;
    for (int slot = 0; slot < count_; ++slot) {
      if (remaining() <= 0.0) {
        timed_out_ = true;
        return;
      }
      improved = improveSlot(design, slot, rng) || improved;
    }
    if (!improved) return;
  }
}

PoolChoice PoolSearch::run(const std::vector<int>* seeded) {
  const int starts = std::max(1, options_.starts);
  std::vector<PoolDesign> designs(static_cast<std::size_t>(starts));
  std::vector<char> done(static_cast<std::size_t>(starts), 0);
  std::mutex progress_mutex;
  int starts_done = 0;
  double best = kNoPoolValue;
  parallelFor(starts, threadCount(options_.threads, starts), [&](int start, int) {
    if (start > 0 && remaining() <= 0.0) {  // start 0 always runs: there is a result
      timed_out_ = true;
      return;
    }
    std::mt19937_64 rng =
        seededGenerator(options_.seed, kPoolSlotStream, static_cast<std::uint64_t>(start));
    PoolDesign design = initialDesign(start, seeded);
    exchange(design, rng);
    const std::lock_guard lock(progress_mutex);
    best = std::min(best, design.value);
    designs[static_cast<std::size_t>(start)] = std::move(design);
    done[static_cast<std::size_t>(start)] = 1;
    ++starts_done;
    if (options_.progress) {
      options_.progress({starts_done, starts, best,
                         std::chrono::duration<double>(PoolClock::now() - started_).count()});
    }
  });
  PoolChoice choice;
  choice.criterion = options_.criterion;
  choice.starts = starts;
  choice.starts_done = starts_done;
  for (int s = 0; s < starts; ++s) {  // the best start wins, ties to the lower index
    const PoolDesign& d = designs[static_cast<std::size_t>(s)];
    if (done[static_cast<std::size_t>(s)] && (choice.best_start < 0 || d.value < choice.value)) {
      choice.best_start = s;
      choice.value = d.value;
      choice.chosen = d.chosen;
    }
  }
  std::sort(choice.chosen.begin(), choice.chosen.end());
  choice.timed_out = timed_out_;
  choice.seconds = std::chrono::duration<double>(PoolClock::now() - started_).count();
  return choice;
}

PoolChoice chooseReadings(const ReadingPool& pool, int count, const PoolOptions& options) {
  const Plan& plan = pool.criterionPlan();
  if (count < 1 || count > pool.size()) {
    throw InputError(plan.source, "/placements",
                     "cannot choose " + std::to_string(count) + " of the pool's " +
                         std::to_string(pool.size()) + " readings: choose between 1 and " +
                         std::to_string(pool.size()));
  }
  if (!isPoolCriterion(options.criterion)) {
    throw InputError(
        plan.source, "/design/criterion",
        "a pool is chosen by worst-tip, mean-tip, D or A, not " + criterionName(options.criterion));
  }
  const auto started = PoolClock::now();
  std::optional<std::vector<int>> seeded;
  if (options.criterion == Criterion::WorstTip) {
    // Start 0 from the D choice: the G choice is then never worse in G than the D choice.
    PoolOptions d_options = options;
    d_options.criterion = Criterion::D;
    d_options.progress = nullptr;
    d_options.time_limit = options.time_limit / 2.0;
    seeded = PoolSearch(pool, count, d_options).run(nullptr).chosen;
  }
  PoolOptions g_options = options;
  g_options.time_limit =
      options.time_limit - std::chrono::duration<double>(PoolClock::now() - started).count();
  PoolChoice choice = PoolSearch(pool, count, g_options).run(seeded ? &*seeded : nullptr);
  choice.seconds = std::chrono::duration<double>(PoolClock::now() - started).count();
  return choice;
}

std::vector<int> randomReadings(const ReadingPool& pool, int count, std::uint64_t seed, int draw) {
  std::mt19937_64 rng = seededGenerator(seed, kPoolRandomStream, static_cast<std::uint64_t>(draw));
  std::vector<int> chosen = drawDistinctReadings(pool.size(), std::min(count, pool.size()), rng);
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

std::vector<int> farthestReadings(const ReadingPool& pool, int count) {
  const Plan& plan = pool.criterionPlan();
  const int n = pool.size();
  const int joints = plan.machine.mechanism->jointCount();
  Eigen::MatrixXd q(joints, n);
  for (int i = 0; i < n; ++i) {
    const PoolReading& r = pool.readings()[static_cast<std::size_t>(i)];
    q.col(i) = plan.placements[static_cast<std::size_t>(r.placement)]
                   .measurements[static_cast<std::size_t>(r.measurement)]
                   .joints;
  }
  // Joints scaled by their range over the pool, so that every joint counts alike.
  const Eigen::VectorXd range = (q.rowwise().maxCoeff() - q.rowwise().minCoeff()).cwiseMax(1e-12);
  q = range.cwiseInverse().asDiagonal() * q;
  const Eigen::VectorXd mean = q.rowwise().mean();
  int first = 0;
  (q.colwise() - mean).colwise().squaredNorm().minCoeff(&first);
  std::vector<int> chosen{first};
  Eigen::VectorXd nearest = (q.colwise() - q.col(first)).colwise().squaredNorm().transpose();
  while (static_cast<int>(chosen.size()) < std::min(count, n)) {
    int next = 0;
    nearest.maxCoeff(&next);
    chosen.push_back(next);
    nearest = nearest.cwiseMin((q.colwise() - q.col(next)).colwise().squaredNorm().transpose());
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

}  // namespace artcal
