// The command line on plane plans (docs/planes.md): `optimize` on a plane's design writes a plan
// whose evaluation is the prediction it wrote, and `procedure` lists each touch at its planned
// point, on the placed face at the ball's radius, with the planned joints as its target.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "temp_folder.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace plane_cli_test {

using test_support::planFile;
using test_support::runCli;

class PlaneCli : public test_support::TempFolder {
 protected:
  PlaneCli() : TempFolder("plane-cli") {}
};

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

Eigen::Vector3d vector3(const nlohmann::json& v) {
  return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

// The spec of plans/planes/arm6-planes.spec.json with fewer starts and touches (the test's
// time): the written plan identifies the arm (check exits 0) and `evaluate` of it gives the worst
// tip uncertainty the optimizer predicted, to rounding.
TEST_F(PlaneCli, OptimizeWritesAPlanWhoseEvaluationIsItsPrediction) {
  nlohmann::json spec = readJson(planFile("planes/arm6-planes.spec.json"));
  spec["design"]["starts"] = 2;
  spec["design"]["postures"] = 8;
  spec["workspace"]["samples"] = 500;
  const std::string spec_file = write("spec.json", spec.dump());
  const std::string plan_file = path("optimized.json");
  const auto optimize = runCli("optimize " + spec_file + " -o " + plan_file + " --seed 3");
  ASSERT_EQ(optimize.status, 0) << optimize.out;
  const nlohmann::json written = readJson(plan_file);
  ASSERT_TRUE(written.contains("predicted"));
  int table_placements = 0;
  for (const auto& placement : written["placements"]) {
    if (placement["artifact"] != "table") continue;
    ++table_placements;
    EXPECT_EQ(placement["measurements"].size(), 8u);
  }
  EXPECT_EQ(table_placements, 3);
  EXPECT_EQ(runCli("check " + plan_file).status, 0);
  const auto evaluate = runCli("evaluate --json " + plan_file);
  ASSERT_EQ(evaluate.status, 0);
  const nlohmann::json figures = nlohmann::json::parse(evaluate.out);
  const double predicted = written["predicted"]["tip"]["worst"]["total"].get<double>();
  EXPECT_NEAR(figures["tip"]["worst"]["total"].get<double>(), predicted, 1e-9 * predicted);
}

// Every touch of a table placement of plans/planes/arm6-planes.json: its listed position is the
// ball's centre 3 mm (the radius) out from the face along the placement's stated normal, and its
// target joints are the plan's own.
TEST_F(PlaneCli, ProcedureListsEachTouchAtItsPlannedPointOnTheFace) {
  const std::string plan_file = planFile("planes/arm6-planes.json");
  const nlohmann::json plan = readJson(plan_file);
  const auto run = runCli("procedure --json " + plan_file);
  ASSERT_EQ(run.status, 0) << run.out;
  const nlohmann::json procedure = nlohmann::json::parse(run.out);
  ASSERT_EQ(procedure["placements"].size(), plan["placements"].size());
  int touches = 0;
  for (std::size_t j = 0; j < plan["placements"].size(); ++j) {
    const nlohmann::json& planned = plan["placements"][j];
    const nlohmann::json& listed = procedure["placements"][j];
    ASSERT_EQ(listed["readings"].size(), planned["measurements"].size());
    const Eigen::Vector3d center = vector3(planned["pose"]["center"]);
    const Eigen::Vector3d normal = vector3(planned["pose"]["direction"]).normalized();
    for (std::size_t k = 0; k < planned["measurements"].size(); ++k) {
      const nlohmann::json& reading = listed["readings"][k];
      const nlohmann::json& joints = planned["measurements"][k]["joints"];
      for (std::size_t i = 0; i < joints.size(); ++i)
        EXPECT_NEAR(reading["joints"][i].get<double>(), joints[i].get<double>(), 1e-9);
      EXPECT_EQ(reading["planned_offset"].get<double>(), 0.0);
      if (planned["artifact"] != "table") continue;
      EXPECT_NEAR((vector3(reading["position"]) - center).dot(normal), 3.0, 1e-6)
          << "placement " << j << " reading " << k;
      ++touches;
    }
  }
  EXPECT_EQ(touches, 90);
}

}  // namespace plane_cli_test
}  // namespace artcal
