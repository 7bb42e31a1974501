#pragma once
// A five-axis machine tool with the ISO 230-7 location errors of its rotary axes (docs/
// five-axis.md; the family "machine-tool"). Readings [X, Y, Z, R1, R2]: the linear slides (mm)
// and two rotary axes (rad inside, deg in files). The probe point x = t_W is the tool tip in the
// workpiece frame W, attached to the table's last axis (C); at zero readings and zero errors
// W = M, the machine frame (origin at the nominal pivot).
//
// Linear axes: s(X, Y, Z) = (X + tan(E_C0Y) Y + tan(E_B0Z) Z, Y + tan(E_A0Z) Z, Z);
// T_axis(c, u, a) = Trans(c) Rot(u, a) Trans(-c), exact rotations (Rodrigues).
//   trunnion-AC:    t = s + (0, 0, -L);  A through (0, E_Y0A, E_Z0A), u_A = Rz(E_C0A) Ry(E_B0A) x,
//                   zero E_A0A; C (carried by A) through (E_X0C, E_Y0C, 0), u_C = Rx(E_A0C)
//                   Ry(E_B0C) z, zero E_C0C;  t_W = (T_A(a) T_C(c))^-1 t.
//   head-B-table-C: t = s + (0, 0, P) + T_B(b) (0, 0, -(P + L)), B in the head through
//                   (E_X0B, 0, E_Z0B), u_B = Rz(E_C0B) Rx(E_A0B) y, zero E_B0B; C on the bed as
//                   above; t_W = T_C(c)^-1 t.
// Parameters (angles rad inside, deg in files; positions and L mm), in this order:
//   trunnion-AC     E_Y0A E_Z0A E_B0A E_C0A E_A0A E_X0C E_Y0C E_A0C E_B0C E_C0C E_C0Y E_B0Z E_A0Z L
//   head-B-table-C  E_X0B E_Z0B E_A0B E_C0B E_B0B E_X0C E_Y0C E_A0C E_B0C E_C0C E_C0Y E_B0Z E_A0Z L
//
// Exact Jacobians. For v = c + Q (y - c) with Q = Rot(u, theta)^T, a change of c, u, theta, y:
//   dv = (I - Q) dc + Q [y - c]x w + Q dy,   w = u dtheta + sin(theta) du + (1 - cos(theta)) u x du
// (w the spatial angular velocity of Rot(u, theta) for a unit u, du perpendicular to u); for
// v = c + R (y - c): dv = (I - R) dc - [R (y - c)]x w + R dy.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "artcal/model/mechanism.hpp"

namespace artcal {

enum class MachineToolConfiguration { TrunnionAC, HeadBTableC };

/// The plan format's names: "trunnion-AC", "head-B-table-C".
inline constexpr EnumNames<MachineToolConfiguration, 2> kMachineToolConfigurationNames{
    {{MachineToolConfiguration::TrunnionAC, "trunnion-AC"},
     {MachineToolConfiguration::HeadBTableC, "head-B-table-C"}}};

class MachineTool final : public Mechanism {
 public:
  static constexpr int kParameterCount = 14;
  static constexpr int kToolLength = 13;  ///< index of L

  /// `pivot_length`: P (mm, head-B-table-C only; not a parameter).
  MachineTool(MachineToolConfiguration configuration, double pivot_length);

  std::string modelName() const override { return "machine-tool"; }
  int dimension() const override { return 3; }
  int jointCount() const override { return 5; }
  JointKind jointKind(int joint) const override {
    return joint < 3 ? JointKind::Prismatic : JointKind::Revolute;
  }
  const std::vector<ParameterInfo>& parameters() const override { return parameters_; }
  ForwardStatus forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x,
                        Eigen::MatrixXd* J_x_p = nullptr,
                        Eigen::MatrixXd* J_x_q = nullptr) const override;
  bool hasLocationErrors() const override { return true; }
  /// The rotary axes (joints 3, 4): a probing cycle commands them, the slides go to the sphere.
  std::vector<int> commandedJoints() const override { return {3, 4}; }
  /// X, Y, Z and the rotary axes' letters (A, C or B, C).
  std::vector<std::string> jointLabels() const override;
  /// Points for drawings: the table's pivot, the spindle nose and the tip (workpiece frame).
  std::vector<Eigen::VectorXd> skeleton(const Eigen::VectorXd& p,
                                        const Eigen::VectorXd& q) const override;

  MachineToolConfiguration configuration() const { return configuration_; }
  double pivotLength() const { return pivot_length_; }
  /// The rotary axis letters of joints 3 and 4: "AC" or "BC".
  std::string rotaryNames() const;

 private:
  MachineToolConfiguration configuration_;
  double pivot_length_;
  std::vector<ParameterInfo> parameters_;
};

/// "trunnion-AC", "head-B-table-C".
std::string machineToolConfigurationName(MachineToolConfiguration configuration);

}  // namespace artcal
