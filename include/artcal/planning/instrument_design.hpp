#pragma once
// Planning an instrument session (instruments.md, "Planning an instrument calibration"): which
// configurations a laser tracker or total station should measure the machine in, and how many.
//
// The candidates are joint configurations (uniform within the limits narrowed by the design's
// joint margin, or task-space samples of its region: the workspace sampler,
// workspaceConfigurations). Each candidate's whitened observation rows [A_p | A_r] are built
// once at the nominal parameters (DesignMatrixBuilder, the station at the machine frame: a
// station's information does not depend on where it stands). A station's information over
// (p, r) is the sum of its readings' terms; its r is eliminated by the Schur complement (the
// rank policy's pseudo-inverse, normal_matrix.hpp), and the stations' reduced terms add up with
// the spec's fixed placements. The criterion is the optimizer's (DesignCriterion: worst-case tip
// uncertainty G by default, "D" the D-optimal one).
//
// Search, per start (seeded by (seed, start) alone, so the result does not depend on threads):
// a random design of `readings` distinct candidates per station, then a Fedorov exchange: each
// reading in turn is swapped for the best of a random subset of the candidates (ranked by the
// active-set bound for G, each choice confirmed by the full criterion, as optimizer.cpp does),
// until a pass improves nothing. The best start wins (ties: the lower index). Seeded starts come
// first: the sweep's design for one reading fewer (completed greedily), and for the criterion G
// the D-optimal design of the same pool and options, so that the G choice is never worse in G
// than the D choice a user compares it with.

#include <Eigen/Core>
#include <vector>

#include "artcal/plan/plan.hpp"
#include "artcal/planning/optimizer.hpp"

namespace artcal {

/// The candidate configurations of `spec`'s instrument design (internal units). InputError at
/// /design/region when the region yields none.
std::vector<Eigen::VectorXd> instrumentCandidates(const Plan& spec);

/// Chooses `design.placements` stations x `readings` configurations minimising the criterion.
/// `start_design` (optional: the sweep's design for one reading fewer) seeds start 0: its
/// readings are kept and each station completed greedily, so the result is never worse.
/// Starts: max(options.starts, seeded starts).
OptimizerSummary optimizeInstrumentDesign(const Plan& spec, const OptimizerOptions& options,
                                          const std::vector<Placement>* start_design = nullptr);

/// Appends designed placements to `plan`: an instrument reading's point (the nominal tip when
/// the design gave none) becomes a feature of its instrument, as the plan reader does.
void appendDesignedPlacements(Plan& plan, const std::vector<Placement>& designed);

}  // namespace artcal
