#include "artcal/calibration/calibrator.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <type_traits>
#include <utility>

#include "artcal/estimation/reading_noise.hpp"
#include "artcal/estimation/reading_rows.hpp"

namespace artcal {

std::string terminationName(TerminationType type) {
  return nameOf(kTerminationNames, type);
}

bool CalibrationOptions::isValid(std::string* error) const {
  auto fail = [error](const char* message) {
    if (error) *error = message;
    return false;
  };
  if (max_iterations < 1) return fail("max_iterations must be at least 1");
  if (!(step_tolerance > 0.0) || !std::isfinite(step_tolerance))
    return fail("step_tolerance must be > 0");
  if (!(function_tolerance >= 0.0) || !std::isfinite(function_tolerance))
    return fail("function_tolerance must be >= 0");
  if (!(flag_threshold > 0.0) || !std::isfinite(flag_threshold))
    return fail("flag_threshold must be > 0");
  if (!(gross_threshold > 0.0) || !std::isfinite(gross_threshold))
    return fail("gross_threshold must be > 0");
  return damping.isValid(error);
}

std::string CalibrationSummary::briefReport() const {
  std::ostringstream out;
  out << terminationName(termination) << " after " << iterations << " iterations ("
      << accepted_steps << " steps accepted), cost " << initial_cost << " -> " << final_cost;
  if (!message.empty()) out << ": " << message;
  return out.str();
}

Eigen::VectorXd Calibration::posteriorU() const {
  if (!covariance || dof <= 0) return {};  // no redundancy: no a-posteriori scale
  return covariance->u * birgeRatio();
}

double Calibration::birgeRatio() const {
  return dof > 0 ? std::sqrt(chi2_per_dof) : 0.0;
}

std::optional<ParameterUncertainty> Calibration::uncertainty(const Machine& machine) const {
  if (!covariance) return std::nullopt;
  return ParameterUncertainty{machine.calibrated, covariance->V, birgeRatio(),
                              noise_estimate ? noise_estimate->probe : 0.0,
                              unmodelled ? unmodelled->sigma : 0.0};
}

Calibrator::Calibrator(const Plan& plan, const CalibrationOptions& options)
    : plan_(&plan),
      options_(options),
      layout_(GlobalLayout::of(plan)),
      builder_(plan.machine, plan.noise),
      reducer_(layout_),
      strategy_(options.damping) {
  std::string error;
  if (!options_.isValid(&error)) throw std::invalid_argument("calibration options: " + error);
}

namespace {

const Artifact& artifactOf(const Plan& plan, const Placement& placement) {
  return plan.artifacts[static_cast<std::size_t>(placement.artifact)];
}

/// The systematic errors of one artifact, taken from c (GlobalLayout order).
Eigen::VectorXd artifactErrors(const GlobalLayout& layout, const Artifact& artifact,
                               int artifact_index, const Eigen::VectorXd& c) {
  const int offset =
      layout.artifact_offset[static_cast<std::size_t>(artifact_index)] - layout.parameters;
  return c.segment(offset, artifact.systematicCount());
}

}  // namespace

double Linearization::predictedReduction(const Eigen::VectorXd& dg) const {
  // Minimising the linearised cost over every r_j for a given dg (docs/method.md section 3) gains
  // the rigid part plus the reduced quadratic model in dg.
  return rigid_reduction + LevenbergMarquardtStrategy::predictedReduction(N, b, dg);
}

CalibrationState Calibrator::initialState(const std::vector<Placement>& placements,
                                          const Eigen::VectorXd& start) const {
  CalibrationState state;
  state.p = start;
  state.c = Eigen::VectorXd::Zero(layout_.systematicCount());
  state.poses = fitPlacements(*plan_, placements, start);
  return state;
}

bool Calibrator::settled(const std::vector<Placement>& placements, bool& finite) {
  // Two-step feasible generalised least squares: weights at the start, then re-evaluated once at
  // the estimate and held while the fit converges again. Iterating further need not contract
  // where the weights depend on a weakly determined direction, and gains nothing statistically.
  if (current_lin_.fresh || reweightings_ >= kMaxReweightings) return true;
  ++reweightings_;
  // The weights at the current estimate replace the held ones; the loop goes on with them.
  // The same state's blocks, re-whitened with the weights at it (recorded when they were built).
  finite = rewhiten(placements, current_lin_.own_weights);
  return false;
}

void Calibrator::computeRigidCaps(const std::vector<Placement>& placements) {
  rigid_caps_.clear();
  for (const Placement& placement : placements) {
    rigid_caps_.push_back(
        rigidRankOfFeatures(artifactOf(*plan_, placement), placement.measurements));
  }
}

bool Calibrator::linearize(const std::vector<Placement>& placements, const CalibrationState& state,
                           Linearization& out, const Linearization* weights) {
  computeRigidCaps(placements);
  return linearizeCapped(placements, state, out, weights);
}

bool Calibrator::linearizeCapped(const std::vector<Placement>& placements,
                                 const CalibrationState& state, Linearization& out,
                                 const Linearization* weights) {
  const Plan& plan = *plan_;
  reducer_.reset();
  out.eliminations.resize(placements.size());
  out.weights.resize(placements.size());
  out.blocks.resize(placements.size());
  out.products.resize(placements.size());
  out.own_weights.resize(weights ? placements.size() : 0);
  out.fresh = weights == nullptr;
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Artifact& artifact = artifactOf(plan, placements[j]);
    const Eigen::VectorXd c_j = artifactErrors(layout_, artifact, placements[j].artifact, state.c);
    ObservationBlock& block = out.blocks[j];
    builder_.build(artifact, placements[j].measurements, state.p, state.poses[j], c_j, true, block,
                   weights ? &weights->weights[j] : nullptr, &out.weights[j],
                   weights ? &out.own_weights[j] : nullptr);
    // Rank policy (docs/method.md section 5): only the rigid directions the measured features can
    // see are eliminated and stepped; noise must not make an unseen one look observed.
    reducer_.add(block, placements[j].artifact, &out.eliminations[j], rigid_caps_[j],
                 &out.products[j]);
  }
  return finishLinearization(state, out);
}

bool Calibrator::finishLinearization(const CalibrationState& state, Linearization& out) {
  const Plan& plan = *plan_;
  // The priors as whitened rows (docs/method.md section 3): on c, cost c^T Sigma_c^-1 c; on p,
  // (p - p0)^T Sigma_p0^-1 (p - p0) about the nominal values; gradient and curvature added.
  const Eigen::VectorXd prior_c = layout_.c_sigma.array().square().inverse();
  const Eigen::VectorXd offset_p =
      plan.machine.calibratedValues(state.p) - plan.machine.calibratedValues(plan.machine.nominal);
  const Eigen::VectorXd& prior_p = layout_.p_prior_weight;
  out.cost = reducer_.chi2() + state.c.dot(prior_c.asDiagonal() * state.c) +
             offset_p.dot(prior_p.asDiagonal() * offset_p);
  out.N = reducer_.normalWithPrior();
  out.b = reducer_.rhs();
  out.b.tail(layout_.systematicCount()) -= prior_c.asDiagonal() * state.c;
  out.b.head(layout_.parameters) -= prior_p.asDiagonal() * offset_p;
  out.rigid_reduction = 0.0;
  for (const PlacementElimination& e : out.eliminations) {
    out.rigid_reduction += e.g_r.dot(e.M_rr_pinv * e.g_r);
  }
  return std::isfinite(out.cost) && out.N.allFinite() && out.b.allFinite();
}

void Calibrator::step(const CalibrationState& from, const Linearization& at,
                      const Eigen::VectorXd& dg, const std::vector<Placement>& placements,
                      CalibrationState& to) const {
  const Machine& machine = plan_->machine;
  const int n_p = layout_.parameters;
  to.p = machine.withCalibrated(from.p, machine.calibratedValues(from.p) + dg.head(n_p));
  to.c = from.c + dg.tail(layout_.systematicCount());
  to.poses.resize(from.poses.size());
  for (std::size_t j = 0; j < placements.size(); ++j) {
    // Back-substitution of r_j for the global step (docs/method.md section 3).
    const Eigen::VectorXd dr = at.eliminations[j].rigidStep(dg);
    to.poses[j] =
        from.poses[j].perturbed(artifactOf(*plan_, placements[j]).expandFullRigidStep(dr));
  }
}

void Calibrator::extendStep(const Eigen::VectorXd& dg, const std::vector<Placement>& placements,
                            double& actual) {
  for (double scale = 2.0; scale <= kMaxExtension; scale *= 2.0) {
    step(current_, current_lin_, scale * dg, placements, extended_);
    if (!linearizeCapped(placements, extended_, extended_lin_, &current_lin_) ||
        !(extended_lin_.cost < trial_lin_.cost)) {
      return;
    }
    std::swap(trial_, extended_);
    std::swap(trial_lin_, extended_lin_);
    actual = current_lin_.cost - trial_lin_.cost;
  }
}

double Calibrator::stepInUncertainties(const Eigen::MatrixXd& N, const Eigen::VectorXd& dg) {
  // max_i |dg_i| / u_i with u the marginal standard uncertainties sqrt(diag N^-1): a step along a
  // weakly determined direction is judged against that direction's own u, not against the
  // conditional 1 / sqrt(N_ii) (a thousand times smaller in a valley, where Gauss-Newton on
  // large residuals creeps linearly). Without an inverse, the conditional ones.
  if (const auto covariance = covarianceFromInformation(N)) {
    return (dg.array() / covariance->u.array()).abs().maxCoeff();
  }
  return (dg.array() * N.diagonal().array().max(0.0).sqrt()).abs().maxCoeff();
}

double Calibrator::scatter(double cost) const {
  return dof_ > 0 && std::isfinite(cost) ? std::max(1.0, std::sqrt(cost / dof_)) : 1.0;
}

double Calibrator::negligible(double cost) const {
  // A cost change of s^2 is what moving s standard deviations along the best direction gives;
  // the standard deviations the readings show, not the stated ones (scatter), so that a noise
  // stated 20 times too small converges where the right one does.
  const double tolerance = options_.step_tolerance * scatter(cost);
  return std::max(options_.function_tolerance * cost, tolerance * tolerance);
}

int Calibrator::degreesOfFreedom(const std::vector<Placement>& placements) const {
  int dof = layout_.priorRows() - layout_.parameters;  // a prior is one row each
  for (const Placement& placement : placements) {
    const Artifact& artifact = artifactOf(*plan_, placement);
    dof += artifact.rowsPerReading() * static_cast<int>(placement.measurements.size());
  }
  for (const int rank : rigid_caps_) dof -= rank;  // effective N(r_j)
  return dof;
}

bool Calibrator::prepare(const std::vector<Placement>& placements, const CalibrationState& state) {
  current_ = state;
  const bool finite = linearize(placements, current_, current_lin_);
  prepared_of_ = &placements;
  prepared_probe_ = builder_.noise().probe;
  return finite;
}

bool Calibrator::prepareFrom(const Calibrator& other, const std::vector<int>& columns,
                             const std::vector<Placement>& placements) {
  const bool prepared = other.prepared_of_ == &placements && other.current_lin_.fresh &&
                        other.prepared_probe_ == builder_.noise().probe &&
                        other.current_lin_.blocks.size() == placements.size() &&
                        other.rigid_caps_.size() == placements.size() &&
                        static_cast<int>(columns.size()) == layout_.parameters;
  if (!prepared) return prepare(placements, other.current_);
  current_ = other.current_;
  rigid_caps_ = other.rigid_caps_;
  Linearization& out = current_lin_;
  out.blocks.resize(placements.size());
  out.weights = other.current_lin_.weights;
  out.own_weights.clear();
  out.eliminations.resize(placements.size());
  out.products.resize(placements.size());
  out.fresh = true;
  reducer_.reset();
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const ObservationBlock& from = other.current_lin_.blocks[j];
    ObservationBlock& block = out.blocks[j];
    block.A_p = from.A_p(Eigen::all, columns);
    block.A_r = from.A_r;
    block.rigid_primary = from.rigid_primary;
    block.A_c = from.A_c;
    block.e = from.e;
    reducer_.add(block, placements[j].artifact, &out.eliminations[j], rigid_caps_[j],
                 &out.products[j]);
  }
  prepared_of_ = &placements;
  prepared_probe_ = builder_.noise().probe;
  return finishLinearization(current_, out);
}

namespace {

// One reading's whitening factor: at most 6 x 6 (a pose; a point's 3 x 3 or fewer), on the stack.
using Factor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, 6>;

// Rows row..row + n of a column-major matrix <- T those rows, for a lower-triangular T of order
// n (1 to 6; K: n known at compile time, or Eigen::Dynamic), in place, column by column (each
// column's n entries contiguous): the last row first, the rows above it still unchanged.
template <int K, typename Triangle>
void transformRows(const Triangle& T, int n_rows, double* first, Eigen::Index stride,
                   Eigen::Index cols) {
  const int n = K == Eigen::Dynamic ? n_rows : K;
  for (Eigen::Index c = 0; c < cols; ++c) {
    double* x = first + c * stride;
    for (int i = n - 1; i >= 0; --i) {
      double v = x[i] * T(i, i);
      for (int j = 0; j < i; ++j) v += T(i, j) * x[j];
      x[i] = v;
    }
  }
}

// One placement's readings re-whitened (Calibrator::rewhiten): each reading's rows times
// T = L'^-1 L (`factors` the held L, replaced by the targets L'), K as in transformRows.
template <int K>
void rewhitenReadings(int per, std::vector<Eigen::Matrix<double, 6, 6>>& factors,
                      const std::vector<Eigen::Matrix<double, 6, 6>>& targets,
                      ObservationBlock& block) {
  using Triangle = std::conditional_t<K == Eigen::Dynamic, Factor, Eigen::Matrix<double, K, K>>;
  const int n = K == Eigen::Dynamic ? per : K;
  for (std::size_t i = 0; i < factors.size(); ++i) {
    const auto& held = factors[i];
    const auto& target = targets[i];
    // T = L'^-1 L, both lower-triangular: forward substitution, column by column.
    Triangle T(n, n);
    for (int c = 0; c < n; ++c) {
      for (int r = 0; r < c; ++r) T(r, c) = 0.0;
      for (int r = c; r < n; ++r) {
        double v = held(r, c);
        for (int j = c; j < r; ++j) v -= target(r, j) * T(j, c);
        T(r, c) = v / target(r, r);
      }
    }
    forEachPartAtRow(block, n * static_cast<int>(i), true,
                     [&](double* first, Eigen::Index stride, Eigen::Index cols) {
                       transformRows<K>(T, n, first, stride, cols);
                     });
    factors[i] = target;
  }
}

}  // namespace

bool Calibrator::reweightToProbe(const std::vector<Placement>& placements) {
  // Sigma = L L^T holds s_p^2 I over the point's rows once: with s_p changed,
  // Sigma' = L L^T + (s'^2 - s^2) I_point = L' L'^T (a pose's orientation rows: their share of
  // s_p^2, reading_noise.hpp, 0 unless the probe noise is estimated).
  const double shift =
      builder_.noise().probe * builder_.noise().probe - prepared_probe_ * prepared_probe_;
  std::vector<ReadingWeights> targets = current_lin_.weights;
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Artifact& artifact = artifactOf(*plan_, placements[j]);
    const int per = artifact.rowsPerReading(), k = artifact.valuedPerFeature();
    const double angle_share = angleVariancePerProbeVariance(builder_.noise().estimate_probe,
                                                             artifact.noise, artifact.noise_angle);
    for (auto& factor : targets[j].factors) {
      if (per == 3 && k == 3) {  // a point's 3 x 3: fixed-size, on the stack
        const Eigen::Matrix3d held = factor.topLeftCorner<3, 3>();
        Eigen::Matrix3d sigma = held * held.transpose();
        sigma.diagonal().array() += shift;
        factor.topLeftCorner<3, 3>() = Eigen::LLT<Eigen::Matrix3d>(sigma).matrixL();
        continue;
      }
      const Factor held = factor.topLeftCorner(per, per);
      Factor sigma = held * held.transpose();
      sigma.diagonal().head(k).array() += shift;
      sigma.diagonal().tail(per - k).array() += shift * angle_share;
      factor.topLeftCorner(per, per) = Eigen::LLT<Factor>(sigma).matrixL();
    }
  }
  prepared_probe_ = builder_.noise().probe;
  return rewhiten(placements, targets);
}

bool Calibrator::rewhiten(const std::vector<Placement>& placements,
                          const std::vector<ReadingWeights>& targets) {
  // A reading whitened with L has rows L^-1 A; with L' it has L'^-1 A = (L'^-1 L) L^-1 A
  // (design_matrix.cpp): the same block, re-whitened, without building it again.
  reducer_.reset();
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const int per = artifactOf(*plan_, placements[j]).rowsPerReading();
    ObservationBlock& block = current_lin_.blocks[j];
    auto& factors = current_lin_.weights[j].factors;
    const auto& own = targets[j].factors;
    withReadingRows(per, [&]<int K>() { rewhitenReadings<K>(per, factors, own, block); });
    reducer_.add(block, placements[j].artifact, &current_lin_.eliminations[j], rigid_caps_[j],
                 &current_lin_.products[j]);
  }
  current_lin_.fresh = true;
  return finishLinearization(current_, current_lin_);
}

bool Calibrator::isPrepared(const std::vector<Placement>& placements,
                            const CalibrationState& state) const {
  if (prepared_of_ != &placements || !current_lin_.fresh) return false;
  if (state.p != current_.p || state.c != current_.c) return false;
  if (state.poses.size() != current_.poses.size()) return false;
  for (std::size_t j = 0; j < state.poses.size(); ++j) {
    if (state.poses[j].R != current_.poses[j].R || state.poses[j].t != current_.poses[j].t) {
      return false;
    }
  }
  return rigid_caps_.size() == placements.size();
}

PlanInformation Calibrator::information(const std::vector<Placement>& placements) {
  // As planInformation (evaluator.cpp): every block reduced with its full rigid motion, the
  // readings' own information of p (no parameter prior); from the blocks' products, kept when
  // they were reduced.
  reducer_.reset();
  for (std::size_t j = 0; j < placements.size(); ++j) {
    reducer_.add(current_lin_.products[j], placements[j].artifact, -1);
  }
  PlanInformation out;
  out.reduced = reducer_.parameterInformation(ParameterPrior::Excluded);
  out.unreduced_diagonal = reducer_.unreducedDiagonal();
  out.rigid_ranks = reducer_.rigidRanks();
  out.poses = current_.poses;
  return out;
}

std::vector<ReadingMisfit> Calibrator::misfits(const std::vector<Placement>& placements) const {
  // As DesignMatrixBuilder::misfits: the point's residual and the known part of its covariance.
  // A pose's orientation rows enter when they carry a share c of s_p^2 (the probe noise
  // estimated, reading_noise.hpp): Sigma = E + s_p^2 D, D = diag(I, c I), and with the orientation
  // rows of the residual and of E scaled by 1/sqrt(c), Sigma becomes E' + s_p^2 I as for a point.
  const double probe2 = builder_.noise().probe * builder_.noise().probe;
  std::vector<ReadingMisfit> out;
  std::size_t readings = 0;
  for (const Placement& placement : placements) readings += placement.measurements.size();
  out.reserve(readings);
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Artifact& artifact = artifactOf(*plan_, placements[j]);
    const int per = artifact.rowsPerReading(), k = artifact.valuedPerFeature();
    const double angle_share = angleVariancePerProbeVariance(builder_.noise().estimate_probe,
                                                             artifact.noise, artifact.noise_angle);
    const int kept = angle_share > 0.0 ? per : k;
    Eigen::VectorXd unscale = Eigen::VectorXd::Ones(kept);
    if (kept > k) unscale.tail(kept - k).setConstant(1.0 / std::sqrt(angle_share));
    const ObservationBlock& block = current_lin_.blocks[j];
    const auto& factors = current_lin_.weights[j].factors;
    for (std::size_t i = 0; i < placements[j].measurements.size(); ++i) {
      if (per == 3 && k == 3) {  // a point's 3 x 3: fixed-size
        const Eigen::Matrix3d L = factors[i].topLeftCorner<3, 3>().triangularView<Eigen::Lower>();
        Eigen::Matrix3d sigma = L * L.transpose();
        sigma.diagonal().array() -= probe2;
        ReadingMisfit& misfit = out.emplace_back();
        misfit.residual = L * block.e.segment<3>(3 * static_cast<int>(i));
        misfit.encoder_covariance = sigma;
        continue;
      }
      const Factor L = factors[i].topLeftCorner(per, per).triangularView<Eigen::Lower>();
      // Sigma = s_p^2 D + (encoders and the instrument's own noise) = L L^T.
      Factor sigma = L * L.transpose();
      sigma.diagonal().head(k).array() -= probe2;
      sigma.diagonal().tail(per - k).array() -= probe2 * angle_share;
      ReadingMisfit misfit;
      misfit.residual =
          (L * block.e.segment(per * static_cast<int>(i), per)).head(kept).cwiseProduct(unscale);
      misfit.encoder_covariance =
          unscale.asDiagonal() * sigma.topLeftCorner(kept, kept) * unscale.asDiagonal();
      out.push_back(std::move(misfit));
    }
  }
  return out;
}

Calibration Calibrator::run(const std::vector<Placement>& placements) {
  return run(placements, plan_->machine.nominal);
}

Calibration Calibrator::run(const std::vector<Placement>& placements,
                            const Eigen::VectorXd& start) {
  return run(placements, initialState(placements, start));
}

Calibration Calibrator::run(const std::vector<Placement>& placements,
                            const CalibrationState& start) {
  Calibration out;
  CalibrationSummary& summary = out.summary;
  // From prepare()'s or the last run's own linearisation when it is at `start` (the probe noise
  // re-estimated: the same blocks re-weighted).
  const bool prepared = isPrepared(placements, start);
  const bool same_noise = prepared && prepared_probe_ == builder_.noise().probe;
  prepared_of_ = nullptr;
  if (!prepared) computeRigidCaps(placements);
  dof_ = degreesOfFreedom(placements);
  reweightings_ = 0;
  strategy_.reset();
  bool finite = true;
  if (same_noise) {
    finite = std::isfinite(current_lin_.cost) && current_lin_.N.allFinite() &&
             current_lin_.b.allFinite();
  } else if (prepared) {
    finite = reweightToProbe(placements);
  } else {
    current_ = start;
    finite = linearizeCapped(placements, current_, current_lin_);
  }
  summary.initial_cost = current_lin_.cost;
  if (!finite) {
    summary.termination = TerminationType::Failure;
    summary.message = "the problem is not finite at the starting values";
  } else {
    summary.termination = TerminationType::NoConvergence;
    summary.message = "max_iterations reached";
  }
  Eigen::VectorXd dg;
  for (int it = 1; finite && it <= options_.max_iterations; ++it) {
    summary.iterations = it;
    const bool solved = strategy_.computeStep(current_lin_.N, current_lin_.b, dg);
    const double scaled_step = solved ? stepInUncertainties(current_lin_.N, dg) : 0.0;
    // A tiny step only means convergence when the damping is not what made it tiny. Steps are
    // measured in the standard uncertainties the readings' scatter gives (scatter()).
    const double step_limit = options_.step_tolerance * scatter(current_lin_.cost);
    // The rigid poses are nuisance parameters: once steps have been taken, their own crawl (a
    // rigid fit of points with large residuals converges linearly) does not hold back a p that
    // no longer moves; before that they must have settled too.
    const bool poses_settled = current_lin_.rigid_reduction <= negligible(current_lin_.cost) ||
                               summary.accepted_steps >= kPoseCrawlSteps;
    if (solved && scaled_step < step_limit && poses_settled && strategy_.mu() <= 1.0) {
      if (settled(placements, finite)) {
        summary.termination = TerminationType::Converged;
        summary.message = "step below step_tolerance";
        break;
      }
      continue;
    }
    const double predicted = solved ? current_lin_.predictedReduction(dg) : 0.0;
    // The weights depend on p (docs/method.md section 2), so the reweighted Gauss-Newton fixed
    // point is where the linear model promises nothing more, not where the cost stops falling
    // exactly.
    if (solved && strategy_.mu() <= 1.0 && predicted <= negligible(current_lin_.cost)) {
      if (settled(placements, finite)) {
        summary.termination = TerminationType::Converged;
        summary.message = "predicted cost change negligible";
        break;
      }
      continue;
    }
    bool accepted = false;
    double actual = 0.0;
    if (solved && predicted > 0.0) {
      step(current_, current_lin_, dg, placements, trial_);
      // The trial's cost under the current weights (iteratively reweighted least squares).
      if (linearizeCapped(placements, trial_, trial_lin_, &current_lin_)) {
        actual = current_lin_.cost - trial_lin_.cost;
        accepted = actual > 0.0;
      }
    }
    if (!accepted) {
      // Rejected, yet neither the model's step nor the actual change exceeds what the cost can
      // resolve: a stationary point within rounding (the reweighted fixed point, where the model
      // omits dW/dp), which damping further cannot improve. Convergence, not failure.
      const double resolvable = negligible(current_lin_.cost);
      if (solved && predicted <= resolvable && std::abs(actual) <= resolvable) {
        if (settled(placements, finite)) {
          summary.termination = TerminationType::Converged;
          summary.message = "cost stationary within rounding";
          break;
        }
        continue;
      }
      strategy_.stepRejected();
      if (strategy_.exhausted()) {
        summary.termination = TerminationType::Failure;
        summary.message = "no step reduces the cost (damping exhausted)";
        break;
      }
      continue;
    }
    // Gauss-Newton on large residuals (model mismatch) can fall short along a valley: the cost
    // falls by more than the model promised. A line search along the same step then goes on
    // while it keeps falling (doubling), instead of crawling one short step per linearisation.
    if (actual > kExtendRatio * predicted && strategy_.mu() <= 1.0) {
      extendStep(dg, placements, actual);
    }
    const bool undamped = strategy_.mu() <= 1.0;  // a heavily damped step proves nothing
    strategy_.stepAccepted(actual / predicted);
    ++summary.accepted_steps;
    const double previous_cost = current_lin_.cost;
    std::swap(current_, trial_);
    std::swap(current_lin_, trial_lin_);
    if (undamped && actual <= negligible(previous_cost) && settled(placements, finite)) {
      summary.termination = TerminationType::Converged;
      summary.message = "cost change negligible";
      break;
    }
  }
  if (!finite && summary.termination == TerminationType::NoConvergence) {
    summary.termination = TerminationType::Failure;
    summary.message = "the problem became non-finite";
  }
  // The figures at the estimate's own weights.
  bool own = finite && current_lin_.fresh;
  if (finite && !current_lin_.fresh) own = linearizeCapped(placements, current_, current_lin_);
  if (own) {  // a run from the estimate (the noise re-estimated) starts from here
    prepared_of_ = &placements;
    prepared_probe_ = builder_.noise().probe;
  }
  summary.final_cost = current_lin_.cost;
  out.parameters = current_.p;
  out.systematic = current_.c;
  out.poses = current_.poses;
  out.chi2 = current_lin_.cost;
  out.dof = dof_;
  out.chi2_per_dof = out.dof > 0 && std::isfinite(out.chi2) ? out.chi2 / out.dof : 0.0;
  if (options_.details && finite) fillDetails(placements, out);
  return out;
}

namespace {

/// Leverages h_ii of a placement's rows in the full problem (g and every r_j), from the
/// covariance V of g (with the prior) and the placement's elimination: with
/// X = (A_r^T A_r)^+ A_r^T A_g, the row's leverage is
///   h = (a_g - a_r X) V (a_g - a_r X)^T + a_r (A_r^T A_r)^+ a_r^T.
Eigen::VectorXd leverages(const ObservationBlock& block, const PlacementElimination& elimination,
                          const Eigen::MatrixXd& V) {
  const int n_p = static_cast<int>(block.A_p.cols());
  const int n_g = static_cast<int>(elimination.columns.size());
  Eigen::MatrixXd A_g(block.rows(), n_g);
  A_g.leftCols(n_p) = block.A_p;
  A_g.rightCols(n_g - n_p) = block.A_c;
  Eigen::MatrixXd V_local(n_g, n_g);
  for (int a = 0; a < n_g; ++a) {
    for (int b = 0; b < n_g; ++b) V_local(a, b) = V(elimination.columns[a], elimination.columns[b]);
  }
  const Eigen::MatrixXd reduced = A_g - block.A_r * (elimination.M_rr_pinv * elimination.M_rg);
  return ((reduced * V_local).cwiseProduct(reduced).rowwise().sum() +
          (block.A_r * elimination.M_rr_pinv).cwiseProduct(block.A_r).rowwise().sum());
}

}  // namespace

void Calibrator::fillDetails(const std::vector<Placement>& placements, Calibration& out) {
  const Plan& plan = *plan_;
  reducer_.reset();
  out.residuals.clear();
  // The estimate's own linearisation (run() leaves it fresh at the estimate): its blocks.
  const std::vector<ObservationBlock>& blocks = current_lin_.blocks;
  std::vector<PlacementElimination> eliminations(placements.size());
  std::vector<Eigen::VectorXd> c(placements.size());
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Artifact& artifact = artifactOf(plan, placements[j]);
    c[j] = artifactErrors(layout_, artifact, placements[j].artifact, out.systematic);
    reducer_.add(blocks[j], placements[j].artifact, &eliminations[j], rigid_caps_[j]);
  }
  out.covariance = covarianceFromInformation(reducer_.parameterInformation());
  const auto global = covarianceFromInformation(reducer_.normalWithPrior());
  // Gross errors are judged against the scatter the fit shows, not only the stated noise: with
  // unmodelled errors every reading is 1.4 sigma wide, and 5 sigma of that is the test.
  const double gross_limit = options_.gross_threshold * std::max(1.0, out.birgeRatio());
  out.gross_limit = gross_limit;
  Eigen::VectorXd x;
  PlaneRows plane_rows;
  PlaneRowsScratch plane_scratch;
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Placement& placement = placements[j];
    const Artifact& artifact = artifactOf(plan, placement);
    const int k = artifact.valuedPerFeature();
    // Standardised residuals z / sqrt(1 - h): each has unit variance under the noise model.
    Eigen::VectorXd spread = Eigen::VectorXd::Ones(blocks[j].rows());
    if (global)
      spread = (1.0 - leverages(blocks[j], eliminations[j], global->V).array()).max(0.0).sqrt();
    for (std::size_t i = 0; i < placement.measurements.size(); ++i) {
      const Measurement& m = placement.measurements[i];
      forwardReadingOrThrow(plan.machine, out.parameters, m, x);
      ResidualEntry entry;
      entry.placement = static_cast<int>(j);
      entry.measurement = static_cast<int>(i);
      entry.feature = m.feature;
      if (artifact.kind().touches_faces) {  // the distance to its face (plane_rows.hpp)
        planeRows(artifact, plan.machine, out.parameters, m, out.poses[j], c[j], false, plane_rows,
                  plane_scratch);
        entry.residual = plane_rows.residual.head(1);
      } else {
        entry.residual = (out.poses[j].apply(x) - artifact.feature(m.feature, c[j])).head(k);
      }
      // A pose's rows: the point's, then the orientation's (each standardised).
      const int per = artifact.rowsPerReading();
      const int row = per * static_cast<int>(i);
      entry.standardized.resize(per);
      for (int r = 0; r < per; ++r) {
        // A row the fit absorbs (almost) entirely, 1 - h < 1e-3, cannot be tested: it reports 0
        // rather than a ratio of two rounding-level numbers.
        constexpr double kTestable = 0.0316;
        const double s = spread[row + r];
        entry.standardized[r] = s > kTestable ? blocks[j].e[row + r] / s : 0.0;
      }
      entry.score = entry.standardized.cwiseAbs().maxCoeff();
      entry.flagged = entry.score > options_.flag_threshold;
      entry.gross = entry.score > gross_limit;
      if (out.largest_residual < 0 || entry.score > out.residuals[out.largest_residual].score) {
        out.largest_residual = static_cast<int>(out.residuals.size());
      }
      out.residuals.push_back(std::move(entry));
    }
  }
}

Calibration calibratePlan(const Plan& plan, const CalibrationOptions& options) {
  Calibrator calibrator(plan, options);
  return calibrator.run(plan.placements);
}

}  // namespace artcal
