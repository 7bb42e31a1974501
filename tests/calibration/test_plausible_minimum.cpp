// The plausible minimum (issue 29, plausible_minimum.hpp): a converged fit whose corrections the
// plausibility rule flags is searched for another minimum of the same cost. The Panda's ball sits
// off its last joint's axis; the rank rule keeps panda_joint7.pitch (a turn about that axis) and
// panda_joint8.x, a polar chart of the ball's offset, so a few mm of offset become a large angle.
// Expected values independent of the search: the simulated truth, the circle the polar chart
// puts the ball on, and the two fits' forward kinematics (the same machine twice).

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "artcal/artcal.hpp"
#include "artcal/calibration/calibrate_readings.hpp"
#include "artcal/calibration/verification.hpp"
#include "artcal/core/units.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/report/calibration_report.hpp"
#include "cli_runner.hpp"
#include "temp_folder.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace plausible_minimum_test {

using nlohmann::json;

class PlausibleMinimum : public test_support::TempFolder {
 protected:
  PlausibleMinimum() : TempFolder("plausible-minimum") {}

  /// The plain plan of panda_4's positions `positions` (import-readings, its defaults).
  std::string imported(const std::vector<std::string>& positions, const std::string& name) {
    const std::string folder = path(name);
    std::filesystem::create_directories(folder);
    for (const std::string& p : positions) {
      std::filesystem::create_directory_symlink(
          test_support::testDataFile("mukca/mukca/panda_4/" + p), folder + "/" + p);
    }
    const std::string out = path(name + ".json");
    const auto run =
        test_support::runCli("import-readings " + folder + " --urdf " +
                                 test_support::testDataFile("mukca/mukca/urdf/panda.urdf") +
                                 " --base panda_link0 --tip ball_link --ball-bar 50 -o " + out,
                             test_support::Stderr::Merge);
    EXPECT_EQ(run.status, 0) << run.out;
    return out;
  }

  /// `plan` simulated by the machine with `truth` (named values over nominal), seed 7, loaded.
  Plan simulated(const std::string& plan, const json& truth) {
    const std::string truth_file = write("truth.json", json{{"parameters", truth}}.dump());
    const std::string out = path("simulated.json");
    const auto run =
        test_support::runCli("simulate " + plan + " --truth " + truth_file + " --seed 7 -o " + out);
    EXPECT_EQ(run.status, 0) << run.out;
    return loadPlan(out);
  }

  /// The mean over panda_4's `left`, `right` and `very-front` of verify's held-out spread rms and
  /// distance error (mm) of a machine file: the figures of tests/data/mukca/mukca/README.md.
  std::pair<double, double> heldOutFigures(const std::string& machine) {
    double rms = 0.0, distance = 0.0;
    for (const std::string held : {"left", "right", "very-front"}) {
      const std::string plan = std::filesystem::exists(path("held-" + held + ".json"))
                                   ? path("held-" + held + ".json")
                                   : imported({held}, "held-" + held);
      const auto run = test_support::runCli("verify " + plan + " --json --machine " + machine);
      const json verify = json::parse(run.out)["verify"];
      rms += verify["spread_rms"].get<double>() / 3.0;
      distance += verify["length_error_mean_abs"].get<double>() / 3.0;
    }
    return {rms, distance};
  }
};

int parameterIndex(const Plan& plan, const std::string& name) {
  const auto& parameters = plan.machine.mechanism->parameters();
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    if (parameters[i].name == name) return static_cast<int>(i);
  }
  ADD_FAILURE() << name;
  return 0;
}

/// The largest distance between the ball positions two parameter vectors give over the readings.
double largestTipDifference(const Plan& plan, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  double worst = 0.0;
  Eigen::VectorXd xa, xb;
  for (const Placement& placement : plan.placements) {
    for (const Measurement& m : placement.measurements) {
      EXPECT_EQ(plan.machine.mechanism->forward(a, m.joints, xa), ForwardStatus::Ok);
      EXPECT_EQ(plan.machine.mechanism->forward(b, m.joints, xb), ForwardStatus::Ok);
      worst = std::max(worst, (xa - xb).norm());
    }
  }
  return worst;
}

bool correctionWarned(const Calibration& c) {
  for (const std::string& w : c.warnings) {
    if (w.find(" is corrected by ") != std::string::npos) return true;
  }
  return false;
}

// A machine with a known second minimum: the nominal Panda but for its ball, 6 mm off the last
// joint's axis (panda_joint8.x -3, .y 5.2 mm, at 120 deg from the link's x), on the readings of
// panda_4's `front` position. The plain fit's polar chart turns panda_joint7 (flagged); the
// chosen minimum is the truth's Cartesian chart; both are the same machine.
TEST_F(PlausibleMinimum, AnOffAxisBallIsFittedInTheChartThatHasIt) {
  const Plan loaded = simulated(imported({"front"}, "front"),
                                json{{"panda_joint8.x", -3.0}, {"panda_joint8.y", 5.2}});
  const CalibrationRun run = calibrateReadings(loaded);
  const Plan& plan = run.decided;  // the chosen minimum's kept set
  const Calibration& c = run.calibration;
  ASSERT_TRUE(c.summary.converged()) << c.summary.message;
  ASSERT_TRUE(c.minimum);
  const MinimumChoice& m = *c.minimum;
  EXPECT_TRUE(m.alternative_chosen);
  ASSERT_TRUE(m.alternative);
  EXPECT_TRUE(m.alternative->flagged.empty());
  EXPECT_FALSE(correctionWarned(c));
  // The other minimum, reported: a turn of panda_joint7 beyond the 2 deg rule ...
  const int pitch = parameterIndex(plan, "panda_joint7.pitch");
  bool pitch_flagged = false;
  for (const ImplausibleCorrection& f : m.flagged.flagged) {
    if (f.parameter != pitch) continue;
    pitch_flagged = true;
    EXPECT_GT(std::abs(f.correction), 2.0 * kDegree);
  }
  EXPECT_TRUE(pitch_flagged);
  // ... whose radius panda_joint8.x puts the ball on the circle of the truth's offset: in the
  // link's frame the ball is off the axis by (x8, 0) + v0 (turned), v0 the URDF's own offset of
  // the ball (ball_joint 0.0777, -0.0421 mm, turned by panda_hand_joint's -45 deg), so
  // |(x8, 0) + v0| = |(-3, 5.2) + v0|.
  const Eigen::Rotation2Dd hand(-45.0 * kDegree);
  const Eigen::Vector2d v0 = hand * Eigen::Vector2d(0.07773732033005863, -0.04214022515884392);
  const double x8 = m.flagged.parameters[parameterIndex(plan, "panda_joint8.x")];
  EXPECT_NEAR((Eigen::Vector2d(x8, 0.0) + v0).norm(), (Eigen::Vector2d(-3.0, 5.2) + v0).norm(),
              0.05);
  // The chosen minimum has the truth's offset (within 5 u_posterior) ...
  ASSERT_TRUE(c.covariance);
  const Eigen::VectorXd u = c.posteriorU();
  for (const auto& [name, truth] : {std::pair{"panda_joint8.x", -3.0}, {"panda_joint8.y", 5.2}}) {
    const int i = parameterIndex(plan, name);
    const auto k = std::find(plan.machine.calibrated.begin(), plan.machine.calibrated.end(), i) -
                   plan.machine.calibrated.begin();
    ASSERT_LT(k, plan.machine.calibratedCount()) << name << " not kept";
    EXPECT_NEAR(c.parameters[i], truth, 5.0 * u[k]) << name;
  }
  // ... and both minima are the same machine: the same cost and the same ball positions.
  EXPECT_NEAR(m.alternative->chi2, m.flagged.chi2, 1e-3 * m.flagged.chi2);
  EXPECT_LT(largestTipDifference(loaded, m.flagged.parameters, c.parameters), 0.005);
  // The table and its JSON twin show both.
  const json out = calibrationToJson(plan, plan.placements, c);
  EXPECT_EQ(out["minimum"]["chosen"], "alternative");
  EXPECT_EQ(out["minimum"]["plausible"], true);
  EXPECT_EQ(out["minimum"]["flagged"]["flagged"][0]["name"], "panda_joint7.pitch");
  EXPECT_EQ(out["minimum"]["flagged"]["flagged"][0]["unit"], "deg");
  EXPECT_NEAR(out["minimum"]["alternative"]["chi2"].get<double>(), c.chi2, 1e-9 * c.chi2);
  const std::string table = calibrationTable(plan, plan.placements, c);
  EXPECT_NE(table.find("minimum: a plausible one"), std::string::npos) << table;
  EXPECT_NE(table.find("plain fit:         chi2 = "), std::string::npos) << table;
  EXPECT_NE(table.find("corrects panda_joint7.pitch by "), std::string::npos) << table;
}

// A correction the readings need stays flagged: a link 24 mm longer than nominal (panda_joint3.y
// -340 mm against -316 mm, beyond the rule's 15.8 mm) is no chart's artefact: no alternative is
// free of flagged corrections, so the plain fit stands with the link's correction and its warning.
TEST_F(PlausibleMinimum, ACorrectionTheReadingsNeedStaysFlagged) {
  const Plan plan = simulated(imported({"front"}, "front"), json{{"panda_joint3.y", -340.0}});
  const Calibration c = calibrateReadings(plan).calibration;
  ASSERT_TRUE(c.summary.converged()) << c.summary.message;
  ASSERT_TRUE(c.minimum);
  EXPECT_FALSE(c.minimum->alternative_chosen);
  const int link = parameterIndex(plan, "panda_joint3.y");
  EXPECT_NEAR(c.parameters[link], -340.0, 1.0);
  bool warned = false;
  for (const std::string& w : c.warnings) {
    warned = warned || w.rfind("panda_joint3.y is corrected by", 0) == 0;
  }
  EXPECT_TRUE(warned);
}

// A calibration whose corrections are plausible runs no search and reports no second minimum:
// the nominal Panda simulated.
TEST_F(PlausibleMinimum, APlausibleFitHasNoSecondMinimum) {
  const Plan plan = simulated(imported({"front"}, "front"), json::object());
  const Calibration c = calibrateReadings(plan).calibration;
  ASSERT_TRUE(c.summary.converged());
  if (c.minimum) {
    // The rank rule's chart of a ball 0.09 mm off the axis may still turn the joint: then an
    // alternative without it must have been taken.
    EXPECT_TRUE(c.minimum->alternative_chosen);
  }
  EXPECT_FALSE(correctionWarned(c));
}

// panda_4 trained on `front`, the plain documented path: the plain fit turns panda_joint7 by
// 141.8 deg; the chosen minimum has no flagged correction and is the same machine (the held-out
// positions' figures of the two agree to 1 um), so that the choice costs no accuracy.
// (The rank rule's set: the held-out choice that follows is the next test's.)
TEST_F(PlausibleMinimum, Panda4TrainedOnFrontTakesThePlausibleMinimum) {
  const Plan loaded = loadPlan(imported({"front"}, "front"));
  CalibrationOptions rank_only;
  rank_only.model_choice = ModelChoiceMode::Rank;
  const Calibration c = calibrateReadings(loaded, rank_only).calibration;
  ASSERT_TRUE(c.summary.converged()) << c.summary.message;
  ASSERT_TRUE(c.minimum);
  EXPECT_TRUE(c.minimum->alternative_chosen);
  EXPECT_FALSE(correctionWarned(c));
  ASSERT_FALSE(c.minimum->flagged.flagged.empty());
  EXPECT_GT(std::abs(c.minimum->flagged.flagged.front().correction), 100.0 * kDegree);
  EXPECT_LT(largestTipDifference(loaded, c.minimum->flagged.parameters, c.parameters), 0.005);
  for (const std::string held : {"left", "right", "very-front"}) {
    const Plan position = loadPlan(imported({held}, "held-" + held));
    const Verification chosen = verifyMachine(position, c.parameters, std::nullopt);
    const Verification flagged =
        verifyMachine(position, c.minimum->flagged.parameters, std::nullopt);
    EXPECT_NEAR(chosen.spread_rms, flagged.spread_rms, 1e-3) << held;
    EXPECT_NEAR(chosen.length_error_mean_abs, flagged.length_error_mean_abs, 1e-3) << held;
  }
}

std::vector<std::string> chosenRestored(const json& calibration) {
  for (const json& c : calibration["model_choice"]["candidates"])
    if (c["chosen"].get<bool>()) return c["restored"].get<std::vector<std::string>>();
  ADD_FAILURE() << "no candidate chosen";
  return {};
}

// panda_4 trained on `front`, the plain documented path: the weak-direction rule holds
// panda_joint6.y and panda_joint7.x (surviving fractions ~1e-8), and with one position Cp says
// that calibrating them again holds better; so it is, on the three positions it never saw: the
// independent calibration's figures (README: 0.363 mm rms spread, 0.156 mm distance error) are
// met, where holding them gives 0.377 / 0.166 mm.
TEST_F(PlausibleMinimum, Panda4TrainedOnFrontCalibratesTheWeakDirectionsAgainByCp) {
  const std::string plan = imported({"front"}, "front");
  const std::string machine = path("front.machine.json");
  const auto run = test_support::runCli("calibrate " + plan + " --json --write-machine " + machine);
  ASSERT_EQ(run.status, 0) << run.out;
  const json calibration = json::parse(run.out);
  EXPECT_EQ(calibration["model_choice"]["rule"], "mallows-cp");
  EXPECT_EQ(calibration["model_choice"]["decided_by"], "mallows-cp");
  EXPECT_EQ(chosenRestored(calibration),
            (std::vector<std::string>{"panda_joint6.y", "panda_joint7.x"}));
  const auto [rms, distance] = heldOutFigures(machine);
  EXPECT_LE(rms, 0.363);
  EXPECT_LE(distance, 0.156);

  // The rank rule's set alone (the weak directions held), written the same way: worse held out.
  const std::string held_machine = path("front-held.machine.json");
  ASSERT_EQ(test_support::runCli("calibrate " + plan + " --model-choice rank --write-machine " +
                                 held_machine)
                .status,
            0);
  const auto [held_rms, held_distance] = heldOutFigures(held_machine);
  EXPECT_GT(held_rms, rms + 0.01);
  EXPECT_GT(held_distance, distance + 0.005);
}

// Simulated readings of `front` by two machines: the one the weak directions were calibrated for
// (off nominal in them) gets them calibrated again; the rank rule's (nominal in them) does not.
TEST_F(PlausibleMinimum, TheWeakDirectionsComeBackOnlyWhereTheMachineIsOffNominalInThem) {
  const std::string plan = imported({"front"}, "front");
  const std::string restored = path("restored.machine.json");
  const std::string held = path("held.machine.json");
  ASSERT_EQ(test_support::runCli("calibrate " + plan + " --write-machine " + restored).status, 0);
  ASSERT_EQ(
      test_support::runCli("calibrate " + plan + " --model-choice rank --write-machine " + held)
          .status,
      0);
  for (const auto& [truth, expected] :
       {std::pair{restored, std::vector<std::string>{"panda_joint6.y", "panda_joint7.x"}},
        std::pair{held, std::vector<std::string>{}}}) {
    const std::string simulated = path("simulated.json");
    ASSERT_EQ(
        test_support::runCli("simulate " + plan + " --truth " + truth + " --seed 7 -o " + simulated)
            .status,
        0);
    const auto run = test_support::runCli("calibrate " + simulated + " --json");
    ASSERT_EQ(run.status, 0) << run.out;
    EXPECT_EQ(chosenRestored(json::parse(run.out)), expected) << truth;
  }
}

}  // namespace plausible_minimum_test
}  // namespace artcal
