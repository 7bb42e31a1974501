#include "artcal/calibration/unmodelled_error.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <vector>
#include "artcal/core/dense_decompositions.hpp"

#include "artcal/calibration/calibrate_readings.hpp"
#include "artcal/calibration/station_verification.hpp"
#include "artcal/calibration/verification.hpp"
#include "artcal/core/error.hpp"

namespace artcal {

namespace {

/// Which readings of each placement a fold leaves out.
using FoldMask = std::vector<std::vector<bool>>;  // [placement][reading]: left out

const Artifact& artifactOf(const Plan& plan, const Placement& placement) {
  return plan.artifacts[static_cast<std::size_t>(placement.artifact)];
}

bool scoredArtifact(const Artifact& artifact) {
  return !artifact.kind().touches_faces && !artifact.kind().readings_are_features;
}

FoldMask emptyMask(const Plan& plan) {
  FoldMask mask;
  for (const Placement& placement : plan.placements)
    mask.emplace_back(placement.measurements.size(), false);
  return mask;
}

/// Each placement of a calibrated artifact left out in turn, in at most kMaxUnmodelledFolds
/// groups (placement k in group k mod folds).
std::vector<FoldMask> placementFolds(const Plan& plan, const std::vector<int>& scored) {
  const int folds = std::min<int>(static_cast<int>(scored.size()), kMaxUnmodelledFolds);
  std::vector<FoldMask> out(static_cast<std::size_t>(folds), emptyMask(plan));
  for (std::size_t k = 0; k < scored.size(); ++k) {
    auto& mask = out[k % static_cast<std::size_t>(folds)][static_cast<std::size_t>(scored[k])];
    std::fill(mask.begin(), mask.end(), true);
  }
  return out;
}

/// A placement's readings ordered along the first principal direction of their joint readings
/// (each joint scaled by its spread), so that consecutive slabs are regions of the workspace.
std::vector<int> alongPrincipalDirection(const Placement& placement) {
  const auto n = static_cast<int>(placement.measurements.size());
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  if (n < 2) return order;
  const auto joints = static_cast<int>(placement.measurements.front().joints.size());
  Eigen::MatrixXd Q(n, joints);
  for (int i = 0; i < n; ++i) Q.row(i) = placement.measurements[static_cast<std::size_t>(i)].joints;
  Q.rowwise() -= Q.colwise().mean();
  for (int c = 0; c < joints; ++c) {
    const double spread = Q.col(c).norm();
    if (spread > 0.0) Q.col(c) /= spread;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(Q.transpose() * Q);
  const Eigen::VectorXd score = Q * eigen.eigenvectors().col(joints - 1);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return score[a] < score[b]; });
  return order;
}

/// Each placement's readings in kUnmodelledFolds folds: slabs along the principal direction
/// (regions) or every kUnmodelledFolds-th reading (an instrument's stations).
std::vector<FoldMask> readingFolds(const Plan& plan, bool regions) {
  std::vector<FoldMask> out(static_cast<std::size_t>(kUnmodelledFolds), emptyMask(plan));
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const Placement& placement = plan.placements[j];
    const auto n = static_cast<int>(placement.measurements.size());
    if (!artifactOf(plan, placement).kind().readings_are_features &&
        !scoredArtifact(artifactOf(plan, placement)))
      continue;  // a plane's touches stay in every fold's training
    const std::vector<int> order = regions ? alongPrincipalDirection(placement) : [n] {
      std::vector<int> all(static_cast<std::size_t>(n));
      std::iota(all.begin(), all.end(), 0);
      return all;
    }();
    for (int rank = 0; rank < n; ++rank) {
      const int fold = regions ? rank * kUnmodelledFolds / n : rank % kUnmodelledFolds;
      out[static_cast<std::size_t>(fold)][j][static_cast<std::size_t>(order[rank])] = true;
    }
  }
  return out;
}

/// The plan's readings the fold leaves out (`left_out`, re-registered on themselves: no reading
/// marked for stationing) or trains on; placements left empty are dropped; the calibrated set as
/// decided, listed (no rank rule runs again).
Plan foldPlan(const Plan& decided, const FoldMask& mask, bool left_out) {
  Plan out = decided;
  out.placements.clear();
  out.machine.calibrate_identifiable = false;
  out.calibrate_resolution.reset();
  for (std::size_t j = 0; j < decided.placements.size(); ++j) {
    Placement placement = decided.placements[j];
    placement.measurements.clear();
    for (std::size_t i = 0; i < decided.placements[j].measurements.size(); ++i) {
      if (mask[j][i] != left_out) continue;
      placement.measurements.push_back(decided.placements[j].measurements[i]);
      if (left_out) placement.measurements.back().stationing = false;
    }
    if (!placement.measurements.empty()) out.placements.push_back(std::move(placement));
  }
  return out;
}

/// A fold's sums: observed, predicted (V_p and noise) and per unit s_u^2, over `readings`.
struct FoldSums {
  double observed = 0.0, base = 0.0, per_unit = 0.0;
  int readings = 0;
};

double squares(double rms, int count) {
  return rms * rms * count;
}

/// The left-out readings scored as verify scores them, with the fold's calibration.
std::optional<FoldSums> scoreFold(const Plan& held, const CalibrationRun& fold) {
  auto uncertainty = fold.calibration.uncertainty(fold.decided.machine);
  if (!uncertainty) return std::nullopt;
  uncertainty->unmodelled = 1.0;  // the unmodelled shares are then per unit s_u^2
  const Eigen::VectorXd& p = fold.calibration.parameters;
  FoldSums sums;
  bool stations = false, artifacts = false;
  for (const Placement& placement : held.placements) {
    const Artifact& artifact = artifactOf(held, placement);
    stations = stations || artifact.kind().readings_are_features;
    artifacts = artifacts || scoredArtifact(artifact);
  }
  if (artifacts) {
    const Verification v = verifyMachine(held, p, uncertainty);
    int readings = 0;
    for (const PlacementVerification& placement : v.placements) {
      if (!scoredArtifact(
              artifactOf(held, held.placements[static_cast<std::size_t>(placement.index)])))
        continue;
      for (const FeatureSpread& f : placement.features) {
        readings += f.postures;
        sums.observed += squares(f.spread_rms, f.postures);
        sums.base += squares(
            basePrediction(f.predicted_spread_rms, f.predicted_spread_rms_posterior), f.postures);
        sums.per_unit += squares(f.predicted_spread_rms_unmodelled, f.postures);
      }
    }
    sums.readings += readings;
  }
  if (stations) {
    const StationsVerification v = verifyStations(held, p, uncertainty);
    const DeviationSummary& all = v.all;
    sums.readings += all.count;
    sums.observed += squares(all.rms, all.count);
    sums.base += squares(basePrediction(all.predicted_rms, all.predicted_rms_posterior), all.count);
    sums.per_unit += squares(all.predicted_rms_unmodelled, all.count);
  }
  if (sums.readings == 0) return std::nullopt;
  return sums;
}

}  // namespace

std::optional<UnmodelledError> estimateUnmodelledError(const CalibrationRun& run,
                                                       const CalibrationOptions& options) {
  const Plan& decided = run.decided;
  std::vector<int> scored;
  bool stations = false;
  for (std::size_t j = 0; j < decided.placements.size(); ++j) {
    const Artifact& artifact = artifactOf(decided, decided.placements[j]);
    if (scoredArtifact(artifact)) scored.push_back(static_cast<int>(j));
    stations = stations || artifact.kind().readings_are_features;
  }
  if (scored.empty() && !stations) return std::nullopt;
  UnmodelledError out;
  std::vector<FoldMask> folds;
  if (!stations && scored.size() >= 3) {
    out.scheme = "placements";
    folds = placementFolds(decided, scored);
  } else {
    out.scheme = stations ? "readings" : "regions";
    folds = readingFolds(decided, !stations);
  }
  CalibrationOptions fold_options = options;
  fold_options.cross_validation = false;
  fold_options.details = true;
  FoldSums pooled;
  for (const FoldMask& mask : folds) {
    try {
      const Plan training = foldPlan(decided, mask, false);
      const Plan held = foldPlan(decided, mask, true);
      if (held.placements.empty()) continue;
      const CalibrationRun fold = calibrateReadings(training, fold_options);
      if (!fold.calibration.summary.converged()) continue;
      Plan scored_plan = held;
      scored_plan.noise = fold.decided.noise;
      const auto sums = scoreFold(scored_plan, fold);
      if (!sums) continue;
      pooled.observed += sums->observed;
      pooled.base += sums->base;
      pooled.per_unit += sums->per_unit;
      pooled.readings += sums->readings;
      ++out.folds;
    } catch (const std::runtime_error&) {
      continue;  // a fold that cannot be calibrated (a direction only the left-out readings see)
    }
  }
  if (out.folds < 2 || pooled.readings == 0 || !(pooled.per_unit > 0.0)) return std::nullopt;
  out.readings = pooled.readings;
  out.observed_rms = std::sqrt(pooled.observed / pooled.readings);
  out.predicted_rms = std::sqrt(pooled.base / pooled.readings);
  out.sigma = std::sqrt(std::max(0.0, (pooled.observed - pooled.base) / pooled.per_unit));
  return out;
}

std::optional<TipWithUnmodelled> tipWithUnmodelled(const Evaluation& evaluation, double sigma,
                                                   int dimension) {
  if (!evaluation.tip || evaluation.workspace_total.empty()) return std::nullopt;
  TipWithUnmodelled out;
  out.sigma = sigma;
  const double share2 = dimension * sigma * sigma;
  out.trace_share = std::sqrt(share2);
  const double worst = evaluation.tip->worst.total;
  out.worst_total = std::sqrt(worst * worst + share2);
  double sum = 0.0, sum2 = 0.0;
  for (const double s : evaluation.workspace_total) {
    sum += std::sqrt(s * s + share2);
    sum2 += s * s + share2;
  }
  const double n = static_cast<double>(evaluation.workspace_total.size());
  out.mean_total = sum / n;
  out.rms_total = std::sqrt(sum2 / n);
  return out;
}

}  // namespace artcal
