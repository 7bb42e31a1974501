#pragma once
// A Cartesian CMM with form-deviation error functions (docs/models.md section 4; ISO 230-1
// rigid-body model). Axes are listed from the base to the probe; the reading of axis k is its scale
// value u_k (mm). Each axis carries six error functions of its own position, three translations
// delta_k(u) and three rotations eps_k(u), each a Legendre series without constant term:
//   e(u) = sum_{n=1..degree} c_n P_n(s),   s = 2 (u - mid_k) / width_k.
// Forward model: T_k(u_k) = Trans(direction_k u_k + delta_k(u_k)) Rot(eps_k(u_k)),
//   x = T_1 T_2 ... T_n stylus_s,
// Rot the exact exponential of the rotation vector. Parameters, per axis, per degree N:
// AXIS.tx.N AXIS.ty.N AXIS.tz.N (mm) and AXIS.rx.N AXIS.ry.N AXIS.rz.N (rad inside, um/m in
// files). Nominal p = 0: the model is linear in p up to the second-order terms of the rotations.
// The stylus is chosen per reading (forwardStylus); forward() uses stylus 0.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "artcal/model/axis_error_functions.hpp"
#include "artcal/model/mechanism.hpp"

namespace artcal {

class Cartesian final : public Mechanism, public AxisErrorFunctions {
 public:
  Cartesian(std::vector<CartesianAxis> axes, int degree, std::vector<Eigen::Vector3d> styli);

  std::string modelName() const override { return "cartesian"; }
  int dimension() const override { return 3; }
  int jointCount() const override { return static_cast<int>(axes_.size()); }
  JointKind jointKind(int) const override { return JointKind::Prismatic; }
  const std::vector<ParameterInfo>& parameters() const override { return parameters_; }
  ForwardStatus forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x,
                        Eigen::MatrixXd* J_x_p = nullptr,
                        Eigen::MatrixXd* J_x_q = nullptr) const override;
  int stylusCount() const override { return static_cast<int>(styli_.size()); }
  /// The one solution: inverse() (the nominal closed form refined by Newton).
  bool hasClosedFormInverse() const override { return true; }
  std::vector<Eigen::VectorXd> closedFormInverse(const Eigen::VectorXd& p,
                                                 const Eigen::VectorXd& target,
                                                 int stylus) const override;
  int posturesPerPoint() const override { return stylusCount(); }
  /// The axis positions for drawings: from the machine origin along each axis by its reading in
  /// turn (direction_k u_k, the nominal geometry), ending at the quill (the styli are not drawn).
  std::vector<Eigen::VectorXd> skeleton(const Eigen::VectorXd& p,
                                        const Eigen::VectorXd& q) const override;
  ForwardStatus forwardStylus(int stylus, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                              Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p = nullptr,
                              Eigen::MatrixXd* J_x_q = nullptr) const override;

  /// The capability its analyses ask for (axis_error_functions.hpp).
  const AxisErrorFunctions* axisErrorFunctions() const override { return this; }
  const std::vector<CartesianAxis>& axes() const override { return axes_; }
  int degree() const override { return degree_; }
  const std::vector<Eigen::Vector3d>& styli() const override { return styli_; }
  std::shared_ptr<const Mechanism> withStyli(std::vector<Eigen::Vector3d> styli) const override {
    return std::make_shared<Cartesian>(axes_, degree_, std::move(styli));
  }
  int parameterIndex(int axis, AxisError error, int n) const override {
    return (axis * degree_ + (n - 1)) * kAxisErrorCount + static_cast<int>(error);
  }
  using Mechanism::parameterIndex;
  double normalised(int axis, double u) const override;

  /// Readings that put stylus `stylus` on `target` at nominal (p = 0): the target minus the
  /// stylus resolved along the axis directions; std::nullopt when the directions are singular.
  std::optional<Eigen::VectorXd> nominalInverse(const Eigen::Vector3d& target, int stylus) const;
  /// Readings that put stylus `stylus` of the machine p on `target`: the nominal solution, then
  /// Newton on f(p, u) = target (nearly linear: two or three steps). std::nullopt when Newton does
  /// not reach `tolerance` mm.
  std::optional<Eigen::VectorXd> inverse(const Eigen::VectorXd& p, const Eigen::Vector3d& target,
                                         int stylus, double tolerance = 1e-10) const;

 private:
  std::vector<CartesianAxis> axes_;
  int degree_;
  std::vector<Eigen::Vector3d> styli_;
  std::vector<ParameterInfo> parameters_;
};

}  // namespace artcal
