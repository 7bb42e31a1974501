// Cartesian CMM plans (models.md section 4): the independent reference case
// tests/data/ref-cartesian-plate matched, and what the example plans in plans/cmm-*.json can
// identify.

#include <gtest/gtest.h>

#include <fstream>

#include "artcal/internal.hpp"
#include "artcal/estimation/error_functions.hpp"
#include "artcal/model/cartesian.hpp"
#include "artcal/report/cartesian_report.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace cartesian_plans_test {

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

std::vector<std::string> names(const nlohmann::json& list) {
  std::vector<std::string> out;
  for (const auto& name : list) out.push_back(name.get<std::string>());
  return out;
}

// The reference gives rotations' u in um/m and translations' in mm; artcal keeps rad and mm.
double referenceInternal(const std::string& name, double value) {
  const bool rotation = name.find(".r") != std::string::npos;
  return rotation ? value * 1e-6 : value;
}

TEST(CartesianReference, PlateInThreePlanesWithTwoStyliAndDiagonals) {
  const std::string base = test_support::testDataFile("ref-cartesian-plate");
  const Plan plan = loadPlan(base + ".json");
  const nlohmann::json expected = readJson(base + ".expected.json");
  const Evaluation ev = evaluatePlan(plan);
  const nlohmann::json got = evaluationToJson(plan, ev);
  EXPECT_EQ(got["identifiable"], expected["identifiable"]);
  EXPECT_EQ(got["rank"]["deficiency"], expected["rank"]["deficiency"]);
  for (const char* key : {"N_p", "N_b", "N_r", "satisfied"}) {
    EXPECT_EQ(got["counting"][key], expected["counting"][key]) << key;
  }
  EXPECT_EQ(names(got["calibrate_resolved"]), names(expected["calibrate_resolved"]));
  EXPECT_EQ(names(got["calibrate_dropped"]), names(expected["calibrate_dropped"]));
  ASSERT_TRUE(ev.covariance);
  const auto& reference = expected["parameters"];
  ASSERT_EQ(plan.machine.calibratedCount(), static_cast<int>(reference.size()));
  for (int k = 0; k < plan.machine.calibratedCount(); ++k) {
    const std::string name = reference[static_cast<std::size_t>(k)]["name"];
    EXPECT_EQ(plan.machine.calibratedInfo(k).name, name);
    const double u = referenceInternal(name, reference[static_cast<std::size_t>(k)]["u"]);
    EXPECT_NEAR(ev.covariance->u[k], u, 1e-6 * u) << name;
  }
  ASSERT_TRUE(ev.tip);
  const auto& worst = expected["tip"]["worst"];
  EXPECT_NEAR(got["tip"]["worst"]["total"].get<double>(), worst["total"].get<double>(),
              1e-6 * worst["total"].get<double>());
  EXPECT_NEAR(got["tip"]["worst"]["kinematic"].get<double>(), worst["kinematic"].get<double>(),
              1e-6 * worst["kinematic"].get<double>());
  EXPECT_NEAR(got["tip"]["worst"]["encoder"].get<double>(), worst["encoder"].get<double>(),
              1e-6 * worst["encoder"].get<double>());
  EXPECT_NEAR(got["tip"]["mean"].get<double>(), expected["tip"]["mean"].get<double>(),
              1e-6 * expected["tip"]["mean"].get<double>());
}

Plan examplePlan(const std::string& name) {
  return loadPlan(test_support::planFile(name + ".json"));
}

// One stylus on the ram's axis: every frame rotation is absorbed by the placements, and the
// functions with no lever arm to the probe (ram tilts and roll, carriage yaw) stay unseparated.
TEST(CartesianAnswers, OneStylusAbsorbsEveryFrameRotation) {
  const Plan plan = examplePlan("cmm-plate-3planes");
  const CartesianAnswers answers = cartesianAnswers(plan, nullptr);
  ASSERT_EQ(answers.absorbed.size(), 3u);
  for (int a = 0; a < 3; ++a) {
    EXPECT_TRUE(
        answers.absorbed[static_cast<std::size_t>(a)].axis.isApprox(Eigen::Vector3d::Unit(a)));
    EXPECT_FALSE(answers.held_by_frame[static_cast<std::size_t>(a)].empty());
  }
  std::vector<std::string> functions;
  for (const auto& f : answers.unseparated) {
    functions.push_back(f.function);
    EXPECT_EQ(f.degrees, (std::vector<int>{1, 2, 3})) << f.function;
  }
  EXPECT_EQ(functions, (std::vector<std::string>{"x.rz", "z.rx", "z.ry", "z.rz"}));
  // 54 coefficients = 39 calibrated + 3 held by the frame + 4 functions x 3 degrees.
  EXPECT_EQ(plan.machine.calibratedCount(), 54 - 3 - 12);
}

// Styli offset by d: only the rotation about d is absorbed (models.md section 4).
TEST(CartesianAnswers, TwoStyliLeaveOnlyTheRotationAboutTheirOffset) {
  const Plan plan = examplePlan("cmm-plate-3planes-2styli");
  const auto* cmm = axisErrorFunctionsOf(plan);
  ASSERT_TRUE(cmm);
  const Eigen::Vector3d d = (cmm->styli()[1] - cmm->styli()[0]).normalized();
  const CartesianAnswers answers = cartesianAnswers(plan, nullptr);
  ASSERT_EQ(answers.absorbed.size(), 1u);
  EXPECT_NEAR(std::abs(answers.absorbed[0].axis.dot(d)), 1.0, 1e-9);
}

// The profile of a function is g^T V g over its calibrated degrees: at the axis's ends
// (P_n(+-1) = (+-1)^n) it is the uncertainty of the sum (or alternating sum) of its coefficients.
TEST(CartesianAnswers, ProfileEndsAreSumsOfTheCoefficients) {
  const Plan plan = examplePlan("cmm-plate-3planes-2styli");
  const Evaluation ev = evaluatePlan(plan);
  ASSERT_TRUE(ev.covariance);
  const CartesianAnswers answers = cartesianAnswers(plan, &ev, 5);
  ASSERT_EQ(answers.profiles.size(), 18u);
  const auto* cmm = axisErrorFunctionsOf(plan);
  for (const ErrorFunctionProfile& f : answers.profiles) {
    for (const int end : {0, 4}) {
      Eigen::VectorXd g = Eigen::VectorXd::Zero(plan.machine.calibratedCount());
      for (int k = 0; k < plan.machine.calibratedCount(); ++k) {
        for (const int n : f.calibrated_degrees) {
          if (plan.machine.calibrated[static_cast<std::size_t>(k)] ==
              cmm->parameterIndex(f.axis, f.error, n)) {
            g[k] = (end == 0 && n % 2 == 1) ? -1.0 : 1.0;
          }
        }
      }
      const double u = std::sqrt(g.dot(ev.covariance->V * g));
      EXPECT_NEAR(f.u[static_cast<std::size_t>(end)], u, 1e-12 + 1e-9 * u) << f.name;
    }
  }
}

TEST(CartesianPlans, StylusOfEachReadingIsReadAndWritten) {
  const Plan plan = examplePlan("cmm-plate-3planes-2styli");
  ASSERT_EQ(plan.placements[0].measurements[1].stylus, 1);
  EXPECT_EQ(plan.placements[0].measurements[0].stylus, 0);
  const nlohmann::json written = placementsToJson(plan);
  EXPECT_EQ(written[0]["measurements"][1]["stylus"], 1);
  EXPECT_FALSE(written[0]["measurements"][0].contains("stylus"));
}
}  // namespace cartesian_plans_test
}  // namespace artcal
