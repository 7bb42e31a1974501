#pragma once
// Plausibility of a parsed plan's readings at the input edge (docs/hardening.md, "Plausibility"):
// a plan whose numbers are valid JSON and valid types can still be wrong in ways that give
// confident nonsense (readings in radians, a machine in metres, a pose metres away). These checks
// raise InputError naming the placement and what to check; an honest plan never trips them.
//
// For each placement with readings, at the nominal parameters (or, for `verify --machine`, at
// the machine verified):
//   collapse      the mean probed positions of the measured balls must spread at least half as
//                 far from their centre as the balls themselves: wrong units (readings in radians
//                 read as degrees, a machine in metres) collapse them, however far off nominal
//                 the machine is;
//   fit residual  the readings' probe positions f(p, q) are fitted rigidly onto the artifact's
//                 features (Kabsch/Umeyama, the calibrator's starting r_j); the RMS length of the
//                 residual vectors (valued coordinates) must stay within
//                     T = max(100 s_p, 1 mm, 0.25 d_art, 0.05 R),
//                 d_art the RMS distance of the artifact's features from their centroid and R the
//                 farthest the plan's readings probe from the machine's origin. Real robots are
//                 10-30 mm off their nominal model (the MUKCa Gen3 lite: 10.4 mm RMS at one tool
//                 position; 5 % of a 0.8 m reach is 40 mm); readings whose angles are read in the
//                 wrong unit scatter over the machine's whole reach.
//   pose          when a `pose` is given, the mean probed position of each measured feature,
//                 taken into the pose's artifact frame, must lie within max(T, 10 mm) of the
//                 feature (valued coordinates): a pose is informational, but one that disagrees
//                 with the readings says that one of them is wrong.

#include <string>

#include "artcal/plan/plan.hpp"

namespace artcal {

/// The fit-residual threshold T of `artifact` for probe noise `probe_sigma` and a machine that
/// probes within `reach` of its origin (mm).
double plausibleResidual(const Artifact& artifact, double probe_sigma, double reach);

/// InputError (file: plan.source, pointer: the placement) when a placement's readings fail the
/// checks above. Placements whose readings the nominal machine cannot evaluate are left alone.
void checkPlausibility(const Plan& plan);
/// The same checks with the machine at parameters `p` (full vector, internal units): `verify
/// --machine` checks the readings against the machine it verifies.
/// `machine` names it in messages ("the calibrated machine").
void checkPlausibility(const Plan& plan, const Eigen::VectorXd& p, const std::string& machine);
/// `verify --machine`: the readings pass when the machine verified or the plan's nominal machine
/// passes the checks. Either one fitting them rules out what the checks are for (units, feature
/// indices, a tip that is not the ball); a calibration that fits them worse than any machine error
/// (one tool position extrapolated across the workspace) is verify's finding, not bad input. When
/// both fail, the error is the machine verified's.
void checkPlausibilityOfVerified(const Plan& plan, const Eigen::VectorXd& p,
                                 const std::string& machine);

}  // namespace artcal
