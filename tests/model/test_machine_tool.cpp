// The machine-tool family (docs/five-axis.md, the spec's section 2): the forward kinematics
// against the spec's formulas written apart from the model, as explicit products of 4 x 4
// homogeneous matrices (Rodrigues by hand, T_axis = Trans(c) Rot(u, a) Trans(-c)), for both
// configurations with random nonzero location errors; and the exact Jacobians against central
// differences at those errors (the registry battery checks them at the plans' nominal values).

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <random>

#include "artcal/core/units.hpp"
#include "artcal/estimation/plane_rows.hpp"
#include "artcal/model/machine_tool.hpp"
#include "finite_difference.hpp"

namespace artcal {
namespace machine_tool_test {

using Matrix4 = Eigen::Matrix4d;
using Vector4 = Eigen::Vector4d;

Matrix4 translation(double x, double y, double z) {
  Matrix4 T = Matrix4::Identity();
  T(0, 3) = x;
  T(1, 3) = y;
  T(2, 3) = z;
  return T;
}

// Rot(u, a) = cos a I + sin a [u]x + (1 - cos a) u u^T, u normalised here.
Matrix4 rotation(double ux, double uy, double uz, double a) {
  const double n = std::sqrt(ux * ux + uy * uy + uz * uz);
  ux /= n;
  uy /= n;
  uz /= n;
  const double c = std::cos(a), s = std::sin(a), v = 1.0 - c;
  Matrix4 T = Matrix4::Identity();
  T(0, 0) = c + v * ux * ux;
  T(0, 1) = v * ux * uy - s * uz;
  T(0, 2) = v * ux * uz + s * uy;
  T(1, 0) = v * uy * ux + s * uz;
  T(1, 1) = c + v * uy * uy;
  T(1, 2) = v * uy * uz - s * ux;
  T(2, 0) = v * uz * ux - s * uy;
  T(2, 1) = v * uz * uy + s * ux;
  T(2, 2) = c + v * uz * uz;
  return T;
}

Matrix4 rx(double a) {
  return rotation(1, 0, 0, a);
}
Matrix4 ry(double a) {
  return rotation(0, 1, 0, a);
}
Matrix4 rz(double a) {
  return rotation(0, 0, 1, a);
}

Matrix4 aboutLine(const Vector4& c, const Vector4& u, double a) {
  return translation(c[0], c[1], c[2]) * rotation(u[0], u[1], u[2], a) *
         translation(-c[0], -c[1], -c[2]);
}

// The spec's parameters by name, deg for angles (as in files), here turned to rad by hand.
struct Errors {
  double pos0, pos1, tilt0, tilt1, zero;  // first rotary axis, in the spec's order
  double X0C, Y0C, A0C, B0C, C0C, C0Y, B0Z, A0Z, L;
};

Eigen::VectorXd internal(const Errors& e) {
  const double d = std::numbers::pi / 180.0;
  Eigen::VectorXd p(14);
  p << e.pos0, e.pos1, e.tilt0 * d, e.tilt1 * d, e.zero * d, e.X0C, e.Y0C, e.A0C * d, e.B0C * d,
      e.C0C * d, e.C0Y * d, e.B0Z * d, e.A0Z * d, e.L;
  return p;
}

// The spindle nose s as a 4 x 4 shear applied to (X, Y, Z, 1): x' = X + tan(E_C0Y) Y + tan(E_B0Z)
// Z, y' = Y + tan(E_A0Z) Z.
Vector4 nose(const Errors& e, double X, double Y, double Z) {
  const double d = std::numbers::pi / 180.0;
  Matrix4 shear = Matrix4::Identity();
  shear(0, 1) = std::tan(e.C0Y * d);
  shear(0, 2) = std::tan(e.B0Z * d);
  shear(1, 2) = std::tan(e.A0Z * d);
  return shear * Vector4(X, Y, Z, 1.0);
}

Eigen::Vector3d trunnionTip(const Errors& e, const Eigen::VectorXd& q_deg) {
  const double d = std::numbers::pi / 180.0;
  const Vector4 u_A = rz(e.tilt1 * d) * ry(e.tilt0 * d) * Vector4(1, 0, 0, 0);
  const Vector4 u_C = rx(e.A0C * d) * ry(e.B0C * d) * Vector4(0, 0, 1, 0);
  const Matrix4 T_A = aboutLine(Vector4(0, e.pos0, e.pos1, 1), u_A, (q_deg[3] + e.zero) * d);
  const Matrix4 T_C = aboutLine(Vector4(e.X0C, e.Y0C, 0, 1), u_C, (q_deg[4] + e.C0C) * d);
  Vector4 t = nose(e, q_deg[0], q_deg[1], q_deg[2]);
  t[2] -= e.L;
  return ((T_A * T_C).inverse() * t).head<3>();
}

Eigen::Vector3d headTableTip(const Errors& e, double P, const Eigen::VectorXd& q_deg) {
  const double d = std::numbers::pi / 180.0;
  const Vector4 u_B = rz(e.tilt1 * d) * rx(e.tilt0 * d) * Vector4(0, 1, 0, 0);
  const Vector4 u_C = rx(e.A0C * d) * ry(e.B0C * d) * Vector4(0, 0, 1, 0);
  const Matrix4 T_B = aboutLine(Vector4(e.pos0, 0, e.pos1, 1), u_B, (q_deg[3] + e.zero) * d);
  const Matrix4 T_C = aboutLine(Vector4(e.X0C, e.Y0C, 0, 1), u_C, (q_deg[4] + e.C0C) * d);
  const Vector4 s = nose(e, q_deg[0], q_deg[1], q_deg[2]);
  // The head frame H: parallel to M, origin at s + (0, 0, P).
  const Matrix4 H = translation(s[0], s[1], s[2] + P);
  const Vector4 t = H * T_B * Vector4(0, 0, -(P + e.L), 1);
  return (T_C.inverse() * t).head<3>();
}

Errors randomErrors(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> mm(-0.05, 0.05), deg(-0.01, 0.01), big(-3.0, 3.0);
  // Large errors besides typical ones: a small-angle shortcut in the model would show.
  return {mm(rng) * 20, mm(rng) * 20,
          big(rng),     big(rng),
          big(rng),     mm(rng) * 20,
          mm(rng) * 20, big(rng),
          big(rng),     big(rng),
          big(rng),     big(rng),
          big(rng),     150.0 + mm(rng) * 100};
}

Eigen::VectorXd randomReadings(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> lin(-300.0, 300.0), rot(-180.0, 180.0);
  Eigen::VectorXd q(5);
  q << lin(rng), lin(rng), lin(rng), rot(rng), rot(rng);
  return q;
}

Eigen::VectorXd toInternal(const Eigen::VectorXd& q_deg) {
  Eigen::VectorXd q = q_deg;
  q[3] *= kDegree;
  q[4] *= kDegree;
  return q;
}

TEST(MachineTool, TrunnionForwardKinematicsIsTheSpecsProductOfTransforms) {
  std::mt19937_64 rng(31);
  const MachineTool tool(MachineToolConfiguration::TrunnionAC, 0.0);
  for (int trial = 0; trial < 50; ++trial) {
    const Errors e = randomErrors(rng);
    const Eigen::VectorXd q = randomReadings(rng);
    Eigen::VectorXd x;
    ASSERT_EQ(tool.forward(internal(e), toInternal(q), x), ForwardStatus::Ok);
    EXPECT_LT((x - trunnionTip(e, q)).norm(), 1e-10) << "trial " << trial;
  }
}

TEST(MachineTool, HeadTableForwardKinematicsIsTheSpecsProductOfTransforms) {
  std::mt19937_64 rng(32);
  const double P = 250.0;
  const MachineTool tool(MachineToolConfiguration::HeadBTableC, P);
  for (int trial = 0; trial < 50; ++trial) {
    const Errors e = randomErrors(rng);
    const Eigen::VectorXd q = randomReadings(rng);
    Eigen::VectorXd x;
    ASSERT_EQ(tool.forward(internal(e), toInternal(q), x), ForwardStatus::Ok);
    EXPECT_LT((x - headTableTip(e, P, q)).norm(), 1e-10) << "trial " << trial;
  }
}

// At zero readings and zero errors W = M: the tip is (0, 0, -L) below the pivot (spec, section
// 1), in both configurations; a positive C reading turns the table counter-clockwise seen from
// +Z, so the tip, fixed in M, moves clockwise in W.
TEST(MachineTool, SignConventionsOfTheSpec) {
  Eigen::VectorXd p = Eigen::VectorXd::Zero(14);
  p[MachineTool::kToolLength] = 100.0;
  const MachineTool trunnion(MachineToolConfiguration::TrunnionAC, 0.0);
  Eigen::VectorXd q(5), x;
  q << 10.0, 0.0, 100.0, 0.0, 90.0 * kDegree;
  ASSERT_EQ(trunnion.forward(p, q, x), ForwardStatus::Ok);
  EXPECT_NEAR(x[0], 0.0, 1e-12);
  EXPECT_NEAR(x[1], -10.0, 1e-12);
  EXPECT_NEAR(x[2], 0.0, 1e-12);
  const MachineTool head(MachineToolConfiguration::HeadBTableC, 300.0);
  q << 0.0, 0.0, 0.0, 90.0 * kDegree, 0.0;
  ASSERT_EQ(head.forward(p, q, x), ForwardStatus::Ok);
  // The tool, turned +90 deg about +Y from pointing down, points along -X: tip at (-400, 0, 300).
  EXPECT_NEAR(x[0], -400.0, 1e-9);
  EXPECT_NEAR(x[2], 300.0, 1e-9);
}

TEST(MachineTool, ExactJacobiansAtNonzeroErrors) {
  std::mt19937_64 rng(33);
  for (const auto configuration :
       {MachineToolConfiguration::TrunnionAC, MachineToolConfiguration::HeadBTableC}) {
    const MachineTool tool(configuration, 250.0);
    for (int trial = 0; trial < 10; ++trial) {
      const Eigen::VectorXd p = internal(randomErrors(rng));
      const Eigen::VectorXd q = toInternal(randomReadings(rng));
      Eigen::VectorXd x;
      Eigen::MatrixXd J_x_p, J_x_q;
      ASSERT_EQ(tool.forward(p, q, x, &J_x_p, &J_x_q), ForwardStatus::Ok);
      auto of_p = [&](const Eigen::VectorXd& v) {
        Eigen::VectorXd y;
        EXPECT_EQ(tool.forward(v, q, y), ForwardStatus::Ok);
        return y;
      };
      auto of_q = [&](const Eigen::VectorXd& v) {
        Eigen::VectorXd y;
        EXPECT_EQ(tool.forward(p, v, y), ForwardStatus::Ok);
        return y;
      };
      const std::string where = machineToolConfigurationName(configuration);
      testing::expectJacobianNear(J_x_p, testing::centralDifferenceJacobian(of_p, p, 1e-6), 1e-6,
                                  where + " J_x_p");
      testing::expectJacobianNear(J_x_q, testing::centralDifferenceJacobian(of_q, q, 1e-6), 1e-6,
                                  where + " J_x_q");
    }
  }
}

// The double ball bar between a table ball and the spindle's (the spec's section 3): one row
// |t_W - w_b| - length. Its value and its derivatives in p, q and the table ball's position
// (plane_rows.hpp, the one place the rows are formed) against the spec's tip written apart from
// the model (the 4 x 4 products above) and central differences of that distance, at random
// nonzero errors in both configurations.
TEST(MachineTool, TableSpindleBallBarRowIsTheDistanceOfTheSpecsTip) {
  std::mt19937_64 rng(41);
  const double length = 150.0;
  const Artifact bar = Artifact::planeArtifact(
      "bar", 3, PlaneGeometry{PlaneShape::TableBall, {}, 0.0, false, Eigen::Vector3d::UnitZ(),
                              length, 0.0},
      0.0, 0.0, 0.0);
  for (const auto configuration :
       {MachineToolConfiguration::TrunnionAC, MachineToolConfiguration::HeadBTableC}) {
    Machine machine;
    machine.mechanism = std::make_shared<MachineTool>(configuration, 250.0);
    const int n = machine.mechanism->parameterCount();
    for (int k = 0; k < n; ++k) machine.calibrated.push_back(k);
    for (int trial = 0; trial < 5; ++trial) {
      const Errors e = randomErrors(rng);
      const Eigen::VectorXd p = internal(e);
      machine.nominal = p;
      const Eigen::VectorXd q_deg = randomReadings(rng);
      const Eigen::Vector3d w_b(20.0, -35.0, 60.0);
      auto tip = [&](const Errors& errors, const Eigen::VectorXd& q) {
        return configuration == MachineToolConfiguration::TrunnionAC
                   ? trunnionTip(errors, q)
                   : headTableTip(errors, 250.0, q);
      };
      RigidTransform placed = RigidTransform::identity(3);
      placed.t = -w_b;
      const Measurement m{0, toInternal(q_deg), 0};
      PlaneRows rows;
      PlaneRowsScratch scratch;
      planeRows(bar, machine, p, m, placed, Eigen::VectorXd(), true, rows, scratch);
      ASSERT_EQ(rows.rows, 1);
      EXPECT_NEAR(rows.residual[0], (tip(e, q_deg) - w_b).norm() - length, 1e-9);
      // d/dp through the internal parameter vector, d/dq through the internal readings.
      auto of_p = [&](const Eigen::VectorXd& v) {
        PlaneRows r;
        PlaneRowsScratch s2;
        planeRows(bar, machine, v, m, placed, Eigen::VectorXd(), false, r, s2);
        return Eigen::VectorXd(r.residual.head(1));
      };
      auto of_q = [&](const Eigen::VectorXd& v) {
        Eigen::VectorXd q = v;
        q[3] /= kDegree;
        q[4] /= kDegree;
        return Eigen::VectorXd::Constant(1, (tip(e, q) - w_b).norm() - length);
      };
      auto of_w = [&](const Eigen::VectorXd& v) {
        return Eigen::VectorXd::Constant(1, (tip(e, q_deg) + v).norm() - length);
      };
      const std::string where = machineToolConfigurationName(configuration);
      testing::expectJacobianNear(rows.J_p, testing::centralDifferenceJacobian(of_p, p, 1e-6),
                                  1e-6, where + " bar J_p");
      testing::expectJacobianNear(rows.J_q, testing::centralDifferenceJacobian(of_q, m.joints, 1e-6),
                                  1e-6, where + " bar J_q");
      testing::expectJacobianNear(rows.J_r, testing::centralDifferenceJacobian(of_w, placed.t, 1e-6),
                                  1e-6, where + " bar J_r");
    }
  }
}

TEST(MachineTool, ParameterNamesAndOrderOfTheSpec) {
  const MachineTool trunnion(MachineToolConfiguration::TrunnionAC, 0.0);
  const MachineTool head(MachineToolConfiguration::HeadBTableC, 200.0);
  std::string a, b;
  for (const ParameterInfo& info : trunnion.parameters()) a += info.name + " ";
  for (const ParameterInfo& info : head.parameters()) b += info.name + " ";
  EXPECT_EQ(a, "E_Y0A E_Z0A E_B0A E_C0A E_A0A E_X0C E_Y0C E_A0C E_B0C E_C0C E_C0Y E_B0Z E_A0Z L ");
  EXPECT_EQ(b, "E_X0B E_Z0B E_A0B E_C0B E_B0B E_X0C E_Y0C E_A0C E_B0C E_C0C E_C0Y E_B0Z E_A0Z L ");
}

}  // namespace machine_tool_test
}  // namespace artcal
