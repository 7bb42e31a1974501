// Choosing readings from a pool on the command line (issue 45): `optimize --choose N` on the
// UR5's recorded grid poses (tests/data/ur5-tracker), and `compare-designs` of subsets held out
// on its random poses.

#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "artcal/internal.hpp"
#include "cli_runner.hpp"
#include "temp_folder.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace compare_designs_test {

using nlohmann::json;

class Ur5Pool : public test_support::TempFolder {
 protected:
  Ur5Pool() : TempFolder("ur5-pool") {}
  void SetUp() override {
    TempFolder::SetUp();
    const std::string data = test_support::testDataFile("ur5-tracker");
    for (const std::string folder : {"train", "held-out"}) {
      ASSERT_EQ(
          test_support::runCli("import-readings " + data + "/" + folder + " --machine " + data +
                               "/ur5.machine.json --instrument 0.015 -o " + path(folder + ".json"))
              .status,
          0);
    }
  }
};

TEST_F(Ur5Pool, ChooseWritesAPlanOfTheChosenReadingsThatCalibrates) {
  const auto run = test_support::runCli("optimize " + path("train.json") +
                                        " --choose 12 --criterion D --starts 2 --json -o " +
                                        path("chosen.json"));
  ASSERT_EQ(run.status, 0) << run.out;
  const json summary = json::parse(run.out);
  EXPECT_EQ(summary["chosen"].size(), 12u);
  EXPECT_EQ(summary["pool"], 1000);
  EXPECT_EQ(summary["criterion"], "D");
  EXPECT_GT(summary["value_mm"].get<double>(), 0.0);
  const Plan chosen = loadPlan(path("chosen.json"));
  ASSERT_EQ(chosen.placements.size(), 1u);
  EXPECT_EQ(chosen.placements[0].measurements.size(), 12u);
  EXPECT_EQ(test_support::runCli("calibrate " + path("chosen.json")).status, 0);
}

TEST_F(Ur5Pool, CompareDesignsScoresEveryMethodAndTheWholeGrid) {
  const auto run = test_support::runCli(
      "compare-designs " + path("train.json") + " " + path("held-out.json") +
      " --sizes 12 --draws 2 --criteria worst-tip,D --starts 2 --quiet --json");
  ASSERT_EQ(run.status, 0) << run.out;
  const json out = json::parse(run.out);
  EXPECT_EQ(out["pool"], 1000);
  EXPECT_EQ(out["held_out_readings"], 20);
  // The whole grid holds out as the plain path does (tests/data/ur5-tracker/README.md).
  EXPECT_NEAR(out["all_readings"]["held_out_mean_mm"].get<double>(), 0.101, 0.002);
  const json& methods = out["sizes"][0]["methods"];
  for (const std::string method : {"worst-tip", "D", "farthest", "random"}) {
    ASSERT_TRUE(methods.contains(method)) << method;
    EXPECT_GT(methods[method]["held_out_mean_mm"]["median"].get<double>(), 0.09) << method;
  }
  EXPECT_EQ(methods["random"]["subsets"].size(), 2u);
  // G of the G choice is no worse than G of the D choice.
  EXPECT_LE(methods["worst-tip"]["subsets"][0]["worst_tip_mm"].get<double>(),
            methods["D"]["subsets"][0]["worst_tip_mm"].get<double>() * (1.0 + 1e-9));
}

TEST_F(Ur5Pool, SizesBeyondThePoolAreRefusedOnOneLine) {
  const auto compare = test_support::runCli(
      "compare-designs " + path("train.json") + " " + path("held-out.json") + " --sizes 1000",
      test_support::Stderr::Only);
  EXPECT_EQ(compare.status, 2);
  EXPECT_NE(compare.out.find("train.json: /placements: cannot compare subsets of 1000"),
            std::string::npos)
      << compare.out;
  EXPECT_EQ(std::count(compare.out.begin(), compare.out.end(), '\n'), 1);
  const auto choose =
      test_support::runCli("optimize " + path("train.json") + " --choose 1001 -o " + path("x.json"),
                           test_support::Stderr::Only);
  EXPECT_EQ(choose.status, 2);
  EXPECT_NE(choose.out.find("cannot choose 1001 of the pool's 1000 readings"), std::string::npos)
      << choose.out;
}

}  // namespace compare_designs_test
}  // namespace artcal
