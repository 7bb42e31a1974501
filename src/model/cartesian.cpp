#include "artcal/model/cartesian.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <stdexcept>

#include "artcal/model/frame_turns.hpp"

namespace artcal {

namespace {

// Degrees and axes are small: the per-call scratch lives on the stack.
constexpr int kMaxDegree = 12;
constexpr int kMaxAxes = 6;

// exp([w]) and the right Jacobian J_r(w) of SO(3): exp([w + dw]) = exp([w]) exp([J_r(w) dw]) to
// first order, J_r = I - (1 - cos t)/t^2 [w] + (t - sin t)/t^3 [w]^2 (t = |w|). Series below
// t = 1e-4, where the closed form loses digits (errors of a CMM axis are ~1e-5 rad).
void expAndRightJacobian(const Eigen::Vector3d& w, Eigen::Matrix3d& R, Eigen::Matrix3d& J_r) {
  const double t2 = w.squaredNorm();
  const Eigen::Matrix3d W = skew(w);
  const Eigen::Matrix3d W2 = W * W;
  double a, b, c;  // R = I + a W + b W^2, J_r = I - b W + c W^2
  if (t2 < 1e-8) {
    a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0;
    b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
    c = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
  } else {
    const double t = std::sqrt(t2);
    a = std::sin(t) / t;
    b = (1.0 - std::cos(t)) / t2;
    c = (t - std::sin(t)) / (t2 * t);
  }
  R = Eigen::Matrix3d::Identity() + a * W + b * W2;
  J_r = Eigen::Matrix3d::Identity() - b * W + c * W2;
}

}  // namespace

std::string axisErrorName(AxisError error) {
  return nameOf(kAxisErrorNames, error);
}

std::string axisErrorMeaning(const Eigen::Vector3d& direction, AxisError error) {
  // Along the axis: positioning (translation) and roll (rotation); across it: straightness in
  // the other direction and pitch / yaw (ISO 230-1). Pitch turns about the horizontal axis
  // perpendicular to the motion, yaw about the vertical one; for the vertical axis (ram) the two
  // are the rotations about x and y.
  const int e = static_cast<int>(error);
  const int coordinate = e % 3;
  const char* names = "xyz";
  int along = 0;
  direction.cwiseAbs().maxCoeff(&along);
  if (e < 3) {
    if (coordinate == along) return "positioning";
    return std::string("straightness in ") + names[coordinate];
  }
  if (coordinate == along) return "roll";
  if (along == 2) return std::string("tilt about ") + names[coordinate];
  if (coordinate == 2) return "yaw";
  return "pitch";
}

void legendre(int degree, double s, double* P, double* dP) {
  P[0] = 1.0;
  dP[0] = 0.0;
  if (degree >= 1) {
    P[1] = s;
    dP[1] = 1.0;
  }
  // (n + 1) P_{n+1} = (2n + 1) s P_n - n P_{n-1};  P'_{n+1} = (n + 1) P_n + s P'_n.
  for (int n = 1; n < degree; ++n) {
    P[n + 1] = ((2.0 * n + 1.0) * s * P[n] - n * P[n - 1]) / (n + 1.0);
    dP[n + 1] = (n + 1.0) * P[n] + s * dP[n];
  }
}

Cartesian::Cartesian(std::vector<CartesianAxis> axes, int degree,
                     std::vector<Eigen::Vector3d> styli)
    : axes_(std::move(axes)), degree_(degree), styli_(std::move(styli)) {
  if (axes_.empty() || axes_.size() > static_cast<std::size_t>(kMaxAxes)) {
    throw std::invalid_argument("cartesian: 1 to " + std::to_string(kMaxAxes) + " axes");
  }
  if (degree_ < 1 || degree_ > kMaxDegree) {
    throw std::invalid_argument("cartesian: degree 1 to " + std::to_string(kMaxDegree));
  }
  if (styli_.empty()) throw std::invalid_argument("cartesian: at least one stylus");
  for (const CartesianAxis& axis : axes_) {
    if (!(axis.range[0] < axis.range[1])) {
      throw std::invalid_argument("cartesian: axis " + axis.name + " range must be increasing");
    }
    for (int n = 1; n <= degree_; ++n) {
      for (int e = 0; e < kAxisErrorCount; ++e) {
        const bool rotation = e >= 3;
        parameters_.push_back(
            {axis.name + "." + axisErrorName(static_cast<AxisError>(e)) + "." + std::to_string(n),
             rotation ? kMicrometrePerMetre : Quantity::Length});
      }
    }
  }
}

double Cartesian::normalised(int axis, double u) const {
  const auto [lo, hi] = axes_[static_cast<std::size_t>(axis)].range;
  return (2.0 * u - (lo + hi)) / (hi - lo);
}

ForwardStatus Cartesian::forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                 Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p,
                                 Eigen::MatrixXd* J_x_q) const {
  return forwardStylus(0, p, q, x, J_x_p, J_x_q);
}

// x = sum_k C_{k-1} t_k + C_n s, with t_k = direction_k u_k + delta_k(u_k), R_k = exp([eps_k]),
// C_k = R_1 ... R_k. With v_k = t_k + R_k v_{k+1} (v_{n+1} = s) the point in frame k-1:
//   dx / d delta_k = C_{k-1},   dx / d eps_k = -C_{k-1} R_k [v_{k+1}] J_r(eps_k) =: G_k,
// so a coefficient of degree n moves x by C_{k-1} e_i P_n(s_k) (translations) or G_k e_i P_n(s_k)
// (rotations), and dx/du_k = C_{k-1} (direction_k + delta_k') + G_k eps_k', primes d/du.
ForwardStatus Cartesian::forwardStylus(int stylus, const Eigen::VectorXd& p,
                                       const Eigen::VectorXd& q, Eigen::VectorXd& x,
                                       Eigen::MatrixXd* J_x_p, Eigen::MatrixXd* J_x_q) const {
  const int n = jointCount();
  const int m = degree_ + 1;
  std::array<double, kMaxAxes*(kMaxDegree + 1)> P{}, dP{};
  std::array<Eigen::Vector3d, kMaxAxes> t, dt_du, deps_du;
  std::array<Eigen::Matrix3d, kMaxAxes> R, J_r;
  for (int k = 0; k < n; ++k) {
    const CartesianAxis& axis = axes_[static_cast<std::size_t>(k)];
    const double s = normalised(k, q[k]);
    const double ds_du = 2.0 / (axis.range[1] - axis.range[0]);
    double* Pk = P.data() + k * m;
    double* dPk = dP.data() + k * m;
    legendre(degree_, s, Pk, dPk);
    Eigen::Vector3d delta = Eigen::Vector3d::Zero(), eps = Eigen::Vector3d::Zero();
    Eigen::Vector3d ddelta = Eigen::Vector3d::Zero(), deps = Eigen::Vector3d::Zero();
    for (int d = 1; d <= degree_; ++d) {
      const auto c = p.segment<kAxisErrorCount>(parameterIndex(k, AxisError::Tx, d));
      delta += Pk[d] * c.head<3>();
      eps += Pk[d] * c.tail<3>();
      ddelta += (dPk[d] * ds_du) * c.head<3>();
      deps += (dPk[d] * ds_du) * c.tail<3>();
    }
    t[k] = axis.direction * q[k] + delta;
    dt_du[k] = axis.direction + ddelta;
    deps_du[k] = deps;
    expAndRightJacobian(eps, R[k], J_r[k]);
  }
  // v_{k+1} from the probe back to the base; C_{k-1} from the base forward.
  std::array<Eigen::Vector3d, kMaxAxes + 1> v;
  v[n] = styli_[static_cast<std::size_t>(stylus)];
  for (int k = n - 1; k >= 0; --k) v[k] = t[k] + R[k] * v[k + 1];
  x = v[0];
  if (!J_x_p && !J_x_q) return ForwardStatus::Ok;
  if (J_x_p) J_x_p->resize(3, parameterCount());
  if (J_x_q) J_x_q->resize(3, n);
  Eigen::Matrix3d C = Eigen::Matrix3d::Identity();
  for (int k = 0; k < n; ++k) {
    const Eigen::Matrix3d G = -C * R[k] * skew(v[k + 1]) * J_r[k];
    if (J_x_p) {
      const double* Pk = P.data() + k * m;
      for (int d = 1; d <= degree_; ++d) {
        const int first = parameterIndex(k, AxisError::Tx, d);
        J_x_p->middleCols<3>(first) = Pk[d] * C;
        J_x_p->middleCols<3>(first + 3) = Pk[d] * G;
      }
    }
    if (J_x_q) J_x_q->col(k) = C * dt_du[k] + G * deps_du[k];
    C = C * R[k];
  }
  return ForwardStatus::Ok;
}

std::vector<Eigen::VectorXd> Cartesian::closedFormInverse(const Eigen::VectorXd& p,
                                                          const Eigen::VectorXd& target,
                                                          int stylus) const {
  if (auto u = inverse(p, target.head<3>(), stylus)) return {*u};
  return {};
}

std::optional<Eigen::VectorXd> Cartesian::nominalInverse(const Eigen::Vector3d& target,
                                                         int stylus) const {
  if (jointCount() != 3) return std::nullopt;
  Eigen::Matrix3d D;
  for (int k = 0; k < 3; ++k) D.col(k) = axes_[static_cast<std::size_t>(k)].direction;
  Eigen::FullPivLU<Eigen::Matrix3d> lu(D);
  if (!lu.isInvertible()) return std::nullopt;
  return Eigen::VectorXd(lu.solve(target - styli_[static_cast<std::size_t>(stylus)]));
}

std::optional<Eigen::VectorXd> Cartesian::inverse(const Eigen::VectorXd& p,
                                                  const Eigen::Vector3d& target, int stylus,
                                                  double tolerance) const {
  auto u = nominalInverse(target, stylus);
  if (!u) return std::nullopt;
  Eigen::VectorXd x;
  Eigen::MatrixXd J_x_q;
  for (int it = 0; it < 20; ++it) {
    (void)forwardStylus(stylus, p, *u, x, nullptr, &J_x_q);
    const Eigen::Vector3d error = target - x;
    if (error.norm() <= tolerance) return u;
    Eigen::FullPivLU<Eigen::Matrix3d> lu(J_x_q.leftCols<3>());
    if (!lu.isInvertible()) return std::nullopt;
    *u += lu.solve(error);
  }
  return std::nullopt;
}

std::vector<Eigen::VectorXd> Cartesian::skeleton(const Eigen::VectorXd& /*p*/,
                                                 const Eigen::VectorXd& q) const {
  Eigen::Vector3d at = Eigen::Vector3d::Zero();
  std::vector<Eigen::VectorXd> points{at};
  for (std::size_t k = 0; k < axes_.size(); ++k) {
    at += axes_[k].direction * q[static_cast<Eigen::Index>(k)];
    points.push_back(at);
  }
  return points;
}

}  // namespace artcal
