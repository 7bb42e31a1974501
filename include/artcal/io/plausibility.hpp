#pragma once
// Plausibility of a parsed plan's readings at the input edge (docs/hardening.md, "Plausibility"):
// a plan whose numbers are valid JSON and valid types can still be wrong in ways that give
// confident nonsense (readings in radians, a machine in metres, a pose metres away). These checks
// raise InputError naming the placement and what to check; an honest plan never trips them.
//
// For each placement with readings, at the nominal parameters:
//   fit residual  the readings' probe positions f(p0, q) are fitted rigidly onto the artifact's
//                 features (Kabsch/Umeyama, the calibrator's starting r_j); the RMS length of the
//                 residual vectors (valued coordinates) must stay within
//                     T = max(100 s_p, 1 mm, 0.25 d_art),
//                 d_art the RMS distance of the artifact's features from their centroid. Wrong
//                 units collapse or distort the points by the artifact's own size (residual
//                 ~ d_art); an uncalibrated real machine errs by millimetres (tests/data/mukca:
//                 ~8 mm on a Panda), far below a quarter of any artifact worth calibrating with.
//   pose          when a `pose` is given, the mean probed position of each measured feature,
//                 taken into the pose's artifact frame, must lie within max(T, 10 mm) of the
//                 feature (valued coordinates): a pose is informational, but one that disagrees
//                 with the readings says that one of them is wrong.

#include "artcal/plan/plan.hpp"

namespace artcal {

/// The fit-residual threshold T of `artifact` for probe noise `probe_sigma` (mm).
double plausibleResidual(const Artifact& artifact, double probe_sigma);

/// InputError (file: plan.source, pointer: the placement) when a placement's readings fail the
/// checks above. Placements whose readings the nominal machine cannot evaluate are left alone.
void checkPlausibility(const Plan& plan);

}  // namespace artcal
