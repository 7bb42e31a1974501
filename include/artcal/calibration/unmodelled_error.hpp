#pragma once
// The error the model does not explain, estimated by cross-validation (docs/method.md section 6,
// "Predictions that carry the unmodelled error"). The noise estimate and V_p describe readings
// that scatter about the model; a real machine also has errors the model cannot take (gear and
// elastic errors, an artifact's or a tool's own), which the fit partly absorbs into its
// parameters: its training residuals are then smaller than its errors on new readings. The
// readings are split into folds, the calibration is repeated on all but one (the kept set and the
// noise model as decided), and the left-out readings are scored as verify scores held-out ones:
//   observed  o_k = sum |d_i|^2 over fold k's readings,
//   predicted b_k + c_k s_u^2, b_k from the fold's V_p and noise (posterior), c_k the same formula
//             with Sigma_i = I on each point's coordinates (verification.hpp),
// and s_u^2 = max(0, sum_k (o_k - b_k) / sum_k c_k): the variance per coordinate of a point that
// makes the pooled prediction equal the pooled observation. Folds (chosen to mirror what verify
// scores):
// - "placements": three or more placements of calibrated artifacts, each left out in turn (a new
//   placement of the artifact, re-registered), in at most kMaxUnmodelledFolds groups;
// - "regions": fewer placements: each placement's postures split into kUnmodelledFolds slabs
//   along the first principal direction of their joint readings (a region of the workspace the
//   fit did not see);
// - "readings": an instrument's stations: every kUnmodelledFolds-th reading (new readings of the
//   same station, the station re-registered on them).
// Plain data; calibrateReadings fills it (estimateUnmodelledError, calibrate_readings.hpp).

#include <optional>
#include <string>

#include "artcal/estimation/evaluation_result.hpp"

namespace artcal {

inline constexpr int kUnmodelledFolds = 5;
inline constexpr int kMaxUnmodelledFolds = 10;

struct UnmodelledError {
  double sigma = 0.0;          ///< s_u, mm per coordinate of a point
  std::string scheme;          ///< "placements", "regions" or "readings"
  int folds = 0;               ///< folds whose calibration converged and were scored
  int readings = 0;            ///< readings scored over those folds
  double observed_rms = 0.0;   ///< mm, sqrt(sum o_k / readings)
  double predicted_rms = 0.0;  ///< mm, sqrt(sum b_k / readings): V_p and the noise alone
};

/// The tip uncertainty of the calibrated machine with the unmodelled error (issue 43): at each
/// configuration of the workspace S_u^2 = S^2 + d s_u^2, S the evaluation's S (the parameters'
/// and the encoders' terms, tip.hpp) and d s_u^2 the trace of s_u^2 I over the point's d
/// coordinates (pose_acceptance.hpp's sigma_unmodelled for d = 3). The unmodelled term is the
/// same everywhere: it shifts the map, it does not move its worst point.
struct TipWithUnmodelled {
  double sigma = 0.0;        ///< s_u, mm per coordinate
  double trace_share = 0.0;  ///< sqrt(d) s_u, mm
  double worst_total = 0.0;  ///< S_u at the evaluation's worst configuration, mm
  double mean_total = 0.0;   ///< mean of S_u over the workspace, mm
  double rms_total = 0.0;    ///< sqrt(mean of S_u^2), mm
};

/// S_u over `evaluation`'s workspace (its tip summary and workspace_total) for s_u = `sigma` (mm)
/// and points of `dimension` coordinates; std::nullopt when the evaluation has no tip map.
std::optional<TipWithUnmodelled> tipWithUnmodelled(const Evaluation& evaluation, double sigma,
                                                   int dimension);

}  // namespace artcal
