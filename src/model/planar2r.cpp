#include "artcal/model/planar2r.hpp"

#include <cmath>

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

}  // namespace artcal
