// The hexapod and the closed-chain path (models.md section 3): forward kinematics against the
// closed-form inverse, exact Jacobians against the finite-difference battery, reported failures.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <regex>
#include <sstream>

#include "artcal/core/units.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/model/hexapod.hpp"
#include "artcal/report/html_report.hpp"
#include "artcal/report/report.hpp"
#include "finite_difference.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace hexapod_test {

using testing::centralDifferenceJacobian;
using testing::expectJacobianNear;

// The reference hexapod of tests/data/ref-hexapod-6bars.json: base radius 400, platform radius
// 150, joint pairs +-10 deg about 0, 120, 240 deg (platform turned by 60 deg), probe (0, 0, -100).
Eigen::VectorXd referenceParameters() {
  Eigen::VectorXd p(45);
  const double base_angles[6] = {10, 110, 130, -130, -110, -10};
  const double platform_angles[6] = {50, 70, 170, -170, -70, -50};
  for (int i = 0; i < 6; ++i) {
    const double b = degToRad(base_angles[i]), a = degToRad(platform_angles[i]);
    p.segment<3>(Hexapod::baseOffset(i)) << 400.0 * std::cos(b), 400.0 * std::sin(b), 0.0;
    p.segment<3>(Hexapod::platformOffset(i)) << 150.0 * std::cos(a), 150.0 * std::sin(a), 0.0;
    p[Hexapod::legOffsetIndex(i)] = 0.0;
  }
  p.tail<3>() << 0.0, 0.0, -100.0;
  return p;
}

Hexapod referenceHexapod() {
  ChainPose home;
  home.t << 0.0, 0.0, 600.0;
  return Hexapod(home, 150.0);
}

// A perturbed machine: every joint centre and leg offset moved by up to 1 mm.
Eigen::VectorXd perturbed(const Eigen::VectorXd& p, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Eigen::VectorXd out = p;
  for (int i = 0; i < out.size(); ++i)
    out[i] += 2.0 * (static_cast<double>(rng() >> 11) * 0x1.0p-53) - 1.0;
  return out;
}

struct Reading {
  Eigen::Vector3d target;
  Eigen::Matrix3d R;
  Eigen::VectorXd q;
};

// Random probe targets in a 300 mm cube around (0, 0, 500) with platform tilts up to 15 deg.
std::vector<Reading> randomReadings(const Hexapod& hexapod, const Eigen::VectorXd& p, int count,
                                    std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Reading> out;
  for (int c = 0; c < count; ++c) {
    Reading r;
    for (int k = 0; k < 3; ++k)
      r.target[k] =
          (k == 2 ? 500.0 : 0.0) + 300.0 * (static_cast<double>(rng() >> 11) * 0x1.0p-53 - 0.5);
    r.R = randomTilt(hexapod.homePose().R, degToRad(15.0), rng);
    r.q = hexapod.legReadings(p, r.target, r.R);
    out.push_back(r);
  }
  return out;
}

TEST(Hexapod, HasTheFortyFiveParametersOfTheSpecInOrder) {
  const Hexapod hexapod = referenceHexapod();
  ASSERT_EQ(hexapod.parameterCount(), 45);
  EXPECT_EQ(hexapod.parameters()[0].name, "b1.x");
  EXPECT_EQ(hexapod.parameters()[5].name, "a1.z");
  EXPECT_EQ(hexapod.parameters()[6].name, "l1.offset");
  EXPECT_EQ(hexapod.parameters()[41].name, "l6.offset");
  EXPECT_EQ(hexapod.parameters()[44].name, "probe.z");
  EXPECT_EQ(hexapod.jointKind(3), JointKind::Prismatic);
}

TEST(Hexapod, ForwardKinematicsInvertsTheClosedFormInverse) {
  const Hexapod hexapod = referenceHexapod();
  for (std::uint64_t seed : {0u, 7u}) {
    const Eigen::VectorXd p =
        seed == 0 ? referenceParameters() : perturbed(referenceParameters(), seed);
    for (const Reading& r : randomReadings(hexapod, p, 50, seed + 1)) {
      Eigen::VectorXd x;
      ASSERT_EQ(hexapod.forward(p, r.q, x), ForwardStatus::Ok);
      EXPECT_LT((x - r.target).norm(), 1e-9);
      ChainPose pose;
      ASSERT_EQ(hexapod.solvePose(p, r.q, pose), ForwardStatus::Ok);
      EXPECT_LT((pose.R - r.R).norm(), 1e-12);
    }
  }
}

TEST(Hexapod, JacobiansMatchFiniteDifferences) {
  const Hexapod hexapod = referenceHexapod();
  const Eigen::VectorXd p = perturbed(referenceParameters(), 3);
  int index = 0;
  for (const Reading& r : randomReadings(hexapod, p, 8, 11)) {
    Eigen::VectorXd x;
    Eigen::MatrixXd J_x_p, J_x_q;
    ASSERT_EQ(hexapod.forward(p, r.q, x, &J_x_p, &J_x_q), ForwardStatus::Ok);
    const auto of_p = [&](const Eigen::VectorXd& pp) {
      Eigen::VectorXd y;
      EXPECT_EQ(hexapod.forward(pp, r.q, y), ForwardStatus::Ok);
      return y;
    };
    const auto of_q = [&](const Eigen::VectorXd& qq) {
      Eigen::VectorXd y;
      EXPECT_EQ(hexapod.forward(p, qq, y), ForwardStatus::Ok);
      return y;
    };
    // Steps of 1e-3 mm: the solver's rounding (1e-13 mm) stays far below the differences.
    const std::string where = "reading " + std::to_string(index++);
    expectJacobianNear(J_x_p, centralDifferenceJacobian(of_p, p, 1e-3), 1e-7, where + " J_x_p");
    expectJacobianNear(J_x_q, centralDifferenceJacobian(of_q, r.q, 1e-3), 1e-7, where + " J_x_q");
    Eigen::VectorXd x_alone;
    ASSERT_EQ(hexapod.forward(p, r.q, x_alone), ForwardStatus::Ok);
    EXPECT_EQ(x_alone, x);
  }
}

TEST(Hexapod, ProbeJacobianIsThePlatformRotation) {
  const Hexapod hexapod = referenceHexapod();
  const Eigen::VectorXd p = referenceParameters();
  const Reading r = randomReadings(hexapod, p, 1, 5).front();
  Eigen::VectorXd x;
  Eigen::MatrixXd J_x_p;
  ASSERT_EQ(hexapod.forward(p, r.q, x, &J_x_p), ForwardStatus::Ok);
  // Moving the probe in the platform frame with the legs held: the platform does not move.
  EXPECT_LT((J_x_p.middleCols<3>(Hexapod::kProbeOffset) - r.R).norm(), 1e-12);
  // A leg offset and its reading enter only through their sum.
  Eigen::MatrixXd J_x_q;
  ASSERT_EQ(hexapod.forward(p, r.q, x, nullptr, &J_x_q), ForwardStatus::Ok);
  for (int i = 0; i < 6; ++i)
    EXPECT_LT((J_x_p.col(Hexapod::legOffsetIndex(i)) - J_x_q.col(i)).norm(), 1e-12);
}

TEST(Hexapod, LegsThatCannotCloseAreAReportedFailure) {
  const Hexapod hexapod = referenceHexapod();
  const Eigen::VectorXd p = referenceParameters();
  Eigen::VectorXd x;
  // Legs of 100 mm cannot span a base 400 mm wide to a platform 150 mm wide.
  EXPECT_NE(hexapod.forward(p, Eigen::VectorXd::Constant(6, 100.0), x), ForwardStatus::Ok);
  // Wildly unequal legs: no pose near home closes them.
  Eigen::VectorXd q(6);
  q << 450, 3000, 450, 3000, 450, 3000;
  EXPECT_NE(hexapod.forward(p, q, x), ForwardStatus::Ok);
}

TEST(Hexapod, CoincidentJointsAreSingular) {
  // Every leg meets the platform at one point: the platform may spin about it.
  ChainPose home;
  home.t << 0.0, 0.0, 600.0;
  const Hexapod hexapod(home, 150.0);
  Eigen::VectorXd p = referenceParameters();
  for (int i = 0; i < 6; ++i) p.segment<3>(Hexapod::platformOffset(i)).setZero();
  const Eigen::VectorXd q = hexapod.legReadings(p, Eigen::Vector3d(0, 0, 500), home.R);
  Eigen::VectorXd x;
  EXPECT_EQ(hexapod.forward(p, q, x), ForwardStatus::Singular);
}

TEST(ClosedChain, RetractTurnsByTheExactExponential) {
  ChainPose pose;
  Eigen::VectorXd ds(6);
  ds << 1.0, 2.0, 3.0, 0.0, 0.0, std::numbers::pi / 2;
  retractPose(pose, ds);
  EXPECT_EQ(pose.t, Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_LT((pose.R * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-15);
  Eigen::VectorXd planar(2);
  planar << 0.5, -0.5;
  retractPose(pose, planar);
  EXPECT_EQ(pose.t, Eigen::Vector3d(1.5, 1.5, 3.0));
}

/// The points (px) of every <polyline> in an SVG with exactly `count` points, in order.
std::vector<std::vector<Eigen::Vector2d>> polylinesOf(const std::string& svg, std::size_t count) {
  static const std::regex kPolyline("<polyline points=\"([^\"]*)\"");
  std::vector<std::vector<Eigen::Vector2d>> out;
  for (std::sregex_iterator it(svg.begin(), svg.end(), kPolyline), end; it != end; ++it) {
    std::istringstream points((*it)[1].str());
    std::vector<Eigen::Vector2d> polyline;
    for (std::string pair; points >> pair;) {
      const std::size_t comma = pair.find(',');
      polyline.emplace_back(std::stod(pair.substr(0, comma)), std::stod(pair.substr(comma + 1)));
    }
    if (polyline.size() == count) out.push_back(polyline);
  }
  return out;
}

/// Pixel -> mm of an equal-aspect view (px = a + s x, py = b - s y), fitted by least squares to
/// known points (mm) and where they were drawn (px).
struct ViewScale {
  double a = 0, b = 0, s = 1;
  Eigen::Vector2d toMm(const Eigen::Vector2d& px) const {
    return {(px.x() - a) / s, (b - px.y()) / s};
  }
};

ViewScale fitView(const std::vector<Eigen::Vector2d>& mm, const std::vector<Eigen::Vector2d>& px) {
  // Unknowns (a, b, s): rows px.x = a + s x and px.y = b - s y.
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * static_cast<int>(mm.size()), 3);
  Eigen::VectorXd rhs(A.rows());
  for (std::size_t k = 0; k < mm.size(); ++k) {
    const int r = 2 * static_cast<int>(k);
    A.row(r) << 1, 0, mm[k].x();
    A.row(r + 1) << 0, 1, -mm[k].y();
    rhs[r] = px[k].x();
    rhs[r + 1] = px[k].y();
  }
  const Eigen::Vector3d abs = A.colPivHouseholderQr().solve(rhs);
  return {abs[0], abs[1], abs[2]};
}

// The report's layout (html_report.hpp) draws the machine at each reading through
// Mechanism::skeleton, in plan (XY) and side (XZ) views: one polyline of 26 points per reading
// (base hexagon, legs, platform hexagon, platform centre, probe). Checked against the plan
// file's numbers, not the model: each view's pixel scale is fitted to the file's base joints
// (equal aspect); the two views together give each point in 3-D; every leg is as long as its
// reading, the platform joints are a rigid copy of the file's (pairwise distances), and the
// probe lies |probe| from the platform centre. Pixels are written to 0.1 px (~0.2 mm here).
TEST(HexapodLayout, LegsAndPlatformAtEveryReadingInPlanAndSideViews) {
  const std::string path = test_support::testDataFile("ref-hexapod-6bars.json");
  const Plan plan = loadPlan(path);
  const nlohmann::json file = readJsonFile(path);
  const nlohmann::json& machine = file.at("machine");
  const Evaluation ev = evaluatePlan(plan);
  const nlohmann::json ev_json = evaluationToJson(plan, ev);
  std::map<std::string, std::string> svgs;
  for (const ReportFigure& f : reportFigures({plan, file, ev, ev_json})) svgs[f.name] = f.svg;
  ASSERT_TRUE(svgs.count("layout") && svgs.count("layout-side"));
  constexpr std::size_t kPoints = 26;  // 7 base, a1, 5 x (a, b, a), a1, centre, probe
  const auto top = polylinesOf(svgs["layout"], kPoints);
  const auto side = polylinesOf(svgs["layout-side"], kPoints);
  std::vector<const nlohmann::json*> readings;
  for (const nlohmann::json& placement : file.at("placements")) {
    for (const nlohmann::json& m : placement.at("measurements")) readings.push_back(&m);
  }
  ASSERT_EQ(top.size(), readings.size());
  ASSERT_EQ(side.size(), readings.size());
  auto point = [](const nlohmann::json& xyz) { return Eigen::Vector3d(xyz[0], xyz[1], xyz[2]); };
  std::vector<Eigen::Vector3d> base, platform;
  for (std::size_t i = 0; i < 6; ++i) {
    base.push_back(point(machine.at("base")[i]));
    platform.push_back(point(machine.at("platform")[i]));
  }
  // Scales from reading 0's base joints; the side view's y offset from z = 0 of the base.
  std::vector<Eigen::Vector2d> base_xy, base_xz, top_px, side_px;
  for (std::size_t i = 0; i < 6; ++i) {
    base_xy.emplace_back(base[i].x(), base[i].y());
    base_xz.emplace_back(base[i].x(), base[i].z());
    top_px.push_back(top[0][i]);
    side_px.push_back(side[0][i]);
  }
  const ViewScale plan_view = fitView(base_xy, top_px);
  ViewScale side_view = plan_view;        // the same mm per px and x offset are not assumed:
  side_view = fitView(base_xz, side_px);  // z = 0 leaves s to x alone, which suffices
  const Eigen::Vector3d probe = point(machine.at("probe"));
  constexpr double kTol = 0.5;  // mm: 0.1 px in views of about 0.5 px/mm, summed over points
  for (std::size_t r = 0; r < readings.size(); ++r) {
    SCOPED_TRACE(r);
    std::vector<Eigen::Vector3d> x;
    for (std::size_t k = 0; k < kPoints; ++k) {
      const Eigen::Vector2d xy = plan_view.toMm(top[r][k]), xz = side_view.toMm(side[r][k]);
      EXPECT_NEAR(xy.x(), xz.x(), kTol);
      x.emplace_back(xy.x(), xy.y(), xz.y());
    }
    const nlohmann::json& q = readings[r]->at("joints");
    std::vector<Eigen::Vector3d> a{x[7]};
    for (std::size_t i = 1; i < 6; ++i) a.push_back(x[5 + 3 * i]);
    for (std::size_t i = 0; i < 6; ++i) {
      EXPECT_LT((x[i] - base[i]).norm(), kTol) << "base joint " << i;
      EXPECT_NEAR((a[i] - base[i]).norm(), q[i].get<double>(), kTol) << "leg " << i;
      for (std::size_t j = 0; j < i; ++j) {
        EXPECT_NEAR((a[i] - a[j]).norm(), (platform[i] - platform[j]).norm(), kTol);
      }
    }
    for (std::size_t i = 1; i < 6; ++i) {  // each leg drawn out and back: a_i b_i a_i
      EXPECT_LT((x[6 + 3 * i] - base[i]).norm(), kTol);
      EXPECT_LT((x[7 + 3 * i] - a[i]).norm(), kTol);
    }
    EXPECT_LT((x[23] - a[0]).norm(), kTol);
    EXPECT_NEAR((x[25] - x[24]).norm(), probe.norm(), kTol);
  }
}

}  // namespace hexapod_test
}  // namespace artcal
