#include "artcal/model/planar2r.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace artcal {

Planar2R::Planar2R()
    : parameters_{{"l1", Quantity::Length}, {"l2", Quantity::Length}, {"dt2", Quantity::Angle}} {}

ForwardStatus Planar2R::forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p,
                                Eigen::MatrixXd* J_x_q) const {
  const double l1 = p[0], l2 = p[1], dt2 = p[2];
  const double c1 = std::cos(q[0]), s1 = std::sin(q[0]);
  const double c12 = std::cos(q[0] + q[1] + dt2), s12 = std::sin(q[0] + q[1] + dt2);
  x.resize(2);
  x << l1 * c1 + l2 * c12, l1 * s1 + l2 * s12;
  if (J_x_p) {
    J_x_p->resize(2, 3);
    *J_x_p << c1, c12, -l2 * s12,  //
        s1, s12, l2 * c12;
  }
  if (J_x_q) {
    J_x_q->resize(2, 2);
    *J_x_q << -x[1], -l2 * s12,  //
        x[0], l2 * c12;
  }
  return ForwardStatus::Ok;
}

std::vector<Eigen::VectorXd> Planar2R::elbowBranches(const Eigen::VectorXd& p,
                                                     const Eigen::Vector2d& target) {
  const double l1 = p[0], l2 = p[1], dt2 = p[2];
  const double r2 = target.squaredNorm();
  const double cosine = (r2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2);
  if (cosine < -1.0 - 1e-12 || cosine > 1.0 + 1e-12) return {};
  const double elbow = std::acos(std::clamp(cosine, -1.0, 1.0));
  std::vector<Eigen::VectorXd> solutions;
  for (double sign : {1.0, -1.0}) {
    const double phi = sign * elbow;  // t2 + dt2
    const double t1 = std::atan2(target.y(), target.x()) -
                      std::atan2(l2 * std::sin(phi), l1 + l2 * std::cos(phi));
    solutions.push_back(Eigen::Vector2d(std::remainder(t1, 2 * std::numbers::pi),
                                        std::remainder(phi - dt2, 2 * std::numbers::pi)));
    if (elbow == 0.0) break;
  }
  return solutions;
}

std::vector<Eigen::VectorXd> Planar2R::closedFormInverse(const Eigen::VectorXd& p,
                                                         const Eigen::VectorXd& target,
                                                         int /*stylus*/) const {
  return elbowBranches(p, target.head<2>());
}

std::optional<std::array<double, 2>> Planar2R::reachRange(const Eigen::VectorXd& p) const {
  return std::array<double, 2>{std::abs(p[0] - p[1]), p[0] + p[1]};
}

// The tip uncertainty of the planar arm depends on the reach alone (docs/method.md section 8): t1
// is held at 0 (or the limit nearest it), t2 on each elbow branch from the law of cosines.
std::vector<Eigen::VectorXd> Planar2R::configurationsAtReach(
    const Eigen::VectorXd& p, double reach,
    const std::vector<std::array<double, 2>>& limits) const {
  const double l1 = p[0], l2 = p[1], dt2 = p[2];
  const double t1 = std::clamp(0.0, limits[0][0], limits[0][1]);
  const double cosine = std::clamp((reach * reach - l1 * l1 - l2 * l2) / (2 * l1 * l2), -1.0, 1.0);
  std::vector<Eigen::VectorXd> out;
  for (double sign : {1.0, -1.0}) {  // both elbow branches
    const double t2 = sign * std::acos(cosine) - dt2;
    if (t2 < limits[1][0] || t2 > limits[1][1]) continue;
    out.push_back(Eigen::Vector2d(t1, t2));
  }
  return out;
}

std::vector<Eigen::VectorXd> Planar2R::skeleton(const Eigen::VectorXd& p,
                                                const Eigen::VectorXd& q) const {
  Eigen::VectorXd tip;
  if (forward(p, q, tip) != ForwardStatus::Ok) return {};
  const Eigen::Vector2d elbow(p[0] * std::cos(q[0]), p[0] * std::sin(q[0]));
  return {Eigen::Vector2d::Zero(), elbow, tip};
}

}  // namespace artcal
