// Plan files (plan-format.md): a valid plan read into internal units, and the wrong-input table:
// each row breaks one field of a valid plan and names the exact JSON pointer and a fragment of
// the message the InputError must carry.

#include <gtest/gtest.h>

#include <numbers>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>

#include "artcal/internal.hpp"

namespace artcal {
namespace plan_io_test {

using nlohmann::json;

// A valid planar plan using every field of the format, including a design block.
json planarPlan() {
  return json::parse(R"({
    "format": "artcal-plan/1",
    "name": "table",
    "description": "every field",
    "machine": {
      "model": "planar2r",
      "parameters": {"l1": 150.0, "l2": 100.0, "dt2": 0.5},
      "calibrate": ["l1", "l2", "dt2"],
      "joint_limits": [[-180, 180], [-170, 170]]
    },
    "noise": {"probe": 0.005, "encoder": 0.001},
    "artifacts": {
      "bar80": {"type": "ball_bar", "length": 80.0, "u_length": 0.001},
      "plate": {"type": "ball_plate", "centers": [[0, 0], [50, 0], [0, 30]], "u": 0.002},
      "gauge": {"type": "step_gauge", "positions": [0, 20, 50], "u": 0.0005}
    },
    "placements": [
      {"artifact": "bar80", "pose": {"center": [171.6, 170.2], "angle": 180.0},
       "measurements": [{"feature": 0, "joints": [32.71309177481814, 29.791234742508053]},
                        {"feature": 1, "joints": [31.0, 80.2]}]},
      {"artifact": "plate",
       "measurements": [{"feature": 2, "joints": [10, 20]}]}
    ],
    "workspace": {"samples": 64, "seed": 3},
    "design": {"artifact": "bar80", "placements": 5, "postures": 1,
               "region": {"reach": [55, 245]}, "criterion": "worst-tip",
               "seed": 1, "starts": 4, "time_limit": 10}
  })");
}

// A valid serial plan: a revolute and a prismatic joint.
json serialPlan() {
  return json::parse(R"({
    "format": "artcal-plan/1",
    "machine": {
      "model": "serial-dh",
      "joints": [{"type": "revolute", "theta": 0, "d": 200, "a": 10, "alpha": 90},
                 {"type": "prismatic", "theta": 5, "d": 0, "a": 0, "alpha": 0}],
      "probe": [0, 0, 50],
      "joint_limits": [[-180, 180], [0, 500]]
    },
    "noise": {"probe": 0.01, "encoder": [0.001, 0.002]},
    "artifacts": {"bar": {"type": "ball_bar", "length": 300.0}},
    "placements": [
      {"artifact": "bar", "pose": {"center": [103.8, -531.4, 200], "direction": [0, 1, 0], "roll": 0},
       "measurements": [{"feature": 0, "joints": [10, 491.33000782790947]},
                        {"feature": 1, "joints": [20, 200]}]}
    ],
    "workspace": {"grid": [5, 3]}
  })");
}

TEST(PlanIo, ValidPlanReadInInternalUnits) {
  const Plan plan = parsePlan(planarPlan(), "table.json");
  EXPECT_EQ(plan.name, "table");
  EXPECT_NEAR(plan.machine.nominal[2], degToRad(0.5), 1e-15);
  EXPECT_NEAR(plan.noise.encoder[1], degToRad(0.001), 1e-18);
  ASSERT_EQ(plan.artifacts.size(), 3u);
  ASSERT_EQ(plan.placements.size(), 2u);
  EXPECT_NEAR(plan.placements[0].measurements[1].joints[1], degToRad(80.2), 1e-15);
  EXPECT_NEAR(plan.placements[0].pose->angle, degToRad(180.0), 1e-15);
  EXPECT_EQ(plan.workspace.kind, WorkspaceSpec::Kind::Samples);
  EXPECT_EQ(plan.workspace.samples, 64);
  ASSERT_TRUE(plan.design);
  EXPECT_EQ(plan.design->placements, 5);
  EXPECT_EQ(plan.design->pool, 0);  // automatic
  EXPECT_FALSE(plan.design->target_tip);
  EXPECT_TRUE(plan.warnings.empty());

  const Plan arm = parsePlan(serialPlan(), "arm.json");
  EXPECT_EQ(arm.machine.mechanism->jointKind(1), JointKind::Prismatic);
  EXPECT_NEAR(arm.machine.nominal[4], degToRad(5.0), 1e-15);  // j2.theta
  EXPECT_DOUBLE_EQ(arm.noise.encoder[1], 0.002);              // mm: prismatic
  EXPECT_DOUBLE_EQ(arm.placements[0].measurements[1].joints[1], 200.0);
  EXPECT_EQ(arm.machine.calibratedCount(), 4 * 2 + 3);  // default: all
  EXPECT_EQ(workspaceConfigurations(arm.machine, arm.workspace).size(), 15u);
}

// design.pool and design.target_tip (mm), the optional effort and sweep fields of a spec.
TEST(PlanIo, DesignPoolAndTargetTipRead) {
  json doc = planarPlan();
  doc["design"]["pool"] = 450;
  doc["design"]["target_tip"] = 0.0105;
  const Plan plan = parsePlan(doc, "spec.json");
  ASSERT_TRUE(plan.design);
  EXPECT_EQ(plan.design->pool, 450);
  ASSERT_TRUE(plan.design->target_tip);
  EXPECT_DOUBLE_EQ(*plan.design->target_tip, 0.0105);
  EXPECT_EQ(OptimizerOptions::fromDesign(*plan.design).pool_size, 450);
  doc["design"]["evaluations"] = 12000;
  doc["design"]["polish"] = 4;
  doc["design"]["kicks"] = 16;
  const OptimizerOptions effort = OptimizerOptions::fromDesign(*parsePlan(doc, "spec.json").design);
  EXPECT_EQ(effort.refine_evaluations, 12000);
  EXPECT_EQ(effort.polish, 4);
  EXPECT_EQ(effort.kicks, 16);
  for (const char* field : {"evaluations", "polish", "kicks"}) {
    json bad = doc;
    bad["design"][field] = -1;
    EXPECT_THROW(parsePlan(bad, "spec.json"), InputError) << field;
  }
}

// machine.prior: defaults by kind (mm, deg), a named parameter in its own file unit, written back.
TEST(PlanIo, ParameterPriorReadInInternalUnitsAndWrittenBack) {
  json doc = planarPlan();
  doc["machine"]["prior"] = {{"default", {{"length", 0.5}, {"angle", 0.1}}}, {"l2", 0.02}};
  const Plan plan = parsePlan(doc, "table.json");
  ASSERT_EQ(plan.machine.prior_sigma.size(), 3);
  EXPECT_DOUBLE_EQ(plan.machine.prior_sigma[0], 0.5);
  EXPECT_DOUBLE_EQ(plan.machine.prior_sigma[1], 0.02);
  EXPECT_NEAR(plan.machine.prior_sigma[2], 0.1 * std::numbers::pi / 180.0, 1e-18);
  const json written = machineToJson(plan.machine, plan.machine.nominal);
  EXPECT_DOUBLE_EQ(written["prior"]["dt2"].get<double>(), 0.1);
  EXPECT_DOUBLE_EQ(written["prior"]["l2"].get<double>(), 0.02);
  for (const json& bad :
       {json{{"l3", 0.1}}, json{{"l1", -0.1}}, json{{"default", {{"lenght", 1}}}}}) {
    json wrong = planarPlan();
    wrong["machine"]["prior"] = bad;
    EXPECT_THROW(parsePlan(wrong, "table.json"), InputError) << bad.dump();
  }
}

// An unknown field is an error naming it, with the nearest known key; "x-" keys are extensions.
TEST(PlanIo, UnknownFieldsAreErrorsWithDidYouMean) {
  json doc = planarPlan();
  doc["noise"]["probbe"] = 1;
  try {
    parsePlan(doc, "table.json");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "/noise/probbe");
    EXPECT_NE(std::string(e.what()).find("did you mean \"probe\"?"), std::string::npos) << e.what();
  }
  json extended = planarPlan();
  extended["x-lab"] = {{"operator", "K. T."}};
  extended["artifacts"]["bar80"]["x-serial"] = "BB-80-17";
  EXPECT_NO_THROW(parsePlan(extended, "table.json"));
  json far = planarPlan();
  far["machine"]["completely_unrelated"] = 1;
  try {
    parsePlan(far, "table.json");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "/machine/completely_unrelated");
    EXPECT_EQ(std::string(e.what()).find("did you mean"), std::string::npos) << e.what();
  }
}

struct BadRow {
  std::string what;
  std::function<json()> document;
  std::string pointer;
  std::string fragment;
};

json withPlanar(const std::function<void(json&)>& change) {
  json doc = planarPlan();
  change(doc);
  return doc;
}

json withSerial(const std::function<void(json&)>& change) {
  json doc = serialPlan();
  change(doc);
  return doc;
}

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

std::vector<BadRow> badRows() {
  return {
      // top level
      {"format missing", [] { return withPlanar([](json& d) { d.erase("format"); }); }, "/format",
       "missing field"},
      {"format wrong", [] { return withPlanar([](json& d) { d["format"] = "artcal-plan/2"; }); },
       "/format", "unsupported format"},
      {"format not a string", [] { return withPlanar([](json& d) { d["format"] = 1; }); },
       "/format", "expected a string"},
      {"name not a string", [] { return withPlanar([](json& d) { d["name"] = 3; }); }, "/name",
       "expected a string"},
      {"document not an object", [] { return json::array(); }, "/", "expected an object"},
      // machine
      {"machine missing", [] { return withPlanar([](json& d) { d.erase("machine"); }); },
       "/machine", "missing field"},
      {"model unknown", [] { return withPlanar([](json& d) { d["machine"]["model"] = "scara"; }); },
       "/machine/model", "unknown model"},
      {"parameter missing",
       [] { return withPlanar([](json& d) { d["machine"]["parameters"].erase("l1"); }); },
       "/machine/parameters/l1", "missing field"},
      {"parameter negative",
       [] { return withPlanar([](json& d) { d["machine"]["parameters"]["l2"] = -100.0; }); },
       "/machine/parameters/l2", "must be positive"},
      {"parameter non-finite",
       [] { return withPlanar([](json& d) { d["machine"]["parameters"]["dt2"] = kNaN; }); },
       "/machine/parameters/dt2", "finite"},
      {"parameter unknown",
       [] { return withPlanar([](json& d) { d["machine"]["parameters"]["l3"] = 1.0; }); },
       "/machine/parameters/l3", "unknown parameter"},
      {"calibrate unknown name",
       [] { return withPlanar([](json& d) { d["machine"]["calibrate"][1] = "l9"; }); },
       "/machine/calibrate/1", "unknown parameter \"l9\""},
      {"calibrate repeated",
       [] { return withPlanar([](json& d) { d["machine"]["calibrate"][2] = "l1"; }); },
       "/machine/calibrate/2", "named twice"},
      {"calibrate empty",
       [] { return withPlanar([](json& d) { d["machine"]["calibrate"] = json::array(); }); },
       "/machine/calibrate", "at least 1"},
      {"calibrate not an array",
       [] { return withPlanar([](json& d) { d["machine"]["calibrate"] = "l1"; }); },
       "/machine/calibrate", "expected a list of parameter names"},
      {"joint_limits wrong count",
       [] { return withPlanar([](json& d) { d["machine"]["joint_limits"].erase(1); }); },
       "/machine/joint_limits", "1 entry, but the machine described has 2 joints"},
      {"joint_limits reversed",
       [] { return withPlanar([](json& d) {
              d["machine"]["joint_limits"][1] = {170, -170};
            }); },
       "/machine/joint_limits/1", "lower < upper"},
      {"joint_limits pair of three",
       [] { return withPlanar([](json& d) {
              d["machine"]["joint_limits"][0] = {1, 2, 3};
            }); },
       "/machine/joint_limits/0", "expected 2 numbers, got 3"},
      {"joints missing", [] { return withSerial([](json& d) { d["machine"].erase("joints"); }); },
       "/machine/joints", "missing field"},
      {"joints empty",
       [] { return withSerial([](json& d) { d["machine"]["joints"] = json::array(); }); },
       "/machine/joints", "at least 1"},
      {"joint type unknown",
       [] { return withSerial([](json& d) { d["machine"]["joints"][1]["type"] = "spherical"; }); },
       "/machine/joints/1/type", "unknown joint type"},
      {"joint value not a number",
       [] { return withSerial([](json& d) { d["machine"]["joints"][0]["a"] = "10"; }); },
       "/machine/joints/0/a", "expected a number"},
      {"probe wrong count",
       [] { return withSerial([](json& d) {
              d["machine"]["probe"] = {0, 50};
            }); },
       "/machine/probe", "expected 3 numbers, got 2"},
      {"probe missing", [] { return withSerial([](json& d) { d["machine"].erase("probe"); }); },
       "/machine/probe", "missing field"},
      {"prismatic joint without limits",
       [] { return withSerial([](json& d) { d["machine"].erase("joint_limits"); }); }, "/machine",
       "prismatic"},
      // noise
      {"noise missing", [] { return withPlanar([](json& d) { d.erase("noise"); }); }, "/noise",
       "missing field"},
      {"probe noise negative",
       [] { return withPlanar([](json& d) { d["noise"]["probe"] = -0.005; }); }, "/noise/probe",
       "must be positive"},
      {"probe noise non-finite",
       [] { return withPlanar([](json& d) { d["noise"]["probe"] = kInf; }); }, "/noise/probe",
       "finite"},
      {"encoder noise negative",
       [] { return withPlanar([](json& d) { d["noise"]["encoder"] = -0.001; }); }, "/noise/encoder",
       "must not be negative"},
      {"encoder noise non-finite",
       [] { return withPlanar([](json& d) { d["noise"]["encoder"] = kNaN; }); }, "/noise/encoder",
       "finite"},
      {"encoder per joint wrong count",
       [] { return withSerial([](json& d) { d["noise"]["encoder"] = {0.001}; }); },
       "/noise/encoder", "expected 2 numbers, got 1"},
      {"encoder per joint negative",
       [] { return withSerial([](json& d) { d["noise"]["encoder"][1] = -0.002; }); },
       "/noise/encoder/1", "must not be negative"},
      {"encoder per joint non-finite",
       [] { return withSerial([](json& d) { d["noise"]["encoder"][0] = kInf; }); },
       "/noise/encoder/0", "finite"},
      {"encoder a string", [] { return withPlanar([](json& d) { d["noise"]["encoder"] = "x"; }); },
       "/noise/encoder", "expected a number"},
      // artifacts
      {"artifacts empty",
       [] { return withPlanar([](json& d) { d["artifacts"] = json::object(); }); }, "/artifacts",
       "at least one artifact"},
      {"artifact type unknown",
       [] { return withPlanar([](json& d) { d["artifacts"]["bar80"]["type"] = "hoop"; }); },
       "/artifacts/bar80/type", "unknown artifact type"},
      {"bar length missing",
       [] { return withPlanar([](json& d) { d["artifacts"]["bar80"].erase("length"); }); },
       "/artifacts/bar80/length", "missing field"},
      {"bar length zero",
       [] { return withPlanar([](json& d) { d["artifacts"]["bar80"]["length"] = 0; }); },
       "/artifacts/bar80/length", "must be positive"},
      {"bar u_length negative",
       [] { return withPlanar([](json& d) { d["artifacts"]["bar80"]["u_length"] = -1e-3; }); },
       "/artifacts/bar80/u_length", "must not be negative"},
      {"bar u_length non-finite",
       [] { return withPlanar([](json& d) { d["artifacts"]["bar80"]["u_length"] = kNaN; }); },
       "/artifacts/bar80/u_length", "finite"},
      {"plate centre of three numbers in 2-D",
       [] {
         return withPlanar([](json& d) { d["artifacts"]["plate"]["centers"][1] = {1, 2, 3}; });
       },
       "/artifacts/plate/centers/1", "expected 2 numbers, got 3"},
      {"plate of one centre",
       [] { return withPlanar([](json& d) {
              d["artifacts"]["plate"]["centers"] = {{0, 0}};
            }); },
       "/artifacts/plate/centers", "at least 2"},
      {"plate centres coincide",
       [] {
         return withPlanar([](json& d) { d["artifacts"]["plate"]["centers"] = {{1, 1}, {1, 1}}; });
       },
       "/artifacts/plate/centers", "coincide"},
      {"plate u negative",
       [] { return withPlanar([](json& d) { d["artifacts"]["plate"]["u"] = -1; }); },
       "/artifacts/plate/u", "must not be negative"},
      {"gauge positions repeated",
       [] {
         return withPlanar([](json& d) { d["artifacts"]["gauge"]["positions"] = {0, 20, 20}; });
       },
       "/artifacts/gauge/positions", "distinct"},
      {"gauge position not a number",
       [] {
         return withPlanar([](json& d) { d["artifacts"]["gauge"]["positions"][2] = nullptr; });
       },
       "/artifacts/gauge/positions/2", "expected a number"},
      {"gauge u non-finite",
       [] { return withPlanar([](json& d) { d["artifacts"]["gauge"]["u"] = kInf; }); },
       "/artifacts/gauge/u", "finite"},
      {"3-D plate collinear",
       [] {
         return withSerial([](json& d) {
           d["artifacts"]["plate"] = {{"type", "ball_plate"},
                                      {"centers", {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}}};
         });
       },
       "/artifacts/plate/centers", "collinear"},
      // placements
      {"placements missing", [] { return withPlanar([](json& d) { d.erase("placements"); }); },
       "/placements", "missing field"},
      {"placements empty",
       [] { return withPlanar([](json& d) { d["placements"] = json::array(); }); }, "/placements",
       "at least 1"},
      {"placement artifact unknown",
       [] { return withPlanar([](json& d) { d["placements"][1]["artifact"] = "bar81"; }); },
       "/placements/1/artifact", "unknown artifact \"bar81\""},
      {"placement measurements missing",
       [] { return withPlanar([](json& d) { d["placements"][1].erase("measurements"); }); },
       "/placements/1/measurements", "missing field"},
      {"placement measurements empty",
       [] {
         return withPlanar([](json& d) { d["placements"][0]["measurements"] = json::array(); });
       },
       "/placements/0/measurements", "at least 1"},
      {"feature index too large",
       [] {
         return withPlanar([](json& d) { d["placements"][0]["measurements"][1]["feature"] = 2; });
       },
       "/placements/0/measurements/1/feature", "at most 1"},
      {"feature index negative",
       [] {
         return withPlanar([](json& d) { d["placements"][1]["measurements"][0]["feature"] = -1; });
       },
       "/placements/1/measurements/0/feature", "at least 0"},
      {"feature index fractional",
       [] {
         return withPlanar([](json& d) { d["placements"][1]["measurements"][0]["feature"] = 0.5; });
       },
       "/placements/1/measurements/0/feature", "whole number"},
      {"joints wrong count",
       [] {
         return withPlanar([](json& d) {
           d["placements"][0]["measurements"][0]["joints"] = {1, 2, 3};
         });
       },
       "/placements/0/measurements/0/joints", "expected 2 numbers, got 3"},
      {"joint reading not a number",
       [] {
         return withPlanar(
             [](json& d) { d["placements"][0]["measurements"][1]["joints"][1] = "80.2"; });
       },
       "/placements/0/measurements/1/joints", "expected 2 numbers"},
      {"joint reading non-finite",
       [] {
         return withPlanar(
             [](json& d) { d["placements"][0]["measurements"][1]["joints"][0] = kNaN; });
       },
       "/placements/0/measurements/1/joints/0", "finite"},
      {"pose centre wrong count",
       [] { return withPlanar([](json& d) { d["placements"][0]["pose"]["center"] = {1}; }); },
       "/placements/0/pose/center", "expected 2 numbers, got 1"},
      {"pose angle not a number",
       [] { return withPlanar([](json& d) { d["placements"][0]["pose"]["angle"] = "30"; }); },
       "/placements/0/pose/angle", "expected a number"},
      {"3-D pose direction zero",
       [] {
         return withSerial([](json& d) { d["placements"][0]["pose"]["direction"] = {0, 0, 0}; });
       },
       "/placements/0/pose/direction", "must not be zero"},
      {"3-D pose direction missing",
       [] { return withSerial([](json& d) { d["placements"][0]["pose"].erase("direction"); }); },
       "/placements/0/pose/direction", "missing field"},
      // workspace
      {"workspace two kinds",
       [] { return withPlanar([](json& d) {
              d["workspace"]["grid"] = {3, 3};
            }); }, "/workspace",
       "exactly one of"},
      {"workspace no kind",
       [] { return withPlanar([](json& d) { d["workspace"] = json::object(); }); }, "/workspace",
       "exactly one of"},
      {"samples zero", [] { return withPlanar([](json& d) { d["workspace"]["samples"] = 0; }); },
       "/workspace/samples", "at least 1"},
      {"samples fractional",
       [] { return withPlanar([](json& d) { d["workspace"]["samples"] = 2.5; }); },
       "/workspace/samples", "whole number"},
      {"seed negative", [] { return withPlanar([](json& d) { d["workspace"]["seed"] = -1; }); },
       "/workspace/seed", "at least 0"},
      {"grid wrong count", [] { return withSerial([](json& d) { d["workspace"]["grid"] = {5}; }); },
       "/workspace/grid", "at least 2"},
      {"grid zero points",
       [] { return withSerial([](json& d) { d["workspace"]["grid"][1] = 0; }); },
       "/workspace/grid/1", "at least 1"},
      {"configuration wrong count",
       [] {
         return withPlanar([](json& d) { d["workspace"] = {{"configurations", {{0, 0}, {1}}}}; });
       },
       "/workspace/configurations/1", "expected 2 numbers, got 1"},
      {"configurations empty",
       [] {
         return withPlanar([](json& d) { d["workspace"] = {{"configurations", json::array()}}; });
       },
       "/workspace/configurations", "at least 1"},
      // design block
      {"design artifact unknown",
       [] { return withPlanar([](json& d) { d["design"]["artifact"] = "bar99"; }); },
       "/design/artifact", "unknown artifact"},
      {"design placements zero",
       [] { return withPlanar([](json& d) { d["design"]["placements"] = 0; }); },
       "/design/placements", "at least 1"},
      {"design postures zero",
       [] { return withPlanar([](json& d) { d["design"]["postures"] = 0; }); }, "/design/postures",
       "at least 1"},
      {"design region missing",
       [] { return withPlanar([](json& d) { d["design"].erase("region"); }); }, "/design/region",
       "missing field"},
      {"design region empty",
       [] { return withPlanar([](json& d) { d["design"]["region"] = json::object(); }); },
       "/design/region", "reach and/or box"},
      {"design reach reversed",
       [] { return withPlanar([](json& d) {
              d["design"]["region"]["reach"] = {245, 55};
            }); },
       "/design/region/reach", "min < max"},
      {"design box of one corner",
       [] { return withPlanar([](json& d) {
              d["design"]["region"]["box"] = {{0, 0}};
            }); },
       "/design/region/box", "at least 2"},
      {"design criterion unknown",
       [] { return withPlanar([](json& d) { d["design"]["criterion"] = "best"; }); },
       "/design/criterion", "unknown criterion"},
      {"design seed negative", [] { return withPlanar([](json& d) { d["design"]["seed"] = -3; }); },
       "/design/seed", "at least 0"},
      {"design starts zero", [] { return withPlanar([](json& d) { d["design"]["starts"] = 0; }); },
       "/design/starts", "at least 1"},
      {"design time_limit zero",
       [] { return withPlanar([](json& d) { d["design"]["time_limit"] = 0; }); },
       "/design/time_limit", "must be positive"},
      {"design pool zero", [] { return withPlanar([](json& d) { d["design"]["pool"] = 0; }); },
       "/design/pool", "at least 1"},
      {"design target_tip negative",
       [] { return withPlanar([](json& d) { d["design"]["target_tip"] = -0.01; }); },
       "/design/target_tip", "must be positive"},
      {"design joint_margin negative",
       [] { return withPlanar([](json& d) { d["design"]["joint_margin"] = -1; }); },
       "/design/joint_margin", "must not be negative"},
      {"design joint_margin per joint wrong count",
       [] { return withPlanar([](json& d) {
              d["design"]["joint_margin"] = {1, 2, 3};
            }); },
       "/design/joint_margin", "expected 2 numbers, got 3"},
      {"design joint_margin leaves no range",
       [] { return withPlanar([](json& d) { d["design"]["joint_margin"] = 175; }); },
       "/design/joint_margin", "leaves nothing of joint 2's range"},
      // plausibility (issue 9; docs/hardening.md)
      {"reading outside joint_limits",
       [] {
         return withPlanar(
             [](json& d) { d["placements"][0]["measurements"][1]["joints"][1] = 171; });
       },
       "/placements/0/measurements/1/joints/1", "outside its joint_limits [-170, 170] deg"},
      {"readings in radians",
       [] {
         return withPlanar([](json& d) {
           for (json& m : d["placements"][0]["measurements"])
             for (json& q : m["joints"]) q = q.get<double>() * std::numbers::pi / 180.0;
         });
       },
       "/placements/0", "check the units"},
      {"machine in metres",
       [] {
         return withSerial([](json& d) {
           d["machine"]["joints"][0]["d"] = 0.2;
           d["machine"]["joints"][0]["a"] = 0.01;
           d["machine"]["probe"] = {0, 0, 0.05};
           d["placements"][0]["measurements"][0]["joints"][1] = 0.49133;  // prismatic, metres
           d["placements"][0]["measurements"][1]["joints"][1] = 0.2;
         });
       },
       "/placements/0", "check the units"},
      {"pose 5 m away",
       [] { return withPlanar([](json& d) {
              d["placements"][0]["pose"]["center"] = {5000, 0};
            }); },
       "/placements/0/pose", "check the pose"},
  };
}

TEST(PlanIo, WrongInputTableNamesPointerAndMessage) {
  for (const BadRow& row : badRows()) {
    SCOPED_TRACE(row.what);
    try {
      parsePlan(row.document(), "bad.json");
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), "bad.json");
      EXPECT_EQ(e.pointer(), row.pointer) << e.describe();
      EXPECT_NE(std::string(e.what()).find(row.fragment), std::string::npos) << e.describe();
      EXPECT_EQ(e.describe().find('\n'), std::string::npos);
    }
  }
}

TEST(PlanIo, DesignSpecMayHaveNoPlacements) {
  json doc = planarPlan();
  doc.erase("placements");
  EXPECT_NO_THROW(parsePlan(doc, "spec.json", false));
  EXPECT_THROW(parsePlan(doc, "spec.json", true), InputError);
}

TEST(PlanIo, PlacementsWrittenBackReadTheSame) {
  const Plan plan = parsePlan(planarPlan(), "table.json");
  json doc = planarPlan();
  doc["placements"] = placementsToJson(plan);
  const Plan again = parsePlan(doc, "again.json");
  ASSERT_EQ(again.placements.size(), plan.placements.size());
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const auto& a = plan.placements[j].measurements;
    const auto& b = again.placements[j].measurements;
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].feature, b[i].feature);
      EXPECT_LT((a[i].joints - b[i].joints).norm(), 1e-14);
    }
  }
}

}  // namespace plan_io_test
}  // namespace artcal

namespace artcal {
namespace plan_io_test {

/// The seed's 2R plan of the reference case (5 bars), identifiable with all of l1, l2, dt2.
json referenceTwoArm() {
  std::ifstream in(std::filesystem::path(ARTCAL_TEST_DATA) / "ref-2r-5bars.json");
  return json::parse(in);
}

TEST(CalibrateChoice, ListedNamesComeFirstThenTheModelsOrder) {
  json document = referenceTwoArm();
  document["machine"]["calibrate"] = {{"identifiable", {"dt2"}}};
  const Plan plan = parsePlan(document, "plan.json");
  // dt2 first, then the model's own order for the rest (models.md section 1): l1, l2.
  EXPECT_EQ(plan.machine.calibrated, (std::vector<int>{2, 0, 1}));
  ASSERT_TRUE(plan.calibrate_resolution);
  EXPECT_EQ(plan.calibrate_resolution->listed, (std::vector<int>{2, 0, 1}));
  // The 5-bar plan identifies all three (the reference case), so none is left out any more.
  std::vector<int> kept = plan.calibrate_resolution->kept;
  std::sort(kept.begin(), kept.end());
  EXPECT_EQ(kept, (std::vector<int>{0, 1, 2}));
  EXPECT_TRUE(plan.calibrate_resolution->dropped.empty());
}

TEST(CalibrateChoice, TooFewEquationsAsksForPlacementsNotForFixedParameters) {
  json document = referenceTwoArm();
  document["placements"] = json::array({document["placements"][0]});
  const Plan plan = parsePlan(document, "plan.json");
  const PlanInformation information = planInformation(plan, plan.placements, plan.machine.nominal);
  const Identifiability id = analyseIdentifiability(plan, plan.placements, information);
  // One bar, one posture per ball: 2 x 2 coordinates less 3 rigid unknowns = 1 equation per
  // placement for N(p) = 3 parameters: m >= 3.
  EXPECT_FALSE(id.counting.satisfied);
  EXPECT_EQ(id.counting.minimum_alike, 3);
  const std::string table = identifiabilityTable(plan, id);
  EXPECT_NE(table.find("too few equations: placements like the first needed: m >= 3 (the plan "
                       "has 1)"),
            std::string::npos)
      << table;
  EXPECT_EQ(table.find("fix:"), std::string::npos) << table;
}

}  // namespace plan_io_test
}  // namespace artcal
