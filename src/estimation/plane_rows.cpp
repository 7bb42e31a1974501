#include "artcal/estimation/plane_rows.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <optional>
#include "artcal/core/dense_decompositions.hpp"

#include "artcal/core/error.hpp"
#include "artcal/model/frame_turns.hpp"

namespace artcal {

namespace {

// A table-spindle ball bar's row (five-axis.md section 3): e = |W| - (length + c), W the spindle
// ball in the table ball's frame (translations only); de = n^T dW, n = W / |W|.
void tableBallRow(const Artifact& artifact, const Machine& machine, const Eigen::VectorXd& W,
                  const RigidTransform& r, const Eigen::VectorXd& c, bool with_jacobians,
                  PlaneRows& out, PlaneRowsScratch& s) {
  const double distance = W.norm();
  out.residual[0] = distance - (artifact.plane.length + artifact.feature(0, c)[0]);
  if (!with_jacobians) return;
  if (!(distance > 0.0))
    throw KinematicsError("the spindle's ball is at the table ball's centre: no bar direction");
  const Eigen::VectorXd n = r.R.transpose() * (W / distance);  // machine frame
  const int n_p = machine.calibratedCount();
  out.J_p.resize(1, n_p);
  for (int j = 0; j < n_p; ++j) out.J_p(0, j) = n.dot(s.J_x_p.col(machine.calibrated[j]));
  out.J_q = n.transpose() * s.J_x_q;
  out.J_r.setZero(1, artifact.fullRigidDof());
  out.J_r.row(0) = (W / distance).transpose();  // the three translations
}

// Where a table-spindle ball bar's table ball sits: the centre w of the sphere of radius L
// through the spindle ball's points x_i, by linear least squares on |x_i|^2 - 2 x_i.w + k = L^2
// (k = |w|^2, then w from the solve; at least 4 points not on one plane or circle).
std::optional<Pose> tableBallFromReadings(const Machine& machine, const Eigen::VectorXd& p,
                                          double length, const std::vector<Measurement>& readings) {
  const auto n = static_cast<int>(readings.size());
  if (n < 4) return std::nullopt;
  Eigen::MatrixXd A(n, 4);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) {
    const Measurement& m = readings[static_cast<std::size_t>(i)];
    Eigen::VectorXd x;
    if (forwardReading(machine, p, m, x) != ForwardStatus::Ok) return std::nullopt;
    A.row(i) << 2.0 * x[0], 2.0 * x[1], 2.0 * x[2], -1.0;
    b[i] = x.head<3>().squaredNorm() - length * length;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd s = svd.singularValues();
  if (!(s[3] > 1e-9 * s[0])) return std::nullopt;
  const Eigen::Vector4d solution = svd.solve(b);
  Pose pose;
  pose.center = solution.head<3>();
  return pose;
}

}  // namespace

void planeRows(const Artifact& artifact, const Machine& machine, const Eigen::VectorXd& p,
               const Measurement& m, const RigidTransform& r, const Eigen::VectorXd& c,
               bool with_jacobians, PlaneRows& out, PlaneRowsScratch& s) {
  const PlaneGeometry& plane = artifact.plane;
  const PlaneFace& face = plane.faces.at(static_cast<std::size_t>(m.feature));
  const int a = face.axis;
  const int n_p = machine.calibratedCount();
  const int n_r = artifact.fullRigidDof();
  out.rows = plane.flush ? 3 : 1;
  out.residual.resize(out.rows);
  Eigen::MatrixXd* J_x_p = with_jacobians ? &s.J_x_p : nullptr;
  Eigen::MatrixXd* J_x_q = with_jacobians ? &s.J_x_q : nullptr;
  if (plane.flush) {
    forwardReadingPoseOrThrow(machine, p, m, s.x, s.R_tip, J_x_p, J_x_q,
                              with_jacobians ? &s.J_w_p : nullptr,
                              with_jacobians ? &s.J_w_q : nullptr);
  } else {
    forwardReadingOrThrow(machine, p, m, s.x, J_x_p, J_x_q);
  }
  const Eigen::VectorXd W = r.apply(s.x);
  if (plane.shape == PlaneShape::TableBall) {
    tableBallRow(artifact, machine, W, r, c, with_jacobians, out, s);
    return;
  }
  // The distance row: the valued coordinate against the face's feature (its systematic error).
  out.residual[0] = W[a] - artifact.feature(m.feature, c)[a];
  Eigen::Vector3d u = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
  const int b = (a + 1) % 3, bc = (a + 2) % 3;
  if (plane.flush) {
    u = s.R_tip * plane.tool_axis;  // machine frame
    v = r.R * u;                    // artifact frame
    out.residual[1] = v[b];
    out.residual[2] = v[bc];
  }
  if (!with_jacobians) return;
  out.J_p.resize(out.rows, n_p);
  out.J_q.resize(out.rows, s.J_x_q.cols());
  out.J_r.setZero(out.rows, n_r);
  const Eigen::VectorXd R_a = r.R.row(a).transpose();
  for (int j = 0; j < n_p; ++j) out.J_p(0, j) = R_a.dot(s.J_x_p.col(machine.calibrated[j]));
  out.J_q.row(0).noalias() = R_a.transpose() * s.J_x_q;
  artifact.fullRigidJacobian(W, out.J_r.topRows(1), m.feature);
  if (!plane.flush) return;
  // d(R z) = w x (R z) for a turn w of the tip frame: -[u]x w; then into the artifact frame.
  const Eigen::Matrix3d turn = -r.R * skew(u);  // dv/dw
  Eigen::Matrix<double, 2, 3> tilt_rows;
  tilt_rows.row(0) = turn.row(b);
  tilt_rows.row(1) = turn.row(bc);
  for (int j = 0; j < n_p; ++j)
    out.J_p.block<2, 1>(1, j).noalias() = tilt_rows * s.J_w_p.col(machine.calibrated[j]);
  out.J_q.bottomRows(2).noalias() = tilt_rows * s.J_w_q;
  // A rigid step exp(delta) turns v by delta's rotation: dv/dw_i = e_i x v; translation: 0.
  const std::vector<int>& order = artifact.fullRigidOrder();
  for (std::size_t col = 0; col < order.size(); ++col) {
    const int direction = order[col];
    if (direction < 3) continue;
    const Eigen::Vector3d column = Eigen::Vector3d::Unit(direction - 3).cross(v);
    out.J_r(1, static_cast<int>(col)) = column[b];
    out.J_r(2, static_cast<int>(col)) = column[bc];
  }
}

std::optional<Eigen::VectorXd> touchPlane(const Artifact& artifact, const Machine& machine,
                                          const Eigen::VectorXd& p, const Measurement& m,
                                          const RigidTransform& r, const Eigen::VectorXd& c,
                                          const Eigen::VectorXd& offsets,
                                          const std::optional<Eigen::Vector3d>& at) {
  // The joint Jacobian of the rows does not depend on which parameters are calibrated: a
  // machine with none calibrated gives J_q alone.
  Machine joints_only = machine;
  joints_only.calibrated.clear();
  Measurement reading = m;
  PlaneRows rows;
  PlaneRowsScratch scratch;
  const PlaneGeometry& plane = artifact.plane;
  const PlaneFace& face = plane.faces.at(static_cast<std::size_t>(m.feature));
  // A flush touch has one more row: the tool axis's component along the face's normal against
  // the one the tilts leave, pointing into the face. The two tilt rows alone are zero with the
  // tool pointing out of the material too, and flat (their Jacobian loses rank) where the tool
  // lies along the face; with this row the cost |v - v*|^2 has one minimum on the sphere.
  double into_face = 0.0;
  if (plane.flush) {
    const double tilt2 =
        offsets.size() >= 3 ? offsets[1] * offsets[1] + offsets[2] * offsets[2] : 0.0;
    into_face = -face.sign * std::sqrt(std::max(0.0, 1.0 - tilt2));
  }
  // Steps of at most kLargestStep (rad or mm) per joint: a full Newton step from a tilted tool can
  // swing the arm far round (and out of its limits) before it settles.
  constexpr double kLargestStep = 0.1;
  Eigen::VectorXd e;
  Eigen::MatrixXd J;
  for (int iteration = 0; iteration < 200; ++iteration) {
    planeRows(artifact, joints_only, p, reading, r, c, true, rows, scratch);
    const int n = rows.rows + (plane.flush ? 1 : 0) + (at ? 2 : 0);
    e.resize(n);
    J.resize(n, rows.J_q.cols());
    e.head(rows.rows) = rows.residual - offsets.head(rows.rows);
    J.topRows(rows.rows) = rows.J_q;
    if (plane.flush) {
      const Eigen::Vector3d u = scratch.R_tip * plane.tool_axis;
      const Eigen::Vector3d v = r.R * u;
      e[rows.rows] = v[face.axis] - into_face;
      J.row(rows.rows) = (-r.R * skew(u)).row(face.axis) * scratch.J_w_q;
    }
    if (at) {  // the touch's place on the face: its two in-plane coordinates
      const Eigen::Vector3d W = r.apply(scratch.x);
      for (int k = 1; k <= 2; ++k) {
        const int axis = (face.axis + k) % 3;
        e[n - 3 + k] = W[axis] - (*at)[axis];
        J.row(n - 3 + k) = r.R.row(axis) * scratch.J_x_q;
      }
    }
    if (e.cwiseAbs().maxCoeff() < 1e-12) return reading.joints;
    // Minimum-norm step, damped (the direction rows have rank 2): J^T (J J^T + mu I)^-1 e.
    Eigen::MatrixXd JJt = J * J.transpose();
    JJt.diagonal().array() += 1e-12 * std::max(JJt.trace(), 1e-300);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(JJt);
    if (ldlt.info() != Eigen::Success) return std::nullopt;
    Eigen::VectorXd step = J.transpose() * ldlt.solve(e);
    if (!step.allFinite()) return std::nullopt;
    const double largest = step.cwiseAbs().maxCoeff();
    if (largest > kLargestStep) step *= kLargestStep / largest;
    reading.joints -= step;
  }
  planeRows(artifact, joints_only, p, reading, r, c, false, rows, scratch);
  if ((rows.residual - offsets.head(rows.rows)).cwiseAbs().maxCoeff() < 1e-9) return reading.joints;
  return std::nullopt;
}

std::optional<Pose> planePoseFromTouches(const Artifact& artifact, const Machine& machine,
                                         const Eigen::VectorXd& p,
                                         const std::vector<Measurement>& touches) {
  const PlaneGeometry& plane = artifact.plane;
  if (plane.shape == PlaneShape::TableBall && machine.dimension() == 3)
    return tableBallFromReadings(machine, p, plane.length, touches);
  if (plane.shape != PlaneShape::Single || machine.dimension() != 3 || touches.empty())
    return std::nullopt;
  const Mechanism& mech = *machine.mechanism;
  const auto n = static_cast<int>(touches.size());
  Eigen::Matrix3Xd points(3, n);
  Eigen::Vector3d axis_sum = Eigen::Vector3d::Zero();
  const bool oriented = mech.hasOrientation();
  if (plane.flush && !oriented) return std::nullopt;
  for (int i = 0; i < n; ++i) {
    const Measurement& m = touches[static_cast<std::size_t>(i)];
    Eigen::VectorXd x;
    Eigen::Matrix3d R;
    const ForwardStatus status = oriented ? mech.forwardStylusPose(m.stylus, p, m.joints, x, R)
                                          : mech.forwardStylus(m.stylus, p, m.joints, x);
    if (status != ForwardStatus::Ok) return std::nullopt;
    if (oriented) axis_sum += R * plane.tool_axis;
    points.col(i) = x.head<3>();
  }
  const Eigen::Vector3d centroid = points.rowwise().mean();
  Pose pose;
  pose.center = centroid;
  if (plane.flush) {                                     // the tool axis points into the face
    if (axis_sum.norm() < 0.5 * n) return std::nullopt;  // axes that do not agree on a normal
    pose.direction = -axis_sum.normalized();
    return pose;
  }
  if (n < 3) return std::nullopt;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(points.colwise() - centroid, Eigen::ComputeFullU);
  const Eigen::Vector3d s = svd.singularValues();
  if (!(s[1] > 1e-6 * s[0])) return std::nullopt;  // on one line (or one point)
  Eigen::Vector3d normal = svd.matrixU().col(2);
  const Eigen::Vector3d outward =
      oriented ? Eigen::Vector3d(-axis_sum) : Eigen::Vector3d(-centroid);
  if (normal.dot(outward) < 0.0) normal = -normal;
  pose.direction = normal;
  pose.center = centroid - plane.radius * normal;  // the ball centres sit rho out
  return pose;
}

}  // namespace artcal
