// Instruments as artifacts (instruments.md): a tracker's stations calibrated from simulated
// readings, confirmed by Monte Carlo, and the stations the plan reader refuses.

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <numbers>

#include "artcal/artcal.hpp"
#include "artcal/calibration/calibrate_readings.hpp"
#include "artcal/calibration/station_verification.hpp"
#include "cli_runner.hpp"
#include "plan_builders.hpp"
#include "temp_folder.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace instrument_test {

nlohmann::json trackerDocument() {
  std::ifstream in(test_support::testDataFile("ref-instrument-arm6-2stations.json"));
  return nlohmann::json::parse(in);
}

std::string refusal(const nlohmann::json& document) {
  try {
    parsePlan(document, "tracker.json");
  } catch (const InputError& e) {
    return e.describe();
  }
  return "";
}

using testing::shiftedTruth;

TEST(Instrument, SimulatedTrackerReadingsCalibrateToTheTruthWithin3u) {
  Plan plan = parsePlan(trackerDocument(), "tracker.json");
  const Evaluation prediction = evaluatePlan(plan);
  ASSERT_TRUE(prediction.covariance);
  const Eigen::VectorXd truth = shiftedTruth(plan, prediction.covariance->u);
  NormalSource normal(7);
  plan.placements = Simulator(plan).simulate(truth, normal).placements;
  // The simulated points differ from the plan's (those of the nominal machine).
  EXPECT_GT((plan.placements[0].measurements[0].point -
             parsePlan(trackerDocument(), "tracker.json").placements[0].measurements[0].point)
                .norm(),
            0.0);
  const Calibration calibration = calibratePlan(plan);
  ASSERT_TRUE(calibration.summary.converged());
  ASSERT_TRUE(calibration.covariance);
  const Eigen::VectorXd error =
      calibration.estimate(plan.machine) - plan.machine.calibratedValues(truth);
  for (int k = 0; k < error.size(); ++k) {
    EXPECT_LT(std::abs(error[k]), 3.0 * calibration.covariance->u[k]) << "parameter " << k;
  }
  // chi2/dof near 1: the tracker's noise is in the weights (quadrature with the probe's).
  EXPECT_GT(calibration.chi2_per_dof, 0.5);
  EXPECT_LT(calibration.chi2_per_dof, 1.6);
}

TEST(Instrument, ConfirmConfirmsTheTrackerPlan) {
  const Plan plan = parsePlan(trackerDocument(), "tracker.json");
  ConfirmationOptions options;
  options.trials = 200;
  options.seed = 3;
  const Confirmation confirmation = confirmPlan(plan, options);
  EXPECT_EQ(confirmation.converged_trials, confirmation.trials);
  EXPECT_TRUE(confirmation.confirmed);
  EXPECT_NEAR(confirmation.mean_chi2_per_dof, 1.0, 0.1);
}

TEST(Instrument, AStationOfTwoReadingsIsRefusedNamingIt) {
  nlohmann::json document = trackerDocument();
  auto& readings = document["placements"][1]["measurements"];
  readings.erase(readings.begin() + 2, readings.end());
  const std::string what = refusal(document);
  EXPECT_NE(what.find("/placements/1"), std::string::npos) << what;
  EXPECT_NE(what.find("station 2"), std::string::npos) << what;
  EXPECT_NE(what.find("2 reading"), std::string::npos) << what;
}

TEST(Instrument, APoseMeasurementNeedsAModelWithOrientation) {
  nlohmann::json document = nlohmann::json::parse(R"({
    "format": "artcal-plan/1",
    "machine": {"model": "planar2r", "parameters": {"l1": 150, "l2": 100, "dt2": 0},
                "calibrate": ["l1", "l2", "dt2"]},
    "noise": {"probe": 0.01, "encoder": 0.001},
    "artifacts": {"tracker": {"type": "instrument", "measures": "pose", "noise": 0.02}},
    "placements": [{"artifact": "tracker", "measurements": [
      {"joints": [0, 30]}, {"joints": [40, 60]}, {"joints": [80, 20]}]}]})");
  const std::string what = refusal(document);
  EXPECT_NE(what.find("/artifacts/tracker/measures"), std::string::npos) << what;
  EXPECT_NE(what.find("orientation"), std::string::npos) << what;
}

TEST(Instrument, SimulatedPointsRoundTripThroughThePlanFile) {
  Plan plan = parsePlan(trackerDocument(), "tracker.json");
  NormalSource normal(11);
  plan.placements = Simulator(plan).simulate(plan.machine.nominal, normal).placements;
  nlohmann::json document = trackerDocument();
  document["placements"] = placementsToJson(plan);
  document["placements"][0]["name"] = "station 1";
  const Plan reread = parsePlan(document, "tracker.json");
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    for (std::size_t i = 0; i < plan.placements[j].measurements.size(); ++i) {
      EXPECT_LT(
          (reread.placements[j].measurements[i].point - plan.placements[j].measurements[i].point)
              .norm(),
          1e-9);
    }
  }
}

// Without its points a tracker plan is for planning only: calibrate refuses it, naming the reading.
TEST(Instrument, CalibrateNeedsTheMeasuredPoints) {
  nlohmann::json document = trackerDocument();
  for (auto& reading : document["placements"][1]["measurements"]) reading.erase("point");
  Plan plan = parsePlan(document, "tracker.json");
  try {
    calibrateReadings(plan);
    FAIL() << "calibrated a reading without its point";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "/placements/1/measurements/0");
  }
}

// The reference plan's points are the nominal machine's, without noise: at nominal a station
// fitted on the first 10 readings predicts the other 15 exactly.
TEST(Instrument, VerifyAtTheMachineThatMadeThePointsDeviatesByNothing) {
  Plan plan = parsePlan(trackerDocument(), "tracker.json");
  for (Placement& placement : plan.placements) {
    for (std::size_t i = 0; i < 10; ++i) placement.measurements[i].stationing = true;
  }
  const StationsVerification v = verifyStations(plan, plan.machine.nominal, std::nullopt);
  ASSERT_EQ(v.stations.size(), 2u);
  EXPECT_EQ(v.stations[0].stationing, 10);
  EXPECT_EQ(v.stations[0].summary.count, 15);
  EXPECT_EQ(v.all.count, 30);
  EXPECT_LT(v.all.max, 1e-9);
}

// Held-out stations of a calibrated machine: the observed RMS agrees with the predicted one
// (30 held-out distances: a statistical band), and the nominal machine does far worse.
TEST(Instrument, VerifyHeldOutStationsAgainstThePrediction) {
  Plan plan = parsePlan(trackerDocument(), "tracker.json");
  const Evaluation prediction = evaluatePlan(plan);
  ASSERT_TRUE(prediction.covariance);
  const Eigen::VectorXd truth = shiftedTruth(plan, 10.0 * prediction.covariance->u);
  Plan calibration_plan = plan;
  NormalSource normal(21);
  calibration_plan.placements = Simulator(plan).simulate(truth, normal).placements;
  const Calibration calibration = calibratePlan(calibration_plan);
  ASSERT_TRUE(calibration.summary.converged());
  const auto uncertainty = calibration.uncertainty(plan.machine);
  ASSERT_TRUE(uncertainty);
  Plan held = plan;
  NormalSource other(22);
  held.placements = Simulator(plan).simulate(truth, other).placements;
  for (Placement& placement : held.placements) {
    for (std::size_t i = 0; i < 10; ++i) placement.measurements[i].stationing = true;
  }
  const StationsVerification v = verifyStations(held, calibration.parameters, uncertainty);
  ASSERT_GT(v.all.predicted_rms, 0.0);
  EXPECT_GT(v.all.rms, 0.6 * v.all.predicted_rms);
  EXPECT_LT(v.all.rms, 1.5 * v.all.predicted_rms);
  const StationsVerification nominal = verifyStations(held, plan.machine.nominal, std::nullopt);
  EXPECT_GT(nominal.all.rms, 2.0 * v.all.rms);
}

// The command line: a collinear station is exit 2 with one line naming it; verify of the
// nominal points at nominal reports the stations' held-out figures (zero deviations).
TEST(Instrument, CommandLineRefusesACollinearStationAndVerifiesStations) {
  const std::string collinear = test_support::testDataFile("ref-instrument-arm6-collinear.json");
  const test_support::CliRun refused =
      test_support::runCli("check " + collinear, test_support::Stderr::Only);
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.out.find(collinear + ": /placements/1: station \"station 2\""),
            std::string::npos)
      << refused.out;
  EXPECT_EQ(std::count(refused.out.begin(), refused.out.end(), '\n'), 1);
  const std::string plan = test_support::testDataFile("ref-instrument-arm6-2stations.json");
  const test_support::CliRun verified = test_support::runCli("verify --json " + plan);
  ASSERT_EQ(verified.status, 0);
  const nlohmann::json out = nlohmann::json::parse(verified.out);
  ASSERT_EQ(out["instrument"]["stations"].size(), 2u);
  EXPECT_EQ(out["instrument"]["all"]["readings"], 50);
  EXPECT_LT(out["instrument"]["all"]["max"].get<double>(), 1e-9);
  // Stations alone: no artifact figures (each reading would be a feature of one posture and every
  // pair of readings a "length"), only the stations' table.
  EXPECT_FALSE(out.contains("verify"));
  const test_support::CliRun table = test_support::runCli("verify " + plan);
  ASSERT_EQ(table.status, 0);
  EXPECT_NE(table.out.find("2 stations verified"), std::string::npos) << table.out;
  EXPECT_EQ(table.out.find("length error"), std::string::npos) << table.out;
  EXPECT_LT(std::count(table.out.begin(), table.out.end(), '\n'), 12) << table.out;
}

// A total station's session the plain way (issue 21): a 4 m lifting-column robot whose origins
// are 4 mm (per coordinate) off its URDF, five stations of 30 configurations simulated
// (tests/data/lifting-column-stations*.json) and written as a ROS user exports them: rad and m,
// a header naming the units. Three stations are imported as they are and calibrated, two are held
// out: against the calibrated machine their deviations fall to what the calibration predicts,
// from 16 mm against the URDF.
class PlainStations : public test_support::TempFolder {
 protected:
  PlainStations() : TempFolder("plain-stations") {}

  /// Station `j` of a simulated plan as a CSV file of `folder`: column m, joints rad, point m.
  void writeStation(const nlohmann::json& simulated, std::size_t j, const std::string& folder) {
    const nlohmann::json& station = simulated["placements"][j];
    std::string text = "column_m,j1_rad,j2_rad,j3_rad,j4_rad,j5_rad,j6_rad,x_m,y_m,z_m\n";
    char value[40];
    for (const nlohmann::json& m : station["measurements"]) {
      const auto q = m["joints"].get<std::vector<double>>();
      const auto x = m["point"].get<std::vector<double>>();
      std::vector<double> row = {q[0] * 1e-3};
      for (std::size_t i = 1; i < q.size(); ++i) row.push_back(q[i] * std::numbers::pi / 180.0);
      for (const double c : x) row.push_back(c * 1e-3);
      for (std::size_t i = 0; i < row.size(); ++i) {
        std::snprintf(value, sizeof value, "%.17g%c", row[i], i + 1 < row.size() ? ',' : '\n');
        text += value;
      }
    }
    write(folder + "/" + station["name"].get<std::string>() + ".csv", text);
  }
};

TEST_F(PlainStations, LiftingColumnCalibratesAndVerifiesOnHeldOutStations) {
  using test_support::runCli;
  const std::string simulated = path("simulated.json");
  ASSERT_EQ(runCli("simulate " + test_support::testDataFile("lifting-column-stations.json") +
                   " --truth " + test_support::testDataFile("lifting-column-stations.truth.json") +
                   " --seed 3 -o " + simulated)
                .status,
            0);
  const nlohmann::json stations = nlohmann::json::parse(std::ifstream(simulated));
  ASSERT_EQ(stations["placements"].size(), 5u);
  for (std::size_t j = 0; j < 5; ++j) writeStation(stations, j, j < 3 ? "train" : "held");
  const std::string urdf = test_support::testDataFile("urdf/lifting-column-arm6.urdf");
  const auto import = [&](const std::string& folder) {
    return runCli("import-readings " + path(folder) + " --urdf " + urdf +
                  " --base base_link --tip prism_link --instrument 1.0 -o " +
                  path(folder + ".json"))
        .status;
  };
  ASSERT_EQ(import("train"), 0);
  ASSERT_EQ(import("held"), 0);
  const auto calibrated =
      runCli("calibrate --json " + path("train.json") + " --write-machine " + path("cal.json"));
  ASSERT_EQ(calibrated.status, 0);
  const nlohmann::json calibration = nlohmann::json::parse(calibrated.out);
  EXPECT_TRUE(calibration["converged"].get<bool>());
  for (const nlohmann::json& p : calibration["parameters"])  // no parameter kept on rounding
    EXPECT_LT(p["u"].get<double>(), 5.0) << p["name"];
  const auto verified = [&](const std::string& machine) {
    const auto run = runCli("verify --json " + path("held.json") + machine);
    EXPECT_EQ(run.status, 0);
    return nlohmann::json::parse(run.out)["instrument"]["all"];
  };
  const nlohmann::json nominal = verified(""), held = verified(" --machine " + path("cal.json"));
  EXPECT_EQ(held["readings"], 60);
  EXPECT_GT(nominal["rms"].get<double>(), 10.0);
  const double predicted = held["predicted_rms"].get<double>();
  EXPECT_GT(held["rms"].get<double>(), 0.7 * predicted);
  EXPECT_LT(held["rms"].get<double>(), 1.3 * predicted);
  EXPECT_LT(held["rms"].get<double>(), 0.2 * nominal["rms"].get<double>());
}

}  // namespace instrument_test
}  // namespace artcal
