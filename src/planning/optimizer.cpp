#include "artcal/planning/optimizer.hpp"

#include "artcal/core/dense_decompositions.hpp"
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <deque>
#include <exception>
#include <limits>
#include <mutex>
#include <nlopt.hpp>
#include <numeric>
#include <sstream>
#include <thread>

#include "artcal/acceptance/length_acceptance.hpp"
#include "artcal/calibration/simulation.hpp"
#include "artcal/core/error.hpp"
#include "artcal/core/linear_algebra.hpp"
#include "artcal/core/parallel.hpp"
#include "artcal/core/random.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/estimation/identifiability.hpp"
#include "artcal/planning/instrument_design.hpp"

namespace artcal {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Exchange: candidates refuted by the full criterion before a slot is left as it is.
constexpr int kExchangeConfirmations = 24;
// Refinement: runs on the active-set bound, each followed by the full criterion at its optimum.
constexpr int kRefineRounds = 4;
// Polish: restarts of the refinement while a round gains this much, and the kicks' size (a
// fraction of the design space's initial steps).
constexpr int kPolishRounds = 12;
constexpr double kPolishGain = 1e-4;
constexpr double kKickSize = 0.3;

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The machine's reach (largest probe distance over the workspace): mm per rad for D, A, E.
double machineReach(const Machine& machine, const std::vector<Eigen::VectorXd>& workspace) {
  double reach = 0.0;
  Eigen::VectorXd x;
  for (const Eigen::VectorXd& q : workspace) {
    forwardOrThrow(*machine.mechanism, machine.nominal, q, x);
    reach = std::max(reach, x.norm());
  }
  return reach > 0.0 ? reach : 1.0;
}

}  // namespace

std::string refineAlgorithmName(RefineAlgorithm algorithm) {
  return nameOf(kRefineAlgorithmNames, algorithm);
}

std::optional<RefineAlgorithm> refineAlgorithmFromName(const std::string& name) {
  return fromName(kRefineAlgorithmNames, name);
}

OptimizerOptions OptimizerOptions::fromDesign(const DesignSpec& design) {
  OptimizerOptions options;
  options.criterion = design.criterion;
  options.seed = design.seed;
  options.starts = design.starts;
  options.time_limit = design.time_limit;
  options.pool_size = design.pool;
  options.refine_evaluations = design.evaluations;
  options.polish = design.polish;
  options.kicks = design.kicks;
  return options;
}

bool OptimizerOptions::isValid(std::string* why) const {
  auto fail = [why](const std::string& message) {
    if (why) *why = message;
    return false;
  };
  if (starts < 1) return fail("starts must be at least 1");
  if (!(time_limit > 0.0)) return fail("time_limit must be positive");
  if (pool_size < 0) return fail("pool_size must not be negative");
  if (exchange_passes < 0) return fail("exchange_passes must not be negative");
  if (refine_evaluations < 0) return fail("refine_evaluations must not be negative");
  if (!(smooth_power >= 0.0) || !std::isfinite(smooth_power)) {
    return fail("smooth_power must be finite and not negative");
  }
  if (threads < 0) return fail("threads must not be negative");
  if (polish < 0 || kicks < 0) return fail("polish and kicks must not be negative");
  return true;
}

int OptimizerSummary::startsDone() const {
  return static_cast<int>(
      std::count_if(starts.begin(), starts.end(), [](const StartResult& s) { return s.done; }));
}

OptimizerSummary OptimizerSummary::ofStarts(Criterion criterion, std::vector<StartResult> starts,
                                            int pool_size, bool timed_out, double seconds) {
  OptimizerSummary summary;
  summary.criterion = criterion;
  summary.starts = std::move(starts);
  summary.pool_size = pool_size;
  summary.value = kInfinity;
  for (std::size_t s = 0; s < summary.starts.size(); ++s) {
    const StartResult& r = summary.starts[s];
    if (r.done && r.refined < summary.value) {
      summary.value = r.refined;
      summary.best_start = static_cast<int>(s);
    }
  }
  summary.termination = timed_out ? Termination::TimeLimit : Termination::Completed;
  summary.seconds = seconds;
  if (summary.best_start < 0) summary.message = "no start produced an identifiable design";
  return summary;
}

std::string OptimizerSummary::briefReport() const {
  std::ostringstream out;
  out << (termination == Termination::Completed ? "completed" : "time limit reached") << ": "
      << startsDone() << "/" << starts.size() << " starts, best ";
  if (criterion == Criterion::Pass) {
    const PassObjective objective = passObjectiveOf(value);
    out << objective.value << " (" << objective.name() << ")";
  } else {
    out << value * 1000.0 << " um";
  }
  out << " (start " << best_start << "), pool " << pool_size << ", " << seconds << " s";
  return out.str();
}

// ---------------------------------------------------------------------------------------------
// DesignCriterion

// Criterion::Pass: the plan's ISO 10360-2 gauges at nominal (their g and noise parts do not
// depend on the design), and fixed standard normal draws of the shared parameter error.
struct PassCriterionData {
  LengthTestPrediction gauges;
  Eigen::MatrixXd G;  ///< gauges x calibrated parameters
  Eigen::MatrixXd Z;  ///< calibrated parameters x draws
};

namespace {

constexpr std::uint64_t kPassDrawSeed = 20261201;
constexpr double kPassSaturation = 1.0 / (kPassDraws + 1.0);
constexpr double kPassQuantile = 0.95;

std::shared_ptr<const PassCriterionData> makePassCriterion(const Plan& plan) {
  if (!plan.acceptance) throw std::logic_error("criterion pass without an acceptance block");
  const int n = plan.machine.calibratedCount();
  const AcceptanceInput input = acceptanceInputAtNominal(plan, Eigen::MatrixXd::Zero(n, n));
  LengthTestOptions options;
  options.mpe = *parseMpe(plan.acceptance->mpe);
  auto data = std::make_shared<PassCriterionData>();
  data->gauges = predictLengthTestLinear(input, options);
  data->G = gaugeDerivatives(data->gauges.gauges);
  NormalSource normal(kPassDrawSeed);
  data->Z.resize(n, kPassDraws);
  for (Eigen::Index m = 0; m < data->Z.cols(); ++m)
    for (Eigen::Index k = 0; k < n; ++k) data->Z(k, m) = normal();
  return data;
}

bool passSaturated(double p_pass) {
  return std::min(p_pass, 1.0 - p_pass) <= kPassSaturation;
}

/// The pass criterion's figures for V_p (PassCriterionData); q95 only when P(pass) saturates
/// unless `with_quantile`.
PassEstimate estimatePass(const PassCriterionData& pass, const Eigen::MatrixXd& V,
                          bool with_quantile) {
  const Eigen::LLT<Eigen::MatrixXd> llt(V);
  const Eigen::MatrixXd F =
      llt.info() == Eigen::Success ? Eigen::MatrixXd(llt.matrixL()) : covarianceFactor(V);
  const Eigen::MatrixXd S = pass.G * (F * pass.Z);
  PassEstimate estimate;
  estimate.p_pass = meanConditionalPassProbability(pass.gauges, S);
  estimate.standard_error = std::sqrt(std::max(estimate.p_pass * (1.0 - estimate.p_pass), 0.0) /
                                      static_cast<double>(S.cols()));
  estimate.saturated = passSaturated(estimate.p_pass);
  if (estimate.saturated || with_quantile)
    estimate.q95 = conditionalStatisticQuantile(pass.gauges, S, kPassQuantile);
  estimate.value = passCriterionValue(estimate.p_pass, estimate.q95);
  return estimate;
}

}  // namespace

std::string PassObjective::name() const {
  return quantity == Quantity::FailProbability ? "1 - P(pass)" : "q95 of max |E|/MPE";
}

double passCriterionValue(double p_pass, double q95) {
  if (!passSaturated(p_pass)) return 1.0 - p_pass;
  // q95 <= 1 when P >= 1 - eps > 0.95 and q95 >= 1 when P <= eps: the clamps only guard the
  // ranges against the quantile's round-off.
  if (p_pass > 0.5) return kPassSaturation * std::min(q95, 1.0);
  return (1.0 - kPassSaturation) * std::max(q95, 1.0);
}

PassObjective passObjectiveOf(double criterion_value) {
  using Quantity = PassObjective::Quantity;
  if (criterion_value <= kPassSaturation)
    return {Quantity::Quantile95, criterion_value / kPassSaturation};
  if (criterion_value >= 1.0 - kPassSaturation)
    return {Quantity::Quantile95, criterion_value / (1.0 - kPassSaturation)};
  return {Quantity::FailProbability, criterion_value};
}

DesignCriterion::DesignCriterion(const Plan& plan, Criterion criterion, double smooth_power)
    : plan_(&plan),
      criterion_(criterion),
      smooth_power_(smooth_power),
      layout_(GlobalLayout::of(plan)),
      evaluator_(plan),
      builder_(plan.machine, plan.noise),
      reducer_(layout_) {
  const Machine& machine = plan.machine;
  const double reach = machineReach(machine, evaluator_.workspace().configurations());
  scale_.resize(machine.calibratedCount());
  for (int k = 0; k < machine.calibratedCount(); ++k) {
    scale_[k] = machine.calibratedInfo(k).quantity.isAngle() ? reach : 1.0;
  }
  if (criterion == Criterion::Pass) pass_ = makePassCriterion(plan);
}

Eigen::MatrixXd DesignCriterion::contribution(const Placement& placement) {
  const std::vector<Placement> one{placement};
  const RigidTransform pose = fitPlacements(*plan_, one, plan_->machine.nominal).front();
  const Artifact& artifact = plan_->artifacts[static_cast<std::size_t>(placement.artifact)];
  builder_.build(artifact, placement.measurements, plan_->machine.nominal, pose, Eigen::VectorXd(),
                 false, block_);
  reducer_.reset();
  reducer_.add(block_, placement.artifact);
  return reducer_.normal();
}

double DesignCriterion::value(const Eigen::MatrixXd& information_g) {
  return evaluate(information_g, 0.0);
}

double DesignCriterion::smoothValue(const Eigen::MatrixXd& information_g) {
  return evaluate(information_g, smooth_power_);
}

std::optional<PassEstimate> DesignCriterion::passEstimate(const Eigen::MatrixXd& information_g) {
  if (criterion_ != Criterion::Pass) throw std::logic_error("passEstimate: criterion is not pass");
  const auto covariance =
      covarianceFromInformation(informationOfParameters(information_g, layout_));
  if (!covariance) return std::nullopt;
  return estimatePass(*pass_, covariance->V, true);
}

double DesignCriterion::worstOver(const Eigen::MatrixXd& V, const TipEvaluator& tip) {
  tip.kinematicVariance(V, S_m2_);
  return std::sqrt((S_m2_.array() + tip.encoderVariance().array()).maxCoeff());
}

void DesignCriterion::resetActive() {
  active_.clear();
  active_tip_.reset();
}

double DesignCriterion::activeValue(const Eigen::MatrixXd& information_g) {
  if (criterion_ != Criterion::WorstTip || !active_tip_) return value(information_g);
  const auto covariance =
      covarianceFromInformation(informationOfParameters(information_g, layout_));
  if (!covariance) return kInfinity;
  return worstOver(covariance->V, *active_tip_);
}

double DesignCriterion::activate(const Eigen::MatrixXd& information_g) {
  if (criterion_ != Criterion::WorstTip) return value(information_g);
  const auto covariance =
      covarianceFromInformation(informationOfParameters(information_g, layout_));
  if (!covariance) return kInfinity;
  const TipEvaluator& tip = evaluator_.workspace();
  tip.kinematicVariance(covariance->V, S_m2_);
  const Eigen::VectorXd S2 = S_m2_ + tip.encoderVariance();
  double active_worst = 0.0;
  for (int g : active_) active_worst = std::max(active_worst, S2[g]);
  // The few worst configurations above the active set's worst join it (a handful at a time:
  // neighbours of a new worst point tend to be next).
  constexpr int kJoinAtOnce = 4;
  std::vector<int> above;
  for (int g = 0; g < S2.size(); ++g) {
    if (S2[g] > active_worst * (1.0 + 1e-12)) above.push_back(g);
  }
  const auto count = std::min<std::size_t>(above.size(), kJoinAtOnce);
  std::partial_sort(above.begin(), above.begin() + static_cast<long>(count), above.end(),
                    [&](int a, int b) { return S2[a] > S2[b] || (S2[a] == S2[b] && a < b); });
  if (count > 0) {
    active_.insert(active_.end(), above.begin(), above.begin() + static_cast<long>(count));
    std::vector<Eigen::VectorXd> configurations;
    std::vector<int> styluses;
    for (int g : active_) {
      configurations.push_back(tip.configurations()[static_cast<std::size_t>(g)]);
      styluses.push_back(tip.styluses()[static_cast<std::size_t>(g)]);
    }
    active_tip_.emplace(plan_->machine, plan_->noise, std::move(configurations),
                        std::move(styluses));
  }
  return std::sqrt(S2.maxCoeff());
}

double DesignCriterion::evaluate(const Eigen::MatrixXd& information_g, double power) {
  const auto covariance =
      covarianceFromInformation(informationOfParameters(information_g, layout_));
  if (!covariance) return kInfinity;
  const Eigen::MatrixXd& V = covariance->V;
  const TipEvaluator& tip = evaluator_.workspace();
  switch (criterion_) {
    case Criterion::WorstTip:
    case Criterion::MeanTip: {
      tip.kinematicVariance(V, S_m2_);
      const Eigen::ArrayXd S2 = S_m2_.array() + tip.encoderVariance().array();
      if (criterion_ == Criterion::MeanTip) return std::sqrt(S2.mean());
      const double worst2 = S2.maxCoeff();
      if (power <= 0.0) return std::sqrt(worst2);
      // p-norm of S relative to the worst: smooth, at most the max, near it for large p.
      return std::sqrt(worst2) * std::pow((S2 / worst2).pow(0.5 * power).mean(), 1.0 / power);
    }
    case Criterion::D:
    case Criterion::A:
    case Criterion::E: {
      const Eigen::MatrixXd Vs = scale_.asDiagonal() * V * scale_.asDiagonal();
      const SymmetricEigenSolver eigen(Vs, Eigen::EigenvaluesOnly);
      const Eigen::VectorXd lambda = eigen.eigenvalues().cwiseMax(0.0);
      const double n = static_cast<double>(lambda.size());
      if (criterion_ == Criterion::A) return std::sqrt(lambda.sum() / n);
      if (criterion_ == Criterion::E) return std::sqrt(lambda.maxCoeff());
      return std::exp(lambda.array().log().sum() / (2.0 * n));
    }
    case Criterion::Pass:
      return estimatePass(*pass_, V, false).value;
  }
  return kInfinity;
}

// ---------------------------------------------------------------------------------------------
// Counting condition

namespace {

// An instrument design: stations x (readings x coordinates - rigid unknowns) equations.
void checkInstrumentDesignCount(const Plan& plan, const CountingCondition& fixed) {
  const DesignSpec& design = *plan.design;
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(design.artifact)];
  const int readings = design.instrument->readings;
  const int per_station = readings * artifact.rowsPerReading() - artifact.fullRigidDof();
  const int equations = fixed.N_b - fixed.N_r + design.placements * per_station;
  const int N_p = plan.machine.calibratedCount();
  if (equations >= N_p) return;
  std::ostringstream message;
  message << "cannot be identifiable: " << design.placements << " station(s) of \"" << artifact.id
          << "\" with " << readings << " readings give " << design.placements << " x (" << readings
          << " readings x " << artifact.rowsPerReading() << " coordinates - "
          << artifact.fullRigidDof() << " rigid unknowns)";
  if (!plan.placements.empty()) message << " + " << fixed.N_b - fixed.N_r << " (fixed placements)";
  message << " = " << equations << " equations for " << N_p
          << " parameters (counting condition, docs/method.md section 5)";
  throw InputError(plan.source, "/design/readings", message.str());
}

}  // namespace

void checkDesignCount(const Plan& plan) {
  const DesignSpec& design = *plan.design;
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(design.artifact)];
  const CountingCondition fixed = countingCondition(plan, plan.placements);
  if (design.instrument) return checkInstrumentDesignCount(plan, fixed);
  const int per_placement =
      artifact.featureCount() * design.postures * artifact.valuedPerFeature() - artifact.rigidDof();
  const int equations = fixed.N_b - fixed.N_r + design.placements * per_placement;
  const int N_p = plan.machine.calibratedCount();
  if (equations >= N_p) return;
  std::ostringstream message;
  message << "cannot be identifiable: " << design.placements << " placement(s) of \"" << artifact.id
          << "\" with " << design.postures << " posture(s) give " << design.placements << " x ("
          << artifact.featureCount() << " features x " << design.postures << " postures x "
          << artifact.valuedPerFeature() << " coordinates - " << artifact.rigidDof()
          << " rigid unknowns)";
  if (!plan.placements.empty()) message << " + " << fixed.N_b - fixed.N_r << " (fixed placements)";
  message << " = " << equations << " equations for " << N_p
          << " parameters (counting condition, docs/method.md section 5)";
  if (per_placement > 0) {
    const int needed = (N_p - (fixed.N_b - fixed.N_r) + per_placement - 1) / per_placement;
    message << "; at least " << needed << " placements are needed";
  }
  throw InputError(plan.source, "/design/placements", message.str());
}

// ---------------------------------------------------------------------------------------------
// The search

namespace {

struct Candidate {
  Eigen::VectorXd pose;  ///< pose vector (design_space.hpp)
  Placement placement;
  Eigen::MatrixXd information;  ///< its additive term over g
};

class Search {
 public:
  Search(const Plan& plan, const OptimizerOptions& options)
      : plan_(plan), options_(options), space_(plan), start_time_(Clock::now()) {
    threads_ = threadCount(options.threads, std::numeric_limits<int>::max());
    for (int t = 0; t < threads_; ++t) {
      criteria_.emplace_back(plan, options.criterion, options.smooth_power);
    }
  }

  OptimizerSummary run();

 private:
  double remaining() const { return options_.time_limit - secondsSince(start_time_); }
  void buildPool();
  void runStart(int start, DesignCriterion& criterion);
  void polish(int start, DesignCriterion& criterion);
  double exchange(std::vector<int>& chosen, Eigen::MatrixXd& total, double value,
                  DesignCriterion& criterion);
  double refine(std::vector<Placement>& placements, std::vector<Eigen::VectorXd>& poses,
                double value, DesignCriterion& criterion);
  Eigen::MatrixXd fixedInformation(DesignCriterion& criterion) const;

  const Plan& plan_;
  const OptimizerOptions& options_;
  DesignSpace space_;
  Clock::time_point start_time_;
  int threads_ = 1;
  std::deque<DesignCriterion> criteria_;
  Eigen::MatrixXd fixed_;
  std::vector<Candidate> pool_;
  std::vector<StartResult> results_;
  std::vector<std::vector<Placement>> designs_;
  std::vector<std::vector<Eigen::VectorXd>> design_poses_;
  std::atomic<bool> timed_out_{false};
  std::mutex progress_mutex_;
};

Eigen::MatrixXd Search::fixedInformation(DesignCriterion& criterion) const {
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(criterion.globalSize(), criterion.globalSize());
  for (const Placement& p : plan_.placements) sum += criterion.contribution(p);
  return sum;
}

void Search::buildPool() {
  const DesignSpec& design = *plan_.design;
  const int size =
      options_.pool_size > 0 ? options_.pool_size : std::clamp(30 * design.placements, 120, 600);
  // The first candidate alone tells whether the region holds any feasible placement at all.
  constexpr int kProbeAttempts = 400;
  constexpr int kAttempts = 4000;
  std::vector<std::optional<Candidate>> found(static_cast<std::size_t>(size));
  auto make = [&](int i, int worker) {
    std::mt19937_64 rng = seededGenerator(options_.seed, 1, static_cast<std::uint64_t>(i));
    auto drawn = space_.randomPlacement(rng, i == 0 ? kProbeAttempts : kAttempts);
    if (!drawn) return;
    Eigen::MatrixXd information =
        criteria_[static_cast<std::size_t>(worker)].contribution(drawn->second);
    found[static_cast<std::size_t>(i)] =
        Candidate{std::move(drawn->first), std::move(drawn->second), std::move(information)};
  };
  make(0, 0);
  if (!found[0]) {
    throw InputError(plan_.source, "/design/region",
                     "no placement of \"" + space_.artifact().id +
                         "\" found with every feature inside the region and reachable within "
                         "the joint limits (" +
                         std::to_string(kProbeAttempts) + " random poses tried)");
  }
  parallelFor(size - 1, threads_, [&](int i, int worker) { make(i + 1, worker); });
  for (auto& candidate : found) {
    if (candidate) pool_.push_back(std::move(*candidate));
  }
}

double Search::exchange(std::vector<int>& chosen, Eigen::MatrixXd& total, double value,
                        DesignCriterion& criterion) {
  // Fedorov exchange: the best single swap of each slot in turn, until a pass improves nothing.
  for (int pass = 0; pass < options_.exchange_passes; ++pass) {
    bool improved = false;
    for (std::size_t slot = 0; slot < chosen.size(); ++slot) {
      if (remaining() <= 0.0) {
        timed_out_ = true;
        return value;
      }
      const Eigen::MatrixXd without =
          total - pool_[static_cast<std::size_t>(chosen[slot])].information;
      // Candidates ranked by the active-set bound, the best one confirmed by the full criterion;
      // a refuted one has grown the active set, so the ranking is redone (a bound never above G
      // means no candidate is missed that the full criterion would accept).
      for (int attempt = 0; attempt < kExchangeConfirmations; ++attempt) {
        int best = -1;
        double best_bound = value * (1.0 - 1e-9);
        for (std::size_t c = 0; c < pool_.size(); ++c) {
          if (std::find(chosen.begin(), chosen.end(), static_cast<int>(c)) != chosen.end()) {
            continue;
          }
          const double v = criterion.activeValue(without + pool_[c].information);
          if (v < best_bound) {
            best_bound = v;
            best = static_cast<int>(c);
          }
        }
        if (best < 0) break;
        const Eigen::MatrixXd swapped = without + pool_[static_cast<std::size_t>(best)].information;
        const double confirmed = criterion.activate(swapped);
        if (confirmed < value * (1.0 - 1e-9)) {
          chosen[slot] = best;
          total = swapped;
          value = confirmed;
          improved = true;
          break;
        }
      }
    }
    if (!improved) break;
  }
  return value;
}

nlopt::algorithm nloptAlgorithm(RefineAlgorithm algorithm) {
  switch (algorithm) {
    case RefineAlgorithm::Bobyqa:
      return nlopt::LN_BOBYQA;
    case RefineAlgorithm::NelderMead:
      return nlopt::LN_NELDERMEAD;
    case RefineAlgorithm::Cobyla:
      return nlopt::LN_COBYLA;
    default:
      return nlopt::LN_SBPLX;
  }
}

struct NloptProblem {
  nlopt::algorithm algorithm = nlopt::LN_SBPLX;
  std::vector<double> lower, upper, steps;
  int evaluations = 1000;
  double seconds = 1.0;
};

// Minimises f from x (overwritten with the best point found) with a derivative-free NLopt
// algorithm. NLopt's C++ wrapper swallows exceptions thrown in the objective: the
// first is kept, the run is stopped and the exception rethrown after. A roundoff-limited run
// still leaves its best point in x: possibly usable, the caller judges it.
void minimizeDerivativeFree(const NloptProblem& problem,
                            const std::function<double(const double*)>& f, std::vector<double>& x) {
  nlopt::opt opt(problem.algorithm, static_cast<unsigned>(x.size()));
  opt.set_lower_bounds(problem.lower);
  opt.set_upper_bounds(problem.upper);
  opt.set_initial_step(problem.steps);
  opt.set_maxeval(problem.evaluations);
  opt.set_maxtime(problem.seconds);
  opt.set_xtol_rel(1e-7);
  opt.set_ftol_rel(1e-9);
  struct Context {
    const std::function<double(const double*)>* f;
    nlopt::opt* opt;
    std::exception_ptr failure;
  } context{&f, &opt, nullptr};
  opt.set_min_objective(
      [](unsigned, const double* xs, double*, void* data) {
        auto* c = static_cast<Context*>(data);
        try {
          return (*c->f)(xs);
        } catch (...) {
          if (!c->failure) c->failure = std::current_exception();
          c->opt->force_stop();
          return HUGE_VAL;
        }
      },
      &context);
  double minimum = 0.0;
  try {
    opt.optimize(x, minimum);
  } catch (const nlopt::roundoff_limited&) {
  } catch (const nlopt::forced_stop&) {
  }
  if (context.failure) std::rethrow_exception(context.failure);
}

double Search::refine(std::vector<Placement>& placements, std::vector<Eigen::VectorXd>& poses,
                      double value, DesignCriterion& criterion) {
  if (options_.algorithm == RefineAlgorithm::None || remaining() <= 0.0) return value;
  const int m = static_cast<int>(placements.size());
  const int k = space_.poseSize();
  const unsigned n = static_cast<unsigned>(m * k);
  const std::vector<Placement> base = placements;
  // One slot per placement: its last pose, the placement there (readings continued from the
  // starting postures) and its information term. Subplex moves a few coordinates at a time, so
  // most slots are reused.
  struct Slot {
    Eigen::VectorXd pose;
    std::optional<Placement> placement;
    double violation = 0.0;
    Eigen::MatrixXd term;
  };
  std::vector<Slot> slots(static_cast<std::size_t>(m));
  auto slotAt = [&](const double* x, int j) -> Slot& {
    Slot& slot = slots[static_cast<std::size_t>(j)];
    const Eigen::Map<const Eigen::VectorXd> v(x + j * k, k);
    if (slot.pose.size() == k && slot.pose == v) return slot;
    slot.pose = v;
    slot.violation = space_.regionViolation(v);
    slot.placement = space_.movePlacement(base[static_cast<std::size_t>(j)], v);
    if (slot.placement) slot.term = criterion.contribution(*slot.placement);
    return slot;
  };
  // The information at x, or the penalty measure of an infeasible x (how far its features leave
  // the region, plus one per placement without readings).
  auto informationAt = [&](const double* x, Eigen::MatrixXd& total) {
    total = fixed_;
    double violation = 0.0;
    for (int j = 0; j < m; ++j) {
      const Slot& slot = slotAt(x, j);
      violation += slot.violation + (slot.placement ? 0.0 : 1.0);
      if (slot.placement) total += slot.term;
    }
    return violation;
  };
  const double penalty_base = 10.0 * value;
  Eigen::MatrixXd total;
  auto objective = [&](const double* x) {
    const double violation = informationAt(x, total);
    if (violation > 0.0) return penalty_base * (1.0 + violation);
    const double v =
        options_.smooth_power > 0.0 ? criterion.smoothValue(total) : criterion.activeValue(total);
    return std::isfinite(v) ? v : penalty_base;
  };
  NloptProblem problem;
  problem.algorithm = nloptAlgorithm(options_.algorithm);
  for (int j = 0; j < m; ++j) {
    for (int i = 0; i < k; ++i) {
      problem.lower.push_back(space_.lowerBounds()[i]);
      problem.upper.push_back(space_.upperBounds()[i]);
      problem.steps.push_back(space_.initialSteps()[i] * 0.25);
    }
  }
  std::vector<double> x(n);
  for (int j = 0; j < m; ++j) {
    for (int i = 0; i < k; ++i) {
      const auto at = static_cast<std::size_t>(j * k + i);
      x[at] =
          std::clamp(poses[static_cast<std::size_t>(j)][i], problem.lower[at], problem.upper[at]);
    }
  }
  problem.evaluations = options_.refine_evaluations > 0 ? options_.refine_evaluations
                                                        : std::min(300 * static_cast<int>(n), 6000);
  // Rounds: the optimum of the active-set bound is checked with the full max; where they
  // differ the active set has grown and the search goes on from there.
  double refined = kInfinity;
  for (int round = 0; round < kRefineRounds && remaining() > 0.0; ++round) {
    problem.seconds = std::max(remaining(), 1e-3);
    minimizeDerivativeFree(problem, objective, x);
    if (informationAt(x.data(), total) > 0.0) break;
    const double bound = criterion.activeValue(total);
    refined = criterion.activate(total);
    if (options_.smooth_power > 0.0 || !(refined > bound * (1.0 + 1e-9))) break;
  }
  if (remaining() <= 0.0) timed_out_ = true;
  // Keep the refined design only when it is feasible and truly better (the max, not the proxy).
  if (informationAt(x.data(), total) > 0.0) return value;
  refined = criterion.value(total);
  if (!(refined < value)) return value;
  for (int j = 0; j < m; ++j) {
    const Slot& slot = slotAt(x.data(), j);
    placements[static_cast<std::size_t>(j)] = *slot.placement;
    poses[static_cast<std::size_t>(j)] = slot.pose;
  }
  return refined;
}

void Search::runStart(int start, DesignCriterion& criterion) {
  const int m = plan_.design->placements;
  std::mt19937_64 rng = seededGenerator(options_.seed, 2, static_cast<std::uint64_t>(start));
  // A random initial design: m distinct candidates when the pool has them.
  std::vector<int> order(pool_.size());
  std::iota(order.begin(), order.end(), 0);
  std::vector<int> chosen;
  for (int j = 0; j < m; ++j) {
    const std::size_t left = order.size() - std::min(static_cast<std::size_t>(j), order.size() - 1);
    const std::size_t pick = static_cast<std::size_t>(rng() % left);
    chosen.push_back(order[pick]);
    std::swap(order[pick], order[left - 1]);
  }
  Eigen::MatrixXd total = fixed_;
  for (int c : chosen) total += pool_[static_cast<std::size_t>(c)].information;
  StartResult& result = results_[static_cast<std::size_t>(start)];
  criterion.resetActive();
  result.initial = criterion.activate(total);
  result.exchanged = exchange(chosen, total, result.initial, criterion);
  std::vector<Placement> placements;
  std::vector<Eigen::VectorXd> poses;
  for (int c : chosen) {
    placements.push_back(pool_[static_cast<std::size_t>(c)].placement);
    poses.push_back(pool_[static_cast<std::size_t>(c)].pose);
  }
  result.refined = std::isfinite(result.exchanged)
                       ? refine(placements, poses, result.exchanged, criterion)
                       : result.exchanged;
  designs_[static_cast<std::size_t>(start)] = std::move(placements);
  design_poses_[static_cast<std::size_t>(start)] = std::move(poses);
  result.done = true;
}

// The best designs, polished (docs/optimize.md, "How it searches", step 7). A derivative-free
// local search of a minimax in 6 m dimensions stops short of its basin's floor: Subplex's
// simplices shrink on the way, so it is restarted from its own result while a round gains at
// least kPolishGain. Then an iterated local search (Lourenco, Martin and Stuetzle): each kick
// moves every pose coordinate by a normal draw of kKickSize of its initial step, refines the
// kicked design and keeps it when it is better. A kick crosses the ridges between neighbouring
// minima that the worst-tip max leaves and a simplex does not climb.
void Search::polish(int start, DesignCriterion& criterion) {
  StartResult& result = results_[static_cast<std::size_t>(start)];
  std::vector<Placement>& placements = designs_[static_cast<std::size_t>(start)];
  std::vector<Eigen::VectorXd>& poses = design_poses_[static_cast<std::size_t>(start)];
  Eigen::MatrixXd total = fixed_;
  for (const Placement& p : placements) total += criterion.contribution(p);
  criterion.resetActive();
  double value = criterion.activate(total);
  result.polished_from = value;
  for (int round = 0; round < kPolishRounds && remaining() > 0.0; ++round) {
    const double polished = refine(placements, poses, value, criterion);
    const bool gained = polished < value * (1.0 - kPolishGain);
    value = std::min(value, polished);
    if (!gained) break;
  }
  std::mt19937_64 rng = seededGenerator(options_.seed, 3, static_cast<std::uint64_t>(start));
  std::normal_distribution<double> normal;
  const Eigen::VectorXd steps = space_.initialSteps();
  for (int kick = 0; kick < options_.kicks && remaining() > 0.0; ++kick) {
    std::vector<Placement> trial = placements;
    std::vector<Eigen::VectorXd> trial_poses = poses;
    for (Eigen::VectorXd& pose : trial_poses) {
      for (int i = 0; i < pose.size(); ++i) pose[i] += kKickSize * steps[i] * normal(rng);
    }
    // The kicked design's value is not known: 2 x the current one sets the penalty scale.
    const double kicked = refine(trial, trial_poses, 2.0 * value, criterion);
    if (kicked < value) {
      value = kicked;
      placements = std::move(trial);
      poses = std::move(trial_poses);
    }
  }
  result.refined = std::min(result.refined, value);
}

OptimizerSummary Search::run() {
  checkDesignCount(plan_);
  buildPool();
  fixed_ = fixedInformation(criteria_.front());
  results_.assign(static_cast<std::size_t>(options_.starts), StartResult{});
  designs_.assign(static_cast<std::size_t>(options_.starts), {});
  design_poses_.assign(static_cast<std::size_t>(options_.starts), {});
  std::atomic<int> done{0};
  double best_so_far = kInfinity;
  parallelFor(options_.starts, threads_, [&](int start, int worker) {
    if (start > 0 && remaining() <= 0.0) {  // start 0 always runs: there is a result
      timed_out_ = true;
      return;
    }
    runStart(start, criteria_[static_cast<std::size_t>(worker)]);
    const std::lock_guard lock(progress_mutex_);
    best_so_far = std::min(best_so_far, results_[static_cast<std::size_t>(start)].refined);
    ++done;
    if (options_.progress) {
      options_.progress({done.load(), options_.starts, best_so_far, secondsSince(start_time_)});
    }
  });
  // The best few designs, polished (in parallel, each on its own worker's criterion; each
  // polish starts from a reset active set, so the result does not depend on the threads).
  std::vector<int> ranked;
  for (int s = 0; s < options_.starts; ++s)
    if (results_[static_cast<std::size_t>(s)].done) ranked.push_back(s);
  std::stable_sort(ranked.begin(), ranked.end(), [&](int a, int b) {
    return results_[static_cast<std::size_t>(a)].refined <
           results_[static_cast<std::size_t>(b)].refined;
  });
  ranked.resize(std::min<std::size_t>(ranked.size(), static_cast<std::size_t>(options_.polish)));
  parallelFor(static_cast<int>(ranked.size()), threads_, [&](int i, int worker) {
    if (remaining() <= 0.0) return;
    polish(ranked[static_cast<std::size_t>(i)], criteria_[static_cast<std::size_t>(worker)]);
  });
  OptimizerSummary summary =
      OptimizerSummary::ofStarts(options_.criterion, results_, static_cast<int>(pool_.size()),
                                 timed_out_, secondsSince(start_time_));
  if (summary.best_start < 0) return summary;
  summary.placements = designs_[static_cast<std::size_t>(summary.best_start)];
  if (options_.criterion == Criterion::Pass) {
    DesignCriterion& criterion = criteria_.front();
    Eigen::MatrixXd total = fixed_;
    for (const Placement& p : summary.placements) total += criterion.contribution(p);
    summary.pass = criterion.passEstimate(total);
  }
  summary.message = summary.briefReport();
  return summary;
}

}  // namespace

OptimizerSummary optimizePlan(const Plan& plan, const OptimizerOptions& options) {
  std::string why;
  if (!options.isValid(&why)) throw std::invalid_argument("optimizer options: " + why);
  if (!plan.design) throw InputError(plan.source, "/design", "the spec has no design block");
  if (plan.design->instrument) return optimizeInstrumentDesign(plan, options);
  Search search(plan, options);
  return search.run();
}

}  // namespace artcal
