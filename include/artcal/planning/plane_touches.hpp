#pragma once
// Planned touches of a plane artifact (docs/planes.md): `count` readings of one face, each at a
// point drawn within the face's extent, reached in a posture drawn by the posture generator and,
// for a flush contact, moved by the least joint motion until the tip frame lies flush on the face
// (touchPlane, estimation/plane_rows.hpp) with its tool axis pointing into the face.

#include <random>
#include <vector>

#include "artcal/artifact/rigid_transform.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// Up to `count` touches of face `face` of `artifact` placed at `placed` (artifact from machine)
/// by `reading_machine` at its nominal parameters, within its joint limits, each by tip (stylus)
/// `stylus` (-1: the first).
std::vector<Measurement> planeTouches(const Machine& reading_machine, const Artifact& artifact,
                                      const RigidTransform& placed, int face, int count,
                                      std::mt19937_64& rng, int stylus = -1);

}  // namespace artcal
