#pragma once
// Consistent readings (docs/method.md section 5, "Real readings"; machine-tools spec section 4):
// the readings the machine at parameters p would produce for the same layout. Measured readings
// of a machine off its nominal model do not fit the artifact at the nominal parameters: a feature
// read in several postures gives points some micrometres apart, a sphere's absorbed position no
// longer takes up a turn about the table's axis exactly, and a direction that no layout can
// separate keeps a sliver of information set by the misfit (a surviving fraction about 1e-8),
// not by the layout. The structural verdict (the "identifiable" set of check, evaluate, optimize
// and calibrate alike) is the one the same layout gives with consistent readings.
//
// Each reading is moved to the joints nearest it at which its residual vanishes at the
// placement's rigid fit r_j at p: Gauss-Newton on F(p, q) - W* = 0 in q with the residual's exact
// joint Jacobian J_q, the minimum-norm step dq = -J_q^T (J_q J_q^T)^-1 e (damped by 1e-12 of its
// trace where J_q J_q^T is singular). Readings that already fit (planned ones) move by rounding.
// A placement whose pose is not fitted to its readings' points (a plane's touches, which lie
// anywhere on its faces; a lone feature with a stated pose) keeps its readings: its pose is only a
// starting value.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "artcal/plan/plan.hpp"

namespace artcal {

/// Below this misfit (mm, or rad for a pose's orientation) a reading counts as consistent
/// already: its information differs from the consistent one's by a fraction of order
/// (misfit / reach)^2, far below every rank tolerance.
inline constexpr double kAlreadyConsistent = 1e-6;

/// `placements` with every reading moved to consistency with the machine at `p` (see above);
/// std::nullopt when every reading is consistent already (planned readings: nothing to move).
std::optional<std::vector<Placement>> consistentPlacements(const Plan& plan,
                                                           const std::vector<Placement>& placements,
                                                           const Eigen::VectorXd& p);

}  // namespace artcal
