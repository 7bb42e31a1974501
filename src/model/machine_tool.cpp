#include "artcal/model/machine_tool.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "artcal/model/frame_turns.hpp"

namespace artcal {

namespace {

// Parameter indices shared by both configurations (the C axis, the squareness errors, L).
constexpr int kX0C = 5, kY0C = 6, kA0C = 7, kB0C = 8, kC0C = 9, kC0Y = 10, kB0Z = 11, kA0Z = 12;
constexpr int kL = MachineTool::kToolLength;
// The first rotary axis (A on the trunnion, B in the head): position 0, position 1, the two
// orientation errors, the zero.
constexpr int kPos0 = 0, kPos1 = 1, kTilt0 = 2, kTilt1 = 3, kZero = 4;

const Eigen::Vector3d kX = Eigen::Vector3d::UnitX();
const Eigen::Vector3d kZ = Eigen::Vector3d::UnitZ();

// A unit vector turned by two small rotations about coordinate axes, written out (the axes'
// directions below): cos and sin of each angle, no rotation matrices built.
struct SinCos {
  double s, c;
  explicit SinCos(double angle) : s(std::sin(angle)), c(std::cos(angle)) {}
};

// One rotary axis: the point c on its line, its unit direction u, the angle theta (reading plus
// zero) with its sine and cosine, R = Rot(u, theta), and du for each of its two orientation
// errors.
struct RotaryAxis {
  Eigen::Vector3d c;
  Eigen::Vector3d u;
  double theta = 0.0, sin_theta = 0.0, cos_theta = 1.0;
  Eigen::Matrix3d R;
  Eigen::Vector3d du[2];

  // theta and R = cos I + sin [u]x + (1 - cos) u u^T (Rodrigues), u set.
  void turn(double angle) {
    theta = angle;
    sin_theta = std::sin(angle);
    cos_theta = std::cos(angle);
    R = (1.0 - cos_theta) * u * u.transpose();
    R.diagonal().array() += cos_theta;
    R += sin_theta * skew(u);
  }

  // w for a change of the orientation error k (header): sin(theta) du + (1 - cos theta) u x du.
  Eigen::Vector3d turnOfTilt(int k) const {
    return sin_theta * du[k] + (1.0 - cos_theta) * u.cross(du[k]);
  }
};

// The C axis: through (E_X0C, E_Y0C, 0), direction Rx(E_A0C) Ry(E_B0C) z
// = (sin b, -sin a cos b, cos a cos b), zero E_C0C.
RotaryAxis axisC(const Eigen::VectorXd& p, double reading) {
  RotaryAxis axis;
  axis.c = Eigen::Vector3d(p[kX0C], p[kY0C], 0.0);
  const SinCos a(p[kA0C]), b(p[kB0C]);
  axis.u = Eigen::Vector3d(b.s, -a.s * b.c, a.c * b.c);
  axis.du[0] = kX.cross(axis.u);                              // d/dE_A0C
  axis.du[1] = Eigen::Vector3d(0.0, a.c, a.s).cross(axis.u);  // Rx y, d/dE_B0C
  axis.turn(reading + p[kC0C]);
  return axis;
}

}  // namespace

std::string machineToolConfigurationName(MachineToolConfiguration configuration) {
  return nameOf(kMachineToolConfigurationNames, configuration);
}

MachineTool::MachineTool(MachineToolConfiguration configuration, double pivot_length)
    : configuration_(configuration), pivot_length_(pivot_length) {
  const bool trunnion = configuration == MachineToolConfiguration::TrunnionAC;
  const std::vector<std::string> first =
      trunnion ? std::vector<std::string>{"E_Y0A", "E_Z0A", "E_B0A", "E_C0A", "E_A0A"}
               : std::vector<std::string>{"E_X0B", "E_Z0B", "E_A0B", "E_C0B", "E_B0B"};
  for (int k = 0; k < 5; ++k)
    parameters_.push_back(
        {first[static_cast<std::size_t>(k)], k < 2 ? Quantity::Length : Quantity::Angle});
  for (const char* name : {"E_X0C", "E_Y0C"}) parameters_.push_back({name, Quantity::Length});
  for (const char* name : {"E_A0C", "E_B0C", "E_C0C", "E_C0Y", "E_B0Z", "E_A0Z"})
    parameters_.push_back({name, Quantity::Angle});
  parameters_.push_back({"L", Quantity::Length});
}

std::vector<std::string> MachineTool::jointLabels() const {
  const std::string rotary = rotaryNames();
  return {"X", "Y", "Z", rotary.substr(0, 1), rotary.substr(1, 1)};
}

std::string MachineTool::rotaryNames() const {
  return configuration_ == MachineToolConfiguration::TrunnionAC ? "AC" : "BC";
}

ForwardStatus MachineTool::forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                   Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p,
                                   Eigen::MatrixXd* J_x_q) const {
  const bool trunnion = configuration_ == MachineToolConfiguration::TrunnionAC;
  const double tC0Y = std::tan(p[kC0Y]), tB0Z = std::tan(p[kB0Z]), tA0Z = std::tan(p[kA0Z]);
  const Eigen::Vector3d s(q[0] + tC0Y * q[1] + tB0Z * q[2], q[1] + tA0Z * q[2], q[2]);
  // The first rotary axis: A on the bed (trunnion) or B in the head.
  RotaryAxis first;
  const SinCos tilt0(p[kTilt0]), tilt1(p[kTilt1]);
  if (trunnion) {  // Rz(E_C0A) Ry(E_B0A) x
    first.c = Eigen::Vector3d(0.0, p[kPos0], p[kPos1]);
    first.u = Eigen::Vector3d(tilt1.c * tilt0.c, tilt1.s * tilt0.c, -tilt0.s);
    first.du[0] = Eigen::Vector3d(-tilt1.s, tilt1.c, 0.0).cross(first.u);  // Rz y, d/dE_B0A
    first.du[1] = kZ.cross(first.u);                                       // d/dE_C0A
  } else {                                                                 // Rz(E_C0B) Rx(E_A0B) y
    first.c = Eigen::Vector3d(p[kPos0], 0.0, p[kPos1]);
    first.u = Eigen::Vector3d(-tilt1.s * tilt0.c, tilt1.c * tilt0.c, tilt0.s);
    first.du[0] = Eigen::Vector3d(tilt1.c, tilt1.s, 0.0).cross(first.u);  // Rz x, d/dE_A0B
    first.du[1] = kZ.cross(first.u);                                      // d/dE_C0B
  }
  first.turn(q[3] + p[kZero]);
  const RotaryAxis C = axisC(p, q[4]);

  // Tip in M (t) and, for the trunnion, in the frame carried by A (y = T_A^-1 t).
  Eigen::Vector3d t, y, head_arm;
  if (trunnion) {
    t = s - p[kL] * kZ;
    y = first.c + first.R.transpose() * (t - first.c);
  } else {
    const Eigen::Vector3d tip_in_head(0.0, 0.0, -(pivot_length_ + p[kL]));
    head_arm = first.R * (tip_in_head - first.c);  // R_B (q - c_B)
    t = s + pivot_length_ * kZ + first.c + head_arm;
    y = t;
  }
  const Eigen::Matrix3d QC = C.R.transpose();
  x = C.c + QC * (y - C.c);
  if (!J_x_p && !J_x_q) return ForwardStatus::Ok;

  // dx = (I - QC) dc_C + QC [y - c_C]x w_C + QC dy.
  const Eigen::Matrix3d QC_skew = QC * skew(y - C.c);
  // dy for dt: the trunnion's Q_A, the identity for the head.
  const Eigen::Matrix3d QA = first.R.transpose();
  const Eigen::Matrix3d dx_dt = trunnion ? Eigen::Matrix3d(QC * QA) : QC;
  if (J_x_p) {
    Eigen::MatrixXd& J = *J_x_p;
    J.resize(3, kParameterCount);
    // C axis.
    J.col(kX0C) = (Eigen::Matrix3d::Identity() - QC).col(0);
    J.col(kY0C) = (Eigen::Matrix3d::Identity() - QC).col(1);
    J.col(kA0C) = QC_skew * C.turnOfTilt(0);
    J.col(kB0C) = QC_skew * C.turnOfTilt(1);
    J.col(kC0C) = QC_skew * C.u;
    // Squareness: ds/dE = sec^2(E) times the reading sheared.
    J.col(kC0Y) = dx_dt.col(0) * ((1.0 + tC0Y * tC0Y) * q[1]);
    J.col(kB0Z) = dx_dt.col(0) * ((1.0 + tB0Z * tB0Z) * q[2]);
    J.col(kA0Z) = dx_dt.col(1) * ((1.0 + tA0Z * tA0Z) * q[2]);
    // The first rotary axis.
    Eigen::Matrix3d dy_dc, dy_dw;
    if (trunnion) {
      dy_dc = Eigen::Matrix3d::Identity() - QA;
      dy_dw = QA * skew(t - first.c);
      J.col(kL) = -dx_dt.col(2);
    } else {
      dy_dc = Eigen::Matrix3d::Identity() - first.R;
      dy_dw = -skew(head_arm);
      J.col(kL) = -QC * first.R.col(2);
    }
    const Eigen::Matrix3d dx_dc = QC * dy_dc, dx_dw = QC * dy_dw;
    J.col(kPos0) = dx_dc.col(trunnion ? 1 : 0);
    J.col(kPos1) = dx_dc.col(2);
    J.col(kTilt0) = dx_dw * first.turnOfTilt(0);
    J.col(kTilt1) = dx_dw * first.turnOfTilt(1);
    J.col(kZero) = dx_dw * first.u;
  }
  if (J_x_q) {
    Eigen::MatrixXd& J = *J_x_q;
    J.resize(3, 5);
    J.col(0) = dx_dt.col(0);
    J.col(1) = dx_dt * Eigen::Vector3d(tC0Y, 1.0, 0.0);
    J.col(2) = dx_dt * Eigen::Vector3d(tB0Z, tA0Z, 1.0);
    const Eigen::Matrix3d dy_dw =
        trunnion ? Eigen::Matrix3d(QA * skew(t - first.c)) : Eigen::Matrix3d(-skew(head_arm));
    J.col(3) = QC * dy_dw * first.u;
    J.col(4) = QC_skew * C.u;
  }
  return ForwardStatus::Ok;
}

std::vector<Eigen::VectorXd> MachineTool::skeleton(const Eigen::VectorXd& p,
                                                   const Eigen::VectorXd& q) const {
  Eigen::VectorXd tip;
  if (forward(p, q, tip) != ForwardStatus::Ok) return {};
  Eigen::VectorXd nose = tip;
  nose[2] += p[kL];
  return {Eigen::VectorXd(Eigen::Vector3d::Zero()), nose, tip};
}

}  // namespace artcal
