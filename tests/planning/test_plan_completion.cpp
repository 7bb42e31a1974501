// `artcal plan --complete` (docs/plan-format.md, "Readings planned from a layout"): a placement
// with a pose and {"feature": k, "postures": N} gets N nominal readings of feature k. Checked
// against the feature positions computed here from the pose (feature 0 at the centre, feature 1
// at centre + length * direction), the joint limits, and the planner's own rule.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "artcal/internal.hpp"
#include "artcal/planning/design_space.hpp"
#include "artcal/planning/plan_completion.hpp"
#include "cli_runner.hpp"
#include "temp_folder.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace plan_completion_test {

namespace fs = std::filesystem;
using nlohmann::json;
using test_support::runCli;
using test_support::Stderr;
using test_support::testDataFile;

class Layout : public test_support::TempFolder {
 protected:
  Layout() : TempFolder("layout") {}
  std::string write(const std::string& name, const json& document) const {
    return TempFolder::write(name, document.dump(1));
  }
};

/// The Panda of the chain reference case, a 50 mm bar at two poses, 3 + 3 and 4 + 2 postures.
json pandaLayout() {
  json plan = readJsonFile(testDataFile("ref-chain-panda-2placements.json"));
  plan["placements"] = {
      {{"name", "front"},
       {"artifact", "bar"},
       {"pose", {{"center", {500, 0, 200}}, {"direction", {0, 1, 0}}}},
       {"measurements", {{{"feature", 0}, {"postures", 3}}, {{"feature", 1}, {"postures", 3}}}}},
      {{"name", "left"},
       {"artifact", "bar"},
       {"pose", {{"center", {300, 300, 100}}, {"direction", {1, 1, 0}}}},
       {"measurements", {{{"feature", 0}, {"postures", 4}}, {{"feature", 1}, {"postures", 2}}}}}};
  return plan;
}

/// Feature k of a 3-D ball bar of `length` at pose (center, direction): center + k L d/|d|.
Eigen::Vector3d barFeature(const json& pose, int k, double length) {
  const auto c = pose["center"].get<std::vector<double>>();
  const auto d = pose["direction"].get<std::vector<double>>();
  const Eigen::Vector3d direction = Eigen::Vector3d(d[0], d[1], d[2]).normalized();
  return Eigen::Vector3d(c[0], c[1], c[2]) + k * length * direction;
}

TEST_F(Layout, CompletedReadingsReachTheFeaturesWithinTheJointLimits) {
  const json layout = pandaLayout();
  const std::string in = write("layout.json", layout);
  // A plan with readings still to plan is not run.
  const auto refused = runCli("check " + in, Stderr::Only);
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.out.find("/placements/0/measurements/0: readings to be planned"),
            std::string::npos)
      << refused.out;
  ASSERT_EQ(runCli("plan --complete " + in + " -o " + path("done.json")).status, 0);
  const json done = readJsonFile(path("done.json"));
  EXPECT_EQ(done["placements"][1]["name"], "left");
  const Plan plan = loadPlan(path("done.json"));
  const std::vector<std::vector<int>> postures = {{3, 3}, {4, 2}};
  for (std::size_t j = 0; j < 2; ++j) {
    const Placement& placement = plan.placements[j];
    std::vector<int> count(2, 0);
    for (const Measurement& m : placement.measurements) {
      ++count[static_cast<std::size_t>(m.feature)];
      const Eigen::Vector3d target = barFeature(layout["placements"][j]["pose"], m.feature, 50.0);
      Eigen::VectorXd x;
      ASSERT_EQ(plan.machine.mechanism->forward(plan.machine.nominal, m.joints, x),
                ForwardStatus::Ok);
      EXPECT_LT((x - target).norm(), 1e-9) << j << " feature " << m.feature;
      for (int i = 0; i < m.joints.size(); ++i) {
        const auto [lo, hi] = plan.machine.joint_limits[static_cast<std::size_t>(i)];
        EXPECT_GE(m.joints[i], lo);
        EXPECT_LE(m.joints[i], hi);
      }
    }
    EXPECT_EQ(count, postures[j]);
    // Postures of one feature differ (the diverse-posture rule, not one solution repeated).
    for (std::size_t a = 0; a < placement.measurements.size(); ++a)
      for (std::size_t b = a + 1; b < placement.measurements.size(); ++b)
        EXPECT_GT((placement.measurements[a].joints - placement.measurements[b].joints).norm(),
                  1e-3);
  }
  // Everything but the requests is kept as it was.
  json expected = layout;
  json actual = done;
  for (auto* d : {&expected, &actual})
    for (json& p : (*d)["placements"]) p.erase("measurements");
  EXPECT_EQ(actual, expected);
}

TEST_F(Layout, SameSeedSameReadingsAndThePlannersRule) {
  const std::string in = write("layout.json", pandaLayout());
  ASSERT_EQ(runCli("plan --complete " + in + " -o " + path("a.json") + " --seed 7").status, 0);
  ASSERT_EQ(runCli("plan --complete " + in + " -o " + path("b.json") + " --seed 7").status, 0);
  EXPECT_EQ(readJsonFile(path("a.json")), readJsonFile(path("b.json")));
  // The readings are those of the planner's rule (featureReadings on the machine narrowed by
  // the default joint margin), drawn in order from one generator seeded with the seed.
  const Plan layout = parsePlan(pandaLayout(), in, false);
  const Machine narrowed =
      withJointMargin(layout.machine, defaultJointMargin(*layout.machine.mechanism));
  std::mt19937_64 rng(7);
  const Plan done = loadPlan(path("a.json"));
  for (std::size_t j = 0; j < layout.placements.size(); ++j) {
    const Eigen::MatrixXd features =
        placedFeatures(layout.artifacts[0], *layout.placements[j].pose);
    std::size_t next = 0;
    for (const PostureRequest& r : layout.placements[j].posture_requests) {
      for (const Measurement& m :
           featureReadings(narrowed, r.feature, features.col(r.feature), r.postures, rng)) {
        const Measurement& written = done.placements[j].measurements[next++];
        EXPECT_EQ(written.feature, m.feature);
        EXPECT_LT((written.joints - m.joints).cwiseAbs().maxCoeff(), 1e-12);
      }
    }
  }
}

TEST_F(Layout, PlanarArmGetsBothElbowBranches) {
  json plan = readJsonFile(testDataFile("ref-2r-5bars.json"));
  plan["placements"] = {
      {{"artifact", plan["artifacts"].begin().key()},
       {"pose", {{"center", {120, 40}}, {"angle", 30}}},
       {"measurements", {{{"feature", 0}, {"postures", 2}}, {{"feature", 1}, {"postures", 2}}}}}};
  const std::string in = write("2r.json", plan);
  ASSERT_EQ(runCli("plan --complete " + in + " -o " + path("2r-done.json")).status, 0);
  const Plan done = loadPlan(path("2r-done.json"));
  const double length = plan["artifacts"].begin().value()["length"].get<double>();
  const double angle = 30.0 * std::numbers::pi / 180.0;
  const Eigen::Vector2d center(120, 40), axis(std::cos(angle), std::sin(angle));
  ASSERT_EQ(done.placements[0].measurements.size(), 4u);
  for (const Measurement& m : done.placements[0].measurements) {
    Eigen::VectorXd x;
    ASSERT_EQ(done.machine.mechanism->forward(done.machine.nominal, m.joints, x),
              ForwardStatus::Ok);
    EXPECT_LT((x - (center + m.feature * length * axis)).norm(), 1e-9);
  }
  // The two postures of a feature are the two elbow branches: t2 of opposite signs.
  const auto& ms = done.placements[0].measurements;
  EXPECT_LT(ms[0].joints[1] * ms[1].joints[1], 0.0);
}

TEST_F(Layout, UnreachablePoseIsBadInputNamingTheRequest) {
  json plan = pandaLayout();
  plan["placements"][1]["pose"]["center"] = {3000, 0, 0};  // far beyond the Panda's reach
  const std::string in = write("far.json", plan);
  const auto run = runCli("plan --complete " + in + " -o " + path("far-done.json"), Stderr::Only);
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.out.find("far.json: /placements/1/measurements/0: only 0 of 4 postures reach"),
            std::string::npos)
      << run.out;
  EXPECT_FALSE(fs::exists(path("far-done.json")));
  // A request without a pose, and an output that would replace the input.
  plan = pandaLayout();
  plan["placements"][0].erase("pose");
  const auto posed = runCli(
      "plan --complete " + write("nopose.json", plan) + " -o " + path("x.json"), Stderr::Only);
  EXPECT_EQ(posed.status, 2);
  EXPECT_NE(posed.out.find("/placements/0/measurements/0: \"postures\" needs the placement's pose"),
            std::string::npos)
      << posed.out;
  EXPECT_EQ(runCli("plan --complete " + in + " -o " + in).status, 2);
}

}  // namespace plan_completion_test
}  // namespace artcal
