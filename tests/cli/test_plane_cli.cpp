// The command line on plane plans (docs/planes.md): `optimize` on a plane's design writes a plan
// whose evaluation is the prediction it wrote, and `procedure` lists each touch at its planned
// point, on the placed face at the ball's radius, with the planned joints as its target.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
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

// import-readings of plane touches as a user holds them: one folder per placement with its
// pose.json and a feature_0.csv of joints whose header names them, the machine and the plane in
// files of their own. The flush table touches of plans/planes/arm6-flush.json, simulated for a
// machine off nominal, written out so and imported, calibrate to the estimates of the same
// readings given in the plan itself (same poses, same joints: to 1e-9).
TEST_F(PlaneCli, ImportedFlushTouchesCalibrateAsTheSamePlan) {
  const std::string truth =
      write("truth.json", R"({"parameters": {"j2.a": 0.2, "j3.theta": 0.02, "j5.d": 600.3}})");
  const std::string simulated = path("simulated.json");
  ASSERT_EQ(runCli("simulate " + planFile("planes/arm6-flush.json") + " --truth " + truth +
                   " --seed 3 -o " + simulated)
                .status,
            0);
  nlohmann::json plan = readJson(simulated);
  nlohmann::json tables = nlohmann::json::array();
  for (const nlohmann::json& placement : plan["placements"]) {
    if (placement["artifact"] != "table") continue;
    tables.push_back(placement);
    const std::string folder =
        "touches/" + std::to_string(tables.size()) + "_" + placement["name"].get<std::string>();
    write(folder + "/pose.json", placement["pose"].dump());
    std::string csv = "j1 deg,j2 deg,j3 deg,j4 deg,j5 deg,j6 deg\n";
    for (const nlohmann::json& m : placement["measurements"]) {
      ASSERT_EQ(m["feature"], 0);
      for (std::size_t i = 0; i < m["joints"].size(); ++i) {
        char value[40];
        std::snprintf(value, sizeof value, "%.17g", m["joints"][i].get<double>());
        csv += (i ? "," : "") + std::string(value);
      }
      csv += "\n";
    }
    write(folder + "/feature_0.csv", csv);
  }
  ASSERT_EQ(tables.size(), 3u);
  plan["placements"] = tables;
  plan["artifacts"] = {{"table", plan["artifacts"]["table"]}};
  const std::string given = write("given.json", plan.dump());
  const std::string machine =
      write("machine.json", nlohmann::json{{"machine", plan["machine"]}}.dump());
  const std::string artifact = write("table.json", plan["artifacts"].dump());
  const std::string imported = path("imported.json");
  const auto import =
      runCli("import-readings " + path("touches") + " --machine " + machine + " --artifact " +
             artifact + " --keep-calibrate --probe 0.01 --encoder 0.0005 -o " + imported);
  ASSERT_EQ(import.status, 0) << import.out;
  const auto a = runCli("calibrate --json " + given);
  const auto b = runCli("calibrate --json " + imported);
  ASSERT_EQ(a.status, 0) << a.out;
  ASSERT_EQ(b.status, 0) << b.out;
  const nlohmann::json from_plan = nlohmann::json::parse(a.out);
  const nlohmann::json from_files = nlohmann::json::parse(b.out);
  EXPECT_NEAR(from_files["chi2"].get<double>(), from_plan["chi2"].get<double>(),
              1e-9 * from_plan["chi2"].get<double>());
  ASSERT_EQ(from_files["parameters"].size(), from_plan["parameters"].size());
  for (std::size_t i = 0; i < from_plan["parameters"].size(); ++i) {
    EXPECT_EQ(from_files["parameters"][i]["name"], from_plan["parameters"][i]["name"]);
    EXPECT_NEAR(from_files["parameters"][i]["estimate"].get<double>(),
                from_plan["parameters"][i]["estimate"].get<double>(), 1e-9);
  }
}

// verify of plane touches lists each placement's faces (it listed none): per face the touches'
// count, their distances' mean and rms, which pooled over every face of every placement give the
// all-placements figures, and the predicted rms, whose pooled square is the predicted total; the
// mean touched point of a table face lies on that table (its pose's plane, the stylus's end).
TEST_F(PlaneCli, VerifyListsEachFaceOfEachPlacement) {
  const std::string plan_file = planFile("planes/arm6-flush.json");
  const std::string machine = path("cal.json");
  const std::string truth =
      write("truth.json", R"({"parameters": {"j2.a": 0.2, "j3.theta": 0.02, "j5.d": 600.3}})");
  ASSERT_EQ(
      runCli("simulate " + plan_file + " --truth " + truth + " --seed 1 -o " + path("sim.json"))
          .status,
      0);
  ASSERT_EQ(
      runCli("simulate " + plan_file + " --truth " + truth + " --seed 2 -o " + path("sim2.json"))
          .status,
      0);
  ASSERT_EQ(runCli("calibrate " + path("sim.json") + " --write-machine " + machine).status, 0);
  const auto run = runCli("verify --json " + path("sim2.json") + " --machine " + machine);
  ASSERT_EQ(run.status, 0) << run.out;
  const nlohmann::json verify = nlohmann::json::parse(run.out)["verify"];
  const nlohmann::json plan = readJson(plan_file);
  int touches = 0;
  double sum = 0.0, sum2 = 0.0, predicted2 = 0.0;
  for (std::size_t j = 0; j < plan["placements"].size(); ++j) {
    const nlohmann::json& faces = verify["placements"][j]["features"];
    ASSERT_FALSE(faces.empty()) << j;
    int in_placement = 0;
    for (const nlohmann::json& face : faces) {
      const int n = face["postures"].get<int>();
      in_placement += n;
      sum += n * face["spread_mean"].get<double>();
      sum2 += n * std::pow(face["spread_rms"].get<double>(), 2);
      predicted2 += n * std::pow(face["predicted_spread_rms"].get<double>(), 2);
    }
    EXPECT_EQ(in_placement, static_cast<int>(plan["placements"][j]["measurements"].size()));
    touches += in_placement;
    const nlohmann::json& pose = plan["placements"][j]["pose"];
    if (plan["placements"][j]["artifact"] != "table") continue;
    const Eigen::Vector3d normal = vector3(pose["direction"]).normalized();
    EXPECT_NEAR((vector3(faces[0]["mean_position"]) - vector3(pose["center"])).dot(normal), 0.0,
                0.05)
        << j;
  }
  EXPECT_NEAR(sum / touches, verify["spread_mean"].get<double>(), 1e-12);
  EXPECT_NEAR(std::sqrt(sum2 / touches), verify["spread_rms"].get<double>(), 1e-12);
  EXPECT_NEAR(std::sqrt(predicted2 / touches), verify["predicted_spread_rms"].get<double>(), 1e-12);
}

}  // namespace plane_cli_test
}  // namespace artcal
