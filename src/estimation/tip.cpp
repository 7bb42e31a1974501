#include "artcal/estimation/tip.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <stdexcept>
#include "artcal/core/dense_decompositions.hpp"

#include "artcal/core/linear_algebra.hpp"
#include "artcal/core/random.hpp"
#include "artcal/estimation/tip_kernel.hpp"
#include "artcal/model/inverse_kinematics.hpp"

namespace artcal {

namespace {

// Up to this many calibrated parameters the Gram matrices are prepared (21 parameters: 231
// numbers per configuration, 18.5 MB for 10,000 configurations).
constexpr int kGramMaxParameters = 40;
// A Gram entry whose spread over the workspace is below this (relative to its columns' scale)
// is a constant of the model: rounding, not geometry.
constexpr double kConstantGram = 1e-13;
// Factored form (tip.hpp): the basis is sought only with this many configurations per entry of
// vec(J_p) (it pays for itself on large workspaces), from a spread subset of twice that size;
// eigenvalues of the subset's scaled Gram below kFactorRank of the largest are rounding; every
// configuration must lie in the basis to kFactorResidual of its norm, or the form is not used.
constexpr int kFactorMinSamplesPerEntry = 4;
constexpr double kFactorRank = 1e-12;
constexpr double kFactorResidual = 1e-10;

}  // namespace

namespace {

// Opposite corners of the box that holds the region (its box, or the cube of its outer reach).
std::array<Eigen::VectorXd, 2> boundingBox(const Region& region, int dimension) {
  if (region.box) {
    const auto& [a, b] = *region.box;
    return {a.cwiseMin(b), a.cwiseMax(b)};
  }
  const double r = region.reach ? (*region.reach)[1] : 0.0;
  return {Eigen::VectorXd::Constant(dimension, -r), Eigen::VectorXd::Constant(dimension, r)};
}

// Forward kinematics at nominal works at q and puts the probe on `target` (a closed chain solved
// from home may fail, or assemble otherwise than its inverse kinematics assumed).
bool landsOn(const Machine& machine, const Eigen::VectorXd& q, const Eigen::VectorXd& target) {
  Eigen::VectorXd x;
  return machine.mechanism->forward(machine.nominal, q, x) == ForwardStatus::Ok &&
         (x - target).norm() <= 1e-6;
}

// docs/models.md section 5: probe positions uniform in the region, each in a random posture.
std::vector<Eigen::VectorXd> taskSpaceConfigurations(const Machine& machine,
                                                     const WorkspaceSpec& spec,
                                                     WorkspaceDrops& drops) {
  const int d = machine.dimension();
  const auto [lo, hi] = boundingBox(spec.region, d);
  std::mt19937_64 rng(spec.seed);
  IkOptions options;
  options.tilt = spec.tilt;
  std::vector<Eigen::VectorXd> out;
  out.reserve(static_cast<std::size_t>(spec.samples));
  constexpr long kTriesPerSample = 1000;  // an empty region ends the sampling, not the run
  long tries = 0;
  for (int s = 0; s < spec.samples && tries < kTriesPerSample * spec.samples;) {
    Eigen::VectorXd target(d);
    for (int i = 0; i < d; ++i) target[i] = lo[i] + (hi[i] - lo[i]) * unitUniform(rng);
    ++tries;
    if (!spec.region.contains(target)) continue;
    ++s;
    const auto postures = posturesFor(machine, machine.nominal, target, 1, rng, options);
    if (postures.empty()) {
      ++drops.unreachable;
    } else if (!landsOn(machine, postures.front(), target)) {
      ++drops.failed;
    } else {
      out.push_back(postures.front());
    }
  }
  return out;
}

// Drops (and counts) the configurations whose forward kinematics fails at nominal.
std::vector<Eigen::VectorXd> withWorkingForwardKinematics(const Machine& machine,
                                                          std::vector<Eigen::VectorXd> in,
                                                          WorkspaceDrops& drops) {
  std::vector<Eigen::VectorXd> out;
  out.reserve(in.size());
  Eigen::VectorXd x;
  for (Eigen::VectorXd& q : in) {
    if (machine.mechanism->forward(machine.nominal, q, x) == ForwardStatus::Ok && x.allFinite()) {
      out.push_back(std::move(q));
    } else {
      ++drops.failed;
    }
  }
  return out;
}

std::vector<Eigen::VectorXd> sampledConfigurations(const Machine& machine,
                                                   const WorkspaceSpec& spec,
                                                   WorkspaceDrops& drops) {
  const int n = machine.jointCount();
  std::vector<Eigen::VectorXd> out;
  switch (spec.kind) {
    case WorkspaceSpec::Kind::Configurations:
      return spec.configurations;
    case WorkspaceSpec::Kind::TaskSpace:
      return taskSpaceConfigurations(machine, spec, drops);
    case WorkspaceSpec::Kind::Samples: {
      std::mt19937_64 rng(spec.seed);
      out.reserve(static_cast<std::size_t>(spec.samples));
      for (int s = 0; s < spec.samples; ++s) {
        Eigen::VectorXd q(n);
        for (int i = 0; i < n; ++i) {
          const auto& [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
          q[i] = lo + (hi - lo) * unitUniform(rng);
        }
        out.push_back(q);
      }
      return out;
    }
    case WorkspaceSpec::Kind::Grid: {
      std::vector<int> index(static_cast<std::size_t>(n), 0);
      while (true) {
        Eigen::VectorXd q(n);
        for (int i = 0; i < n; ++i) {
          const auto& [lo, hi] = machine.joint_limits[static_cast<std::size_t>(i)];
          const int steps = spec.grid[static_cast<std::size_t>(i)];
          q[i] = steps == 1 ? 0.5 * (lo + hi)
                            : lo + (hi - lo) * index[static_cast<std::size_t>(i)] / (steps - 1);
        }
        out.push_back(q);
        int i = n - 1;  // odometer, last joint fastest
        while (i >= 0 &&
               ++index[static_cast<std::size_t>(i)] == spec.grid[static_cast<std::size_t>(i)]) {
          index[static_cast<std::size_t>(i)] = 0;
          --i;
        }
        if (i < 0) return out;
      }
    }
  }
  return out;
}

}  // namespace

std::vector<Eigen::VectorXd> workspaceSamples(const Machine& machine, const WorkspaceSpec& spec,
                                              WorkspaceDrops* drops) {
  WorkspaceDrops counted;
  auto out = sampledConfigurations(machine, spec, counted);
  if (drops) *drops = counted;
  return out;
}

std::vector<Eigen::VectorXd> workspaceConfigurations(const Machine& machine,
                                                     const WorkspaceSpec& spec,
                                                     WorkspaceDrops* drops) {
  WorkspaceDrops counted;
  auto out = workspaceSamples(machine, spec, &counted);
  // Task-space samples were checked one by one (landsOn).
  if (spec.kind != WorkspaceSpec::Kind::TaskSpace)
    out = withWorkingForwardKinematics(machine, std::move(out), counted);
  if (drops) *drops = counted;
  return out;
}

TipEvaluator::TipEvaluator(const Machine& machine, const Noise& noise,
                           std::vector<Eigen::VectorXd> configurations, int stylus, TipUse use)
    : TipEvaluator(machine, noise, std::move(configurations), std::vector<int>{}, stylus, use,
                   nullptr) {}

TipEvaluator::TipEvaluator(const Machine& machine, const Noise& noise,
                           std::vector<Eigen::VectorXd> configurations, std::vector<int> styluses,
                           TipUse use)
    : TipEvaluator(machine, noise, std::move(configurations), std::move(styluses), 0, use,
                   nullptr) {}

TipEvaluator TipEvaluator::ofSamples(const Machine& machine, const Noise& noise,
                                     std::vector<Eigen::VectorXd> samples, WorkspaceDrops& drops,
                                     TipUse use) {
  return {machine, noise, std::move(samples), {}, 0, use, &drops};
}

// `drops` given: configurations whose forward kinematics fails are left out and counted (the
// survivors moved forward in place); otherwise a failure is an error (forwardOrThrow).
TipEvaluator::TipEvaluator(const Machine& machine, const Noise& noise,
                           std::vector<Eigen::VectorXd> configurations, std::vector<int> styluses,
                           int stylus, TipUse use, WorkspaceDrops* drops)
    : dimension_(machine.dimension()),
      configurations_(std::move(configurations)),
      styluses_(std::move(styluses)) {
  // One stylus for all: filled here, after the configurations moved in (not copied for a count).
  if (styluses_.empty()) styluses_.assign(configurations_.size(), stylus);
  if (styluses_.size() != configurations_.size())
    throw std::logic_error("TipEvaluator: one stylus per configuration");
  const int n_p = machine.calibratedCount();
  const int count = size();
  J_p_.resize(dimension_ * count, n_p);
  S_q2_.resize(count);
  Eigen::VectorXd x;
  Eigen::MatrixXd J_x_p, J_x_q;
  const Eigen::VectorXd sigma_q2 = noise.encoder.array().square();
  int kept = 0;
  // A workspace configuration as a reading without payload: with compliance (docs/compliance.md)
  // its links' own weight deflects it, and the compliances' columns carry those torques.
  Measurement reading;
  for (int g = 0; g < count; ++g) {
    const auto at = static_cast<std::size_t>(g);
    reading.joints = configurations_[at];
    reading.stylus = styluses_[at];
    const ForwardStatus status =
        forwardReading(machine, machine.nominal, reading, x, &J_x_p, &J_x_q);
    if (!drops) {
      if (status != ForwardStatus::Ok) throw KinematicsError(forwardStatusName(status));
    } else if (status != ForwardStatus::Ok || !x.allFinite()) {
      ++drops->failed;
      continue;
    }
    if (kept != g) {
      configurations_[static_cast<std::size_t>(kept)] = std::move(configurations_[at]);
      styluses_[static_cast<std::size_t>(kept)] = styluses_[at];
    }
    for (int j = 0; j < n_p; ++j) {
      J_p_.block(kept * dimension_, j, dimension_, 1) = J_x_p.col(machine.calibrated[j]);
    }
    // tr(J_q Sigma_q J_q^T) = sum_j s_q,j^2 |J_q column j|^2
    S_q2_[kept] = (J_x_q.colwise().squaredNorm().transpose().array() * sigma_q2.array()).sum();
    ++kept;
  }
  if (kept < count) {
    configurations_.resize(static_cast<std::size_t>(kept));
    styluses_.resize(static_cast<std::size_t>(kept));
    J_p_.conservativeResize(dimension_ * kept, Eigen::NoChange);
    S_q2_.conservativeResize(kept);
  }
  if (use == TipUse::Repeated) prepareRepeated(n_p);
}

// The cheapest prepared form for this workspace (tip.hpp): Gram, factored or panels.
void TipEvaluator::prepareRepeated(int n_p) {
  if (n_p == 0) return;  // nothing calibrated: kinematicVariance answers 0 without a form
  const int count = size();
  if (n_p <= kGramMaxParameters) prepareGram(n_p);
  const long per_configuration = gram_constant_.size() > 0
                                     ? static_cast<long>(gram_rows_.size())
                                     : static_cast<long>(dimension_) * n_p * n_p;
  const bool factored = prepareFactored(n_p, per_configuration);
  // The Gram matrices only while they are less data than J_p itself (tip.hpp).
  const bool blocked = !factored && count > 0 && kTipPanelRows % dimension_ == 0 &&
                       per_configuration > static_cast<long>(dimension_) * n_p;
  if (factored || blocked) {
    gram_.resize(0, 0);
    gram_rows_.clear();
    gram_constant_.resize(0);
  }
  if (blocked) preparePanels(n_p);
}

std::vector<int> TipEvaluator::movingParameters() const {
  std::vector<int> out;
  for (int k = 0; k < J_p_.cols(); ++k)
    if (J_p_.col(k).squaredNorm() > 0.0) out.push_back(k);
  return out;
}

void TipEvaluator::preparePanels(int n_p) {
  const int rows = dimension_ * size();
  panel_count_ = (rows + kTipPanelRows - 1) / kTipPanelRows;
  const long panel_size = static_cast<long>(n_p) * kTipPanelRows;
  panels_.assign(static_cast<std::size_t>(panel_count_ * panel_size), 0.0);
  for (int row = 0; row < rows; ++row) {
    double* panel = panels_.data() + (row / kTipPanelRows) * panel_size + row % kTipPanelRows;
    for (int a = 0; a < n_p; ++a) panel[static_cast<long>(a) * kTipPanelRows] = J_p_(row, a);
  }
  row_squares_.resize(static_cast<std::size_t>(panel_count_) * kTipPanelRows);
}

// The factored form (tip.hpp): vec(J_g), entry (row, parameter a) at a * dimension + row, scaled
// per entry; an orthonormal basis U of their span from the eigenvectors of a subset's Gram; then
// c_g = U^T vec(J_g) for every configuration, checked: |vec(J_g) - U c_g| within kFactorResidual.
// Kept when r^2 operations per configuration beat `cost_to_beat`.
bool TipEvaluator::prepareFactored(int n_p, long cost_to_beat) {
  const int m = dimension_ * n_p;
  const int count = size();
  if (m == 0 || count < kFactorMinSamplesPerEntry * m) return false;
  const auto vecJ = [&](int g) { return J_p_.middleRows(g * dimension_, dimension_).reshaped(); };
  const int subset = 2 * m;
  Eigen::MatrixXd Y(m, subset);
  for (int k = 0; k < subset; ++k) {
    Y.col(k) = vecJ(static_cast<int>(static_cast<long>(k) * count / subset));
  }
  Eigen::VectorXd scale = Y.rowwise().norm() / std::sqrt(static_cast<double>(subset));
  for (double& s : scale) s = s > 0.0 ? s : 1.0;
  Y = scale.cwiseInverse().asDiagonal() * Y;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(m, m);
  K.selfadjointView<Eigen::Lower>().rankUpdate(Y);
  const SymmetricEigenSolver eig(K);
  if (eig.info() != Eigen::Success) return false;
  const Eigen::VectorXd& lambda = eig.eigenvalues();  // ascending
  const int r = static_cast<int>((lambda.array() > kFactorRank * lambda[m - 1]).count());
  if (static_cast<long>(r) * r >= cost_to_beat) return false;
  const Eigen::MatrixXd U = eig.eigenvectors().rightCols(r);
  const double floor = 1e-3 * Y.colwise().norm().maxCoeff();
  Eigen::MatrixXd C(r, count);
  Eigen::VectorXd y(m);
  for (int g = 0; g < count; ++g) {
    y = scale.cwiseInverse().asDiagonal() * vecJ(g);
    C.col(g).noalias() = U.transpose() * y;
    const double residual = (y - U * C.col(g)).norm();
    if (!(residual <= kFactorResidual * std::max(y.norm(), floor))) return false;
  }
  factor_coefficients_ = std::move(C);
  factor_rows_.assign(static_cast<std::size_t>(dimension_), Eigen::MatrixXd(r, n_p));
  for (int row = 0; row < dimension_; ++row) {
    for (int a = 0; a < n_p; ++a) {
      const int e = a * dimension_ + row;
      factor_rows_[static_cast<std::size_t>(row)].col(a) = scale[e] * U.row(e).transpose();
    }
  }
  return true;
}

// S_m^2 = tr(J V J^T) with J = sum_i c_i B_i: c^T W c, W_ii' = sum_rows B_i,row V B_i',row^T.
void TipEvaluator::factoredVariance(const Eigen::MatrixXd& V_p, Eigen::VectorXd& S_m2) const {
  const Eigen::Index r = factor_coefficients_.rows();
  factor_W_.setZero(r, r);
  for (const Eigen::MatrixXd& B : factor_rows_) factor_W_.noalias() += B * V_p * B.transpose();
  factor_WC_.noalias() = factor_W_ * factor_coefficients_;
  S_m2 = factor_coefficients_.cwiseProduct(factor_WC_).colwise().sum().transpose();
}

// Column g: the lower triangle of J_g^T J_g column by column, off-diagonal entries doubled, so
// that tr(V J_g^T J_g) = column . (lower triangle of V). Entries equal over the whole workspace
// (a serial arm's |z_i|^2 = 1, z_i . x_(i+1) = 0, the probe block R^T R = I: about a fifth of
// them) are kept once, and the per-evaluation product runs over the others only.
void TipEvaluator::prepareGram(int n_p) {
  const int entries = n_p * (n_p + 1) / 2;
  gram_constant_.setZero(entries);
  gram_rows_.clear();
  if (size() == 0) {  // nothing to evaluate: every entry "constant" (no max over no samples)
    gram_.resize(0, 0);
    return;
  }
  Eigen::MatrixXd full(entries, size());
  for (int g = 0; g < size(); ++g) {
    const auto J = J_p_.middleRows(g * dimension_, dimension_);
    int k = 0;
    for (int b = 0; b < n_p; ++b) {
      for (int a = b; a < n_p; ++a) full(k++, g) = (a == b ? 1.0 : 2.0) * J.col(a).dot(J.col(b));
    }
  }
  const Eigen::VectorXd column_scale = J_p_.colwise().norm() / std::sqrt(std::max(size(), 1));
  int k = 0;
  for (int b = 0; b < n_p; ++b) {
    for (int a = b; a < n_p; ++a, ++k) {
      const double spread = full.row(k).maxCoeff() - full.row(k).minCoeff();
      if (size() > 1 && spread <= kConstantGram * column_scale[a] * column_scale[b]) {
        gram_constant_[k] = full.row(k).mean();
      } else {
        gram_rows_.push_back(k);
      }
    }
  }
  gram_ = full(gram_rows_, Eigen::all);
}

namespace {

// A square root L of a covariance (V = L L^T): Cholesky, lower triangular (`lower` set), or
// the symmetric root when V is only semi-definite.
Eigen::MatrixXd covarianceRoot(const Eigen::MatrixXd& V, bool& lower) {
  const Eigen::LLT<Eigen::MatrixXd> llt(V);
  lower = llt.info() == Eigen::Success;
  if (lower) return llt.matrixL();
  const SymmetricEigenSolver eig(V);
  return eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
}

}  // namespace

void TipEvaluator::kinematicVariance(const Eigen::MatrixXd& V_p, Eigen::VectorXd& S_m2) const {
  if (J_p_.cols() == 0) {  // nothing calibrated: no kinematic part (and no product of width 0)
    S_m2.setZero(size());
    return;
  }
  // S_m^2 = tr(J V J^T) = |J L|_F^2 with V = L L^T: one product over the whole workspace, with a
  // triangular L (half the work of a full one).
  if (factor_coefficients_.size() > 0) {
    factoredVariance(V_p, S_m2);
    return;
  }
  if (gram_constant_.size() > 0) {
    const int n_p = static_cast<int>(V_p.rows());
    packed_V_.resize(gram_constant_.size());
    int k = 0;
    for (int b = 0; b < n_p; ++b) {
      packed_V_.segment(k, n_p - b) = V_p.col(b).tail(n_p - b);
      k += n_p - b;
    }
    packed_varying_ = packed_V_(gram_rows_);
    S_m2.noalias() = gram_.transpose() * packed_varying_;
    S_m2.array() += gram_constant_.dot(packed_V_);
    return;
  }
  bool lower = false;
  const Eigen::MatrixXd L = covarianceRoot(V_p, lower);
  if (!panels_.empty()) {
    tipKernelRowSquares(panels_.data(), panel_count_, static_cast<int>(L.rows()), L.data(), lower,
                        row_squares_.data());
    S_m2.resize(size());
    const double* squares = row_squares_.data();
    for (int g = 0; g < size(); ++g, squares += dimension_) {
      double sum = 0.0;
      for (int r = 0; r < dimension_; ++r) sum += squares[r];
      S_m2[g] = sum;
    }
    return;
  }
  // J_p L a chunk of configurations at a time, each chunk's product made and consumed in cache
  // (no workspace-sized scratch); row g * dimension + r is tip coordinate r at configuration g.
  constexpr int kChunk = 512;
  S_m2.resize(size());
  for (int first = 0; first < size(); first += kChunk) {
    const int count = std::min(kChunk, size() - first);
    const auto J = J_p_.middleRows(first * dimension_, count * dimension_);
    if (lower) {
      scratch_.noalias() = J * L.triangularView<Eigen::Lower>();
    } else {
      scratch_.noalias() = J * L;
    }
    S_m2.segment(first, count) =
        scratch_.rowwise().squaredNorm().reshaped(dimension_, count).colwise().sum().transpose();
  }
}

TipSummary TipEvaluator::summarize(const Eigen::MatrixXd& V_p) const {
  kinematicVariance(V_p, S_m2_);
  return summarizeVariance(S_m2_);
}

TipSummary TipEvaluator::summarizeVariance(const Eigen::VectorXd& S_m2) const {
  TipSummary summary;
  double sum = 0.0, sum2 = 0.0, worst = -1.0;
  for (int g = 0; g < size(); ++g) {
    const double total2 = S_m2[g] + S_q2_[g];
    sum += std::sqrt(total2);
    sum2 += total2;
    if (total2 > worst) {
      worst = total2;
      summary.worst_index = g;
    }
  }
  if (size() > 0) {
    const int w = summary.worst_index;
    summary.worst = {std::sqrt(worst), std::sqrt(S_m2[w]), std::sqrt(S_q2_[w])};
    summary.mean = sum / size();
    summary.rms = std::sqrt(sum2 / size());
  }
  return summary;
}

TipPoint TipEvaluator::at(int configuration, const Eigen::MatrixXd& V_p) const {
  const auto J = J_p_.middleRows(configuration * dimension_, dimension_);
  const double S_m2 = (J * V_p * J.transpose()).trace();
  const double S_q2 = S_q2_[configuration];
  return {std::sqrt(S_m2 + S_q2), std::sqrt(S_m2), std::sqrt(S_q2)};
}

TipPoint tipUncertainty(const Machine& machine, const Noise& noise, const Eigen::VectorXd& q,
                        const Eigen::MatrixXd& V_p) {
  return TipEvaluator(machine, noise, {q}).at(0, V_p);
}

std::vector<ProfilePoint> reachProfile(const Machine& machine, const Noise& noise,
                                       const Eigen::MatrixXd& V_p, int steps) {
  std::vector<ProfilePoint> profile;
  const Mechanism& mech = *machine.mechanism;
  const auto range = mech.reachRange(machine.nominal);
  if (!range || steps < 2) return profile;
  const auto [inner, outer] = *range;
  for (int s = 0; s < steps; ++s) {
    const double reach = inner + (outer - inner) * s / (steps - 1);
    std::optional<TipPoint> worst;
    for (const Eigen::VectorXd& q :
         mech.configurationsAtReach(machine.nominal, reach, machine.joint_limits)) {
      const TipPoint tip = tipUncertainty(machine, noise, q, V_p);
      if (!worst || tip.total > worst->total) worst = tip;
    }
    if (worst) profile.push_back({reach, *worst});
  }
  return profile;
}

}  // namespace artcal
