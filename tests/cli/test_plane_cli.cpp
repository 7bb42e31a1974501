// The command line on plane plans (docs/planes.md): `optimize` on a plane's design writes a plan
// whose evaluation is the prediction it wrote, and `procedure` lists each touch at its planned
// point, on the placed face at the ball's radius, with the planned joints as its target.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "artcal/core/units.hpp"
#include "artcal/io/plan_io.hpp"
#include "cli_runner.hpp"
#include "temp_folder.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace plane_cli_test {

using test_support::planFile;
using test_support::runCli;
using test_support::testDataFile;

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

// A peer's export of flush touches, as its users keep them: one CSV file per session, named
// columns in rad for every joint of the robot (more than the chain reads), text label fields
// before them, and a header that in some files names them at the end (its names 4 fields left of
// their values, 4 empty names after them). Imported the plain
// way (the files as DIR, two tips with --tip-of, no pose: the touches give the plane), the plan
// calibrates as the same readings written inline with their poses: the same minimum.
TEST_F(PlaneCli, PeerExportedTouchesOfTwoHandsImportAsTheSamePlan) {
  const std::string plan_file = planFile("planes/humanoid-flush.json");
  const std::string simulated = path("sim.json");
  ASSERT_EQ(runCli("simulate " + plan_file + " --truth " +
                   planFile("planes/humanoid-table.truth.json") + " --seed 1 -o " + simulated)
                .status,
            0);
  nlohmann::json plan = readJson(simulated);
  std::vector<std::string> joints;
  for (const nlohmann::json& joint : plan["machine"]["joints"])
    if (joint["type"] != "fixed") joints.push_back(joint["name"]);
  std::vector<std::string> columns = joints;
  columns.push_back("head_1_joint");  // a joint the chain does not read
  std::sort(columns.begin(), columns.end());
  nlohmann::json inline_placements = nlohmann::json::array();
  std::string files, tips;
  for (const nlohmann::json& placement : plan["placements"]) {
    if (placement["artifact"] != "table") continue;
    for (const std::string hand : {"left", "right"}) {
      const std::string tip = "gripper_" + hand + "_base_link";
      nlohmann::json split = placement;
      split["measurements"] = nlohmann::json::array();
      std::string name = placement["name"].get<std::string>() + "_" + hand;
      std::replace(name.begin(), name.end(), ' ', '_');
      split["name"] = name;
      // The left hand's files name the label fields (empty names); the right hand's start with
      // the names and end with the empty ones, the names 4 fields left of their values.
      std::string csv = hand == "left" ? ",,,,joint_names" : "joint_names";
      for (const std::string& c : columns) csv += "," + c;
      csv += hand == "left" ? "\n" : ",,,,\n";
      for (const nlohmann::json& m : placement["measurements"]) {
        if (m["tip"] != tip) continue;
        split["measurements"].push_back(m);
        csv += "gripper,talos/" + hand + "_gripper,handle,table/contact_1,joint_states";
        for (const std::string& c : columns) {
          const auto at = std::find(joints.begin(), joints.end(), c);
          const double deg =
              at == joints.end() ? 5.0 : m["joints"][at - joints.begin()].get<double>();
          char value[40];
          std::snprintf(value, sizeof value, ",%.17g", deg * M_PI / 180.0);
          csv += value;
        }
        csv += "\n";
      }
      inline_placements.push_back(split);
      files += " " + write("session/" + name + ".csv", csv);
      tips += " --tip-of " + name + "=" + tip;
    }
  }
  ASSERT_EQ(inline_placements.size(), 6u);
  plan["placements"] = inline_placements;
  plan["artifacts"] = {{"table", plan["artifacts"]["table"]}};
  const std::string given = write("given.json", plan.dump());
  const std::string artifact = write("table.json", plan["artifacts"].dump());
  const std::string urdf = " --urdf " + testDataFile("urdf/humanoid-small.urdf") +
                           " --base left_sole_link --tip gripper_left_base_link --tip "
                           "gripper_right_base_link";
  const std::string imported = path("imported.json");
  const std::string common = "import-readings" + files + urdf + " --artifact " + artifact +
                             " --unit rad --probe 0.02 --encoder 0.005 -o " + imported;
  const auto unsaid = runCli(common, test_support::Stderr::Only);
  EXPECT_EQ(unsaid.status, 2);
  EXPECT_NE(unsaid.out.find("which tip touched in this placement?"), std::string::npos)
      << unsaid.out;
  EXPECT_NE(unsaid.out.find("add --tip-of table_high_left=TIP"), std::string::npos) << unsaid.out;
  const auto import = runCli(common + tips, test_support::Stderr::Only);
  ASSERT_EQ(import.status, 0) << import.out;
  EXPECT_NE(import.out.find("table_high_right.csv: its header names its rows' last 18 fields "
                            "(the first 4 are unnamed"),
            std::string::npos)
      << import.out;
  nlohmann::json read = readJson(imported);
  ASSERT_EQ(read["placements"].size(), 6u);
  EXPECT_FALSE(read["machine"].contains("prior"));
  // --prior: the tolerances as built, the machine's default prior (mm, deg).
  ASSERT_EQ(runCli(common + tips + " --prior 5,0.5").status, 0);
  EXPECT_EQ(readJson(imported)["machine"]["prior"],
            nlohmann::json::parse(R"({"default": {"length": 5.0, "angle": 0.5}})"));
  EXPECT_EQ(runCli(common + tips + " --prior 5").status, 2);
  ASSERT_EQ(runCli(common + tips).status, 0);
  for (const nlohmann::json& placement : read["placements"]) {
    EXPECT_FALSE(placement.contains("pose"));
    const std::string name = placement["name"];
    const std::string hand = name.ends_with("_left") ? "left" : "right";
    EXPECT_EQ(placement["measurements"][0]["tip"], "gripper_" + hand + "_base_link");
  }
  // Without the gauge block some of the plan's parameters are not observed: both choose.
  plan["machine"]["calibrate"] = "identifiable";
  write("given.json", plan.dump());
  const auto a = runCli("calibrate --json " + given);
  const auto b = runCli("calibrate --json " + imported);
  ASSERT_EQ(a.status, 0);
  ASSERT_EQ(b.status, 0);
  const nlohmann::json from_plan = nlohmann::json::parse(a.out);
  const nlohmann::json from_files = nlohmann::json::parse(b.out);
  // The same minimum from two starts (the plan's poses, the touches' planes), to the solver's
  // stopping tolerance (it stops when the predicted cost change is negligible).
  EXPECT_NEAR(from_files["chi2"].get<double>(), from_plan["chi2"].get<double>(),
              1e-5 * from_plan["chi2"].get<double>());
  ASSERT_EQ(from_files["parameters"].size(), from_plan["parameters"].size());
  for (std::size_t i = 0; i < from_plan["parameters"].size(); ++i) {
    const nlohmann::json& p = from_plan["parameters"][i];
    EXPECT_EQ(from_files["parameters"][i]["name"], p["name"]);
    EXPECT_NEAR(from_files["parameters"][i]["estimate"].get<double>(), p["estimate"].get<double>(),
                0.01 * p["u"].get<double>())
        << p["name"];
  }
}

// A placement without a pose is where its touches put the plane; verify's flush figures: with
// the machine right (the nominal one, readings simulated from it)
// and no probe or encoder noise, a flush touch's height is 0 and its tilts are the drawn ones,
// u_tilt each: their RMS over 60 table touches is u_tilt within the Monte-Carlo's spread. Scored
// in the calibration's frames (--frame-of HELD=CALIBRATED), the same touches give the heights of
// another session's planes: wrong by the planes' distance, and said so per placement.
TEST_F(PlaneCli, VerifyGivesFlushTouchesHeightAndTiltsInEitherFrame) {
  nlohmann::json plan = readJson(planFile("planes/arm6-flush.json"));
  const double u_tilt = plan["artifacts"]["table"]["u_tilt"].get<double>();
  plan["noise"] = {{"probe", 1e-6}, {"encoder", 0.0}};
  plan["artifacts"]["table"]["flatness"] = 0.0;
  plan["placements"].erase(3);  // the gauge block
  const std::string quiet = write("quiet.json", plan.dump());
  const std::string truth = write("truth.json", R"({"parameters": {}})");
  ASSERT_EQ(
      runCli("simulate " + quiet + " --truth " + truth + " --seed 4 -o " + path("sim.json")).status,
      0);
  // Without its pose each placement is where its touches put it: the plane simulated (a point of
  // it, its outward normal), to the readings' noise.
  nlohmann::json no_pose = readJson(path("sim.json"));
  for (nlohmann::json& placement : no_pose["placements"]) placement.erase("pose");
  const Plan derived = parsePlan(no_pose, "no-pose.json");
  for (std::size_t j = 0; j < derived.placements.size(); ++j) {
    const nlohmann::json& pose = plan["placements"][j]["pose"];
    const Eigen::Vector3d normal = vector3(pose["direction"]).normalized();
    const Pose& found = *derived.placements[j].pose;
    EXPECT_LT((found.direction.normalized() - normal).norm(), 2.0 * degToRad(u_tilt));
    EXPECT_LT(std::abs(normal.dot(found.center - vector3(pose["center"]))), 1e-4);
  }
  const auto run = runCli("verify --json " + path("sim.json"));
  ASSERT_EQ(run.status, 0) << run.out;
  const nlohmann::json verify = nlohmann::json::parse(run.out)["verify"];
  ASSERT_TRUE(verify.contains("flush")) << verify.dump();
  EXPECT_EQ(verify["flush"]["touches"], 60);
  EXPECT_LT(verify["flush"]["height_rms"].get<double>(), 1e-4);
  for (const char* tilt : {"roll_rms_deg", "pitch_rms_deg"}) {
    EXPECT_GT(verify["flush"][tilt].get<double>(), 0.75 * u_tilt) << tilt;
    EXPECT_LT(verify["flush"][tilt].get<double>(), 1.25 * u_tilt) << tilt;
  }
  double pooled2 = 0.0;
  for (const nlohmann::json& placement : verify["placements"]) {
    const double h = placement["flush"]["height_rms"].get<double>();
    pooled2 += h * h * placement["flush"]["touches"].get<double>();
  }
  EXPECT_NEAR(std::sqrt(pooled2 / 60.0), verify["flush"]["height_rms"].get<double>(), 1e-12);

  // The calibration's frames: calibrate the same readings, then score placement "wall" in the
  // frame of "table" (another plane) and the others, named as the calibration's, in their own.
  ASSERT_EQ(runCli("calibrate " + path("sim.json") + " --write-machine " + path("cal.json")).status,
            0);
  const auto framed = runCli("verify --json " + path("sim.json") + " --machine " +
                             path("cal.json") + " --frame-of wall=table");
  ASSERT_EQ(framed.status, 0) << framed.out;
  const nlohmann::json placements = nlohmann::json::parse(framed.out)["verify"]["placements"];
  for (const nlohmann::json& placement : placements) {
    const std::string name = placement["name"];
    const nlohmann::json& in_frame = placement["in_calibration_frame"];
    EXPECT_EQ(in_frame["frame_of"], name == "wall" ? "table" : name);
    const double height = in_frame["flush"]["height_rms"].get<double>();
    if (name != "wall") {
      EXPECT_NEAR(height, placement["flush"]["height_rms"].get<double>(), 1e-6);
    } else {  // the wall's touches against the table's plane: tilted by the angle between them
      EXPECT_GT(in_frame["flush"]["roll_rms_deg"].get<double>() +
                    in_frame["flush"]["pitch_rms_deg"].get<double>(),
                10.0);
    }
  }
  // A session under another name is refitted only: the note says how to score it in the frame.
  nlohmann::json renamed = readJson(path("sim.json"));
  renamed["placements"][0]["name"] = "table_day2";
  write("renamed.json", renamed.dump());
  const auto hinted = runCli("verify " + path("renamed.json") + " --machine " + path("cal.json"),
                             test_support::Stderr::Only);
  EXPECT_EQ(hinted.status, 0);
  EXPECT_NE(hinted.out.find("--frame-of table_day2=table"), std::string::npos) << hinted.out;
  const auto unknown = runCli("verify " + path("sim.json") + " --machine " + path("cal.json") +
                                  " --frame-of nowhere=table",
                              test_support::Stderr::Only);
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.out.find("no placement \"nowhere\""), std::string::npos) << unknown.out;
}

}  // namespace plane_cli_test
}  // namespace artcal
