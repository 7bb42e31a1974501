#pragma once
// A plane artifact's observation rows (docs/planes.md), the one place they are formed: the
// design matrix whitens them, the simulator solves them for the joints that touch the true
// plane, the calibrator and verify report them.
//   point contact, 1 row:  e = W_a - (o + s rho),         W = R_r f(p, q) + t_r
//   flush contact, 3 rows: e = (W_a - o, v_b, v_c),        v = R_r R(p, q) z_tool
// a: the face's normal axis (artifact frame), o its offset, s its outward sign, rho the ball's
// radius; b, c the other two axes (v_b, v_c: the tilts, rad, between the tool axis and the
// normal). Exact derivatives: de/dp = R_r J_x_p (distance), e_b^T R_r (-[R z]x) J_w_p (tilts);
// likewise in q; rigid step exp(delta): distance row e_a^T [I | -[W]x], tilt rows e_b^T [0 |
// -[v]x].

#include <Eigen/Core>
#include <optional>

#include "artcal/artifact/artifact.hpp"
#include "artcal/artifact/rigid_transform.hpp"
#include "artcal/model/machine.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// One reading's rows, unwhitened (rows() = 1 or 3; only the leading rows are meaningful).
struct PlaneRows {
  int rows = 1;
  Eigen::VectorXd residual;  ///< e = F - W* (mm, then rad)
  Eigen::MatrixXd J_p;       ///< rows x the calibrated parameters
  Eigen::MatrixXd J_q;       ///< rows x joints
  Eigen::MatrixXd J_r;       ///< rows x the full rigid motion, in Artifact::fullRigidOrder()
};

/// Scratch for planeRows, so that repeated calls do not allocate.
struct PlaneRowsScratch {
  Eigen::VectorXd x;
  Eigen::Matrix3d R_tip;
  Eigen::MatrixXd J_x_p, J_x_q, J_w_p, J_w_q;
};

/// The rows of reading `m` of plane artifact `artifact` at parameters p (full vector), placement
/// r and systematic errors c (may be empty); `with_jacobians` false: the residual only.
void planeRows(const Artifact& artifact, const Machine& machine, const Eigen::VectorXd& p,
               const Measurement& m, const RigidTransform& r, const Eigen::VectorXd& c,
               bool with_jacobians, PlaneRows& out, PlaneRowsScratch& scratch);

/// The machine-frame point and tip orientation at which the machine with parameters p touches
/// face `feature` of the placed plane (R_r, t_r) nearest to where joints q put it: the joints
/// that make every row of reading m zero (plus `offsets`, the drawn noise of each row), by
/// minimum-norm Gauss-Newton from q, steps capped at 0.1 rad (mm) per joint. A flush touch has
/// the tool axis pointing into the face (one more row: its component along the normal). `at`
/// (artifact frame): the touch also keeps that point's two in-plane coordinates (planning a
/// touch of a small face). std::nullopt when it does not converge.
std::optional<Eigen::VectorXd> touchPlane(const Artifact& artifact, const Machine& machine,
                                          const Eigen::VectorXd& p, const Measurement& m,
                                          const RigidTransform& r, const Eigen::VectorXd& c,
                                          const Eigen::VectorXd& offsets,
                                          const std::optional<Eigen::Vector3d>& at = std::nullopt);

/// Where a single plane stood (a placement without a "pose", docs/planes.md), from its touches
/// at parameters p: flush touches give the outward normal (minus their mean tool axis) and a
/// point (their mean tip origin); point touches the least-squares plane through the ball centres
/// (at least 3, not on one line), moved in by the radius, its outward side the one the tool axis
/// comes from (or, for a machine with no orientation, the machine origin's side). The in-plane
/// position and turn are gauges (N(r) = 3): roll 0. std::nullopt for a shape other than a single
/// plane, a 2-D machine, or touches that fix no plane.
std::optional<Pose> planePoseFromTouches(const Artifact& artifact, const Machine& machine,
                                         const Eigen::VectorXd& p,
                                         const std::vector<Measurement>& touches);

}  // namespace artcal
