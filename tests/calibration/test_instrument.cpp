// Instruments as artifacts (instruments.md): a tracker's stations calibrated from simulated
// readings, confirmed by Monte Carlo, and the stations the plan reader refuses.

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <numbers>

#include "artcal/internal.hpp"
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

/// The calibration converged and every calibrated parameter is within 3 u of `truth`.
void expectWithin3u(const Calibration& calibration, const Plan& plan,
                    const Eigen::VectorXd& truth) {
  ASSERT_TRUE(calibration.summary.converged());
  ASSERT_TRUE(calibration.covariance);
  const Eigen::VectorXd error =
      calibration.estimate(plan.machine) - plan.machine.calibratedValues(truth);
  for (int k = 0; k < error.size(); ++k) {
    EXPECT_LT(std::abs(error[k]), 3.0 * calibration.covariance->u[k]) << "parameter " << k;
  }
}

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
  expectWithin3u(calibration, plan, truth);
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

// Readings of the nominal machine of `plan` simulated 400 times with its noise (trial seeds of
// `seed`), `mark` applied to each trial's placements, each verified at nominal: the mean of the
// observed squared deviations (over `count` held-out readings) is `predicted2` within 4 of its
// standard errors (from the trials' spread).
template <typename Mark>
void expectMonteCarloMeanSquare(const Plan& plan, std::uint64_t seed, Mark mark, int count,
                                double predicted2) {
  const Simulator simulator(plan);
  constexpr int kTrials = 400;
  double sum = 0.0, sum2 = 0.0;
  for (int t = 0; t < kTrials; ++t) {
    NormalSource normal(trialSeed(seed, static_cast<std::uint64_t>(t)));
    Plan trial = plan;
    trial.placements = simulator.simulate(plan.machine.nominal, normal).placements;
    mark(trial.placements);
    const StationsVerification v = verifyStations(trial, plan.machine.nominal, std::nullopt);
    ASSERT_EQ(v.all.count, count);
    const double mean_square = v.all.rms * v.all.rms;
    sum += mean_square;
    sum2 += mean_square * mean_square;
  }
  const double mean = sum / kTrials;
  const double standard_error = std::sqrt((sum2 / kTrials - mean * mean) / (kTrials - 1));
  EXPECT_NEAR(mean, predicted2, 4.0 * standard_error)
      << "observed mean square " << mean << " mm^2, predicted " << predicted2 << " mm^2";
}

// The predicted RMS of held-out readings against a Monte-Carlo of the verification itself (fixed
// seeds): readings of the nominal machine simulated 400 times with the plan's noise, each station
// fitted on only 4 readings (the fit's own noise then adds about a third to the held-out mean
// square) and verified at nominal; the mean of the observed squared deviations is the predicted
// RMS squared within 4 of its standard errors (from the trials' spread).
TEST(Instrument, PredictedRmsOfHeldOutReadingsAgreesWithAMonteCarloOfTheStationFits) {
  Plan plan = parsePlan(trackerDocument(), "tracker.json");
  constexpr std::size_t kStationing = 4;
  const auto mark = [](std::vector<Placement>& placements) {
    for (Placement& placement : placements) {
      for (std::size_t i = 0; i < kStationing; ++i) placement.measurements[i].stationing = true;
    }
  };
  mark(plan.placements);
  const StationsVerification planned = verifyStations(plan, plan.machine.nominal, std::nullopt);
  const double predicted2 = planned.all.predicted_rms * planned.all.predicted_rms;
  ASSERT_GT(predicted2, 0.0);
  expectMonteCarloMeanSquare(plan, 43, mark, 2 * (25 - static_cast<int>(kStationing)), predicted2);
}

// The same Monte-Carlo with each station re-registered on the very readings it scores (no reading
// marked "stationing": verify's default, and its re-registered figures beside the calibration's
// frame). A fit on those readings takes up part of their own noise: the mean square is about
// (3n - 6) / 3n of the noise's over n readings of a 3-D point, where a prediction for independent
// readings said (3n + 6) / 3n (15 % too high at 25 readings; issue 43).
TEST(Instrument, PredictedRmsOfReadingsRegisteredOnThemselvesAgreesWithAMonteCarlo) {
  const Plan plan = parsePlan(trackerDocument(), "tracker.json");
  const StationsVerification planned = verifyStations(plan, plan.machine.nominal, std::nullopt);
  const double predicted2 = planned.all.predicted_rms * planned.all.predicted_rms;
  ASSERT_GT(predicted2, 0.0);
  expectMonteCarloMeanSquare(
      plan, 47, [](std::vector<Placement>&) {}, 2 * 25, predicted2);
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

// Pose instruments ("measures": "pose", instruments.md): the tracker plan with each reading's
// orientation (tests/support/plan_builders.hpp, poseTrackerDocument).

using testing::poseTrackerDocument;

/// The pose plan with its readings simulated from `truth` (seed `seed`).
Plan simulatedPosePlan(const Eigen::VectorXd& truth, std::uint64_t seed) {
  Plan plan = parsePlan(poseTrackerDocument(), "tracker-pose.json");
  NormalSource normal(seed);
  plan.placements = Simulator(plan).simulate(truth, normal).placements;
  return plan;
}

TEST(Instrument, SimulatedPoseReadingsCalibrateToTheTruthWithin3u) {
  const Plan nominal = parsePlan(poseTrackerDocument(), "tracker-pose.json");
  const Evaluation prediction = evaluatePlan(nominal);
  ASSERT_TRUE(prediction.covariance);
  // 30 u off nominal on every parameter, alternately up and down.
  const Eigen::VectorXd truth = shiftedTruth(nominal, 10.0 * prediction.covariance->u);
  Plan plan = simulatedPosePlan(truth, 7);
  ASSERT_EQ(plan.placements[0].measurements[0].orientation.size(), 3);
  const Calibration calibration = calibratePlan(plan);
  expectWithin3u(calibration, plan, truth);
  ASSERT_TRUE(calibration.covariance);
  for (int k = 0; k < calibration.covariance->u.size(); ++k) {
    // The calibration's u is the planned one (the same rows at the estimate).
    EXPECT_NEAR(calibration.covariance->u[k], prediction.covariance->u[k],
                0.05 * prediction.covariance->u[k]);
  }
  // 2 x 25 readings x 6 rows - 2 x 6 - 21: chi2/dof near 1 with the angular rows weighted right.
  EXPECT_EQ(calibration.dof, 267);
  EXPECT_GT(calibration.chi2_per_dof, 0.7);
  EXPECT_LT(calibration.chi2_per_dof, 1.3);
  // Each reading's standardised residual has the 6 rows.
  EXPECT_EQ(calibration.residuals.front().standardized.size(), 6);
}

Confirmation confirmPosePlan(int trials) {
  const Plan plan = parsePlan(poseTrackerDocument(), "tracker-pose.json");
  ConfirmationOptions options;
  options.trials = trials;
  options.seed = 5;
  return confirmPlan(plan, options);
}

TEST(Instrument, ConfirmConfirmsThePosePlan) {
  const Confirmation confirmation = confirmPosePlan(100);
  EXPECT_EQ(confirmation.converged_trials, confirmation.trials);
  EXPECT_TRUE(confirmation.confirmed);
  EXPECT_NEAR(confirmation.mean_chi2_per_dof, 1.0, 0.1);
}

// The issue's figure: 1000 trials (label long).
TEST(Instrument, ConfirmConfirmsThePosePlanInAThousandTrials) {
  const Confirmation confirmation = confirmPosePlan(1000);
  EXPECT_EQ(confirmation.converged_trials, 1000);
  EXPECT_TRUE(confirmation.confirmed);
  EXPECT_NEAR(confirmation.mean_chi2_per_dof, 1.0, 0.03);
}

TEST(Instrument, SimulatedPosesRoundTripThroughThePlanFile) {
  const Plan plan =
      simulatedPosePlan(parsePlan(poseTrackerDocument(), "tracker-pose.json").machine.nominal, 11);
  nlohmann::json document = poseTrackerDocument();
  document["placements"] = placementsToJson(plan);
  ASSERT_EQ(document["placements"][0]["measurements"][0]["point"].size(), 6u);
  const Plan reread = parsePlan(document, "tracker-pose.json");
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    for (std::size_t i = 0; i < plan.placements[j].measurements.size(); ++i) {
      const Measurement& a = plan.placements[j].measurements[i];
      const Measurement& b = reread.placements[j].measurements[i];
      EXPECT_LT((a.point - b.point).norm(), 1e-9);
      EXPECT_LT((a.orientation - b.orientation).norm(), 1e-12);
    }
  }
}

// The nominal pose readings at nominal: no deviation, of either kind; the prediction of the
// angular deviations is about sqrt(3) x noise_angle (its 3 coordinates) and a little more.
TEST(Instrument, VerifyPosesAtTheMachineThatMadeThemDeviatesByNothing) {
  Plan plan = parsePlan(poseTrackerDocument(), "tracker-pose.json");
  for (Placement& placement : plan.placements) {
    for (std::size_t i = 0; i < 10; ++i) placement.measurements[i].stationing = true;
  }
  const StationsVerification v = verifyStations(plan, plan.machine.nominal, std::nullopt);
  ASSERT_TRUE(v.angular_all);
  ASSERT_TRUE(v.stations[1].angular);
  EXPECT_EQ(v.angular_all->count, 30);
  EXPECT_LT(v.all.max, 1e-9);
  EXPECT_LT(v.angular_all->max, 1e-9);
  const double noise_deg = radToDeg(plan.artifacts[0].noise_angle);
  EXPECT_GT(v.angular_all->predicted_rms, std::sqrt(3.0) * noise_deg);
  EXPECT_LT(v.angular_all->predicted_rms, 1.2 * std::sqrt(3.0) * noise_deg);
}

// Held-out pose stations of a calibrated machine: the observed RMS of both deviations agrees
// with the prediction (30 held-out readings: a statistical band); the nominal machine is worse.
TEST(Instrument, VerifyHeldOutPoseStationsAgainstThePrediction) {
  const Plan plan = parsePlan(poseTrackerDocument(), "tracker-pose.json");
  const Evaluation prediction = evaluatePlan(plan);
  ASSERT_TRUE(prediction.covariance);
  const Eigen::VectorXd truth = shiftedTruth(plan, 10.0 * prediction.covariance->u);
  const Calibration calibration = calibratePlan(simulatedPosePlan(truth, 21));
  ASSERT_TRUE(calibration.summary.converged());
  const auto uncertainty = calibration.uncertainty(plan.machine);
  ASSERT_TRUE(uncertainty);
  Plan held = simulatedPosePlan(truth, 22);
  for (Placement& placement : held.placements) {
    for (std::size_t i = 0; i < 10; ++i) placement.measurements[i].stationing = true;
  }
  const StationsVerification v = verifyStations(held, calibration.parameters, uncertainty);
  ASSERT_TRUE(v.angular_all);
  EXPECT_GT(v.all.rms, 0.6 * v.all.predicted_rms);
  EXPECT_LT(v.all.rms, 1.5 * v.all.predicted_rms);
  EXPECT_GT(v.angular_all->rms, 0.6 * v.angular_all->predicted_rms);
  EXPECT_LT(v.angular_all->rms, 1.5 * v.angular_all->predicted_rms);
  const StationsVerification nominal = verifyStations(held, plan.machine.nominal, std::nullopt);
  EXPECT_GT(nominal.all.rms, 2.0 * v.all.rms);
  EXPECT_GT(nominal.angular_all->rms, 1.5 * v.angular_all->rms);
}

TEST(Instrument, APoseInstrumentNeedsItsAngularNoise) {
  nlohmann::json document = poseTrackerDocument();
  document["artifacts"]["tracker"].erase("noise_angle");
  const std::string what = refusal(document);
  EXPECT_NE(what.find("/artifacts/tracker"), std::string::npos) << what;
  EXPECT_NE(what.find("noise_angle"), std::string::npos) << what;
  document["artifacts"]["tracker"]["noise_angle"] = 0;
  EXPECT_NE(refusal(document).find("/artifacts/tracker/noise_angle"), std::string::npos);
  // A point of 3 numbers where a pose is measured: the reading's pointer.
  document = poseTrackerDocument();
  document["placements"][1]["measurements"][4]["point"] = {1.0, 2.0, 3.0};
  EXPECT_NE(refusal(document).find("/placements/1/measurements/4/point"), std::string::npos);
}

// Orientations in the wrong unit (rad where deg are read) are no machine error: exit 2 naming
// the station, with what to check.
TEST(Instrument, OrientationsInTheWrongUnitAreRefusedNamingTheStation) {
  nlohmann::json document = poseTrackerDocument();
  for (auto& reading : document["placements"][1]["measurements"]) {
    for (int k = 3; k < 6; ++k) reading["point"][k] = degToRad(reading["point"][k].get<double>());
  }
  const std::string what = refusal(document);
  EXPECT_NE(what.find("tracker.json: /placements/1: "), std::string::npos) << what;
  EXPECT_NE(what.find("rotation vector in deg"), std::string::npos) << what;
}

// Pose readings from a CSV (joints, then x, y, z and the rotation vector in deg): the same
// readings as inline, point_unit scaling only the point; a row of the wrong width is refused
// naming the file and its line, on the command line with exit 2 and one line.
class PoseCsv : public test_support::TempFolder {
 protected:
  PoseCsv() : TempFolder("pose-csv") {}

  /// The pose plan whose station 2 is read from `rows` (in metres for the point).
  std::string writePlan(const std::string& rows) {
    write("station2.csv", rows);
    nlohmann::json document = poseTrackerDocument();
    document["placements"][1]["measurements"] = {
        {{"csv", "station2.csv"}, {"unit", "deg"}, {"point_unit", "m"}}};
    return write("tracker-pose.json", document.dump());
  }
};

TEST_F(PoseCsv, RowsReadAsTheInlineReadings) {
  const nlohmann::json inline_document = poseTrackerDocument();
  std::ostringstream rows;
  rows.precision(17);
  rows << "q1,q2,q3,q4,q5,q6,x,y,z,wx,wy,wz\n";
  for (const auto& reading : inline_document["placements"][1]["measurements"]) {
    for (const auto& q : reading["joints"]) rows << q.get<double>() << ",";
    const auto& point = reading["point"];
    for (int k = 0; k < 6; ++k)
      rows << (k < 3 ? point[k].get<double>() / 1000.0 : point[k].get<double>())
           << (k < 5 ? "," : "\n");
  }
  const Plan from_csv = loadPlan(writePlan(rows.str()));
  const Plan from_json = parsePlan(inline_document, "tracker-pose.json");
  const auto& a = from_csv.placements[1].measurements;
  const auto& b = from_json.placements[1].measurements;
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_LT((a[i].point - b[i].point).norm(), 1e-9);
    EXPECT_LT((a[i].orientation - b[i].orientation).norm(), 1e-12);
    EXPECT_EQ(a[i].csv_row, static_cast<int>(i) + 1);
  }
}

TEST_F(PoseCsv, ARowOfTheWrongWidthIsRefusedNamingTheFileAndLine) {
  const std::string plan = writePlan(
      "10,20,30,40,50,60,1.1,0.2,0.3,10,20,30\n"
      "10,20,30,40,50,60,1.1,0.2,0.3\n");
  try {
    loadPlan(plan);
    FAIL() << "a row of 9 numbers was read as a pose reading";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path("station2.csv"));
    EXPECT_EQ(e.pointer(), "line 2");
    EXPECT_NE(std::string(e.what()).find("6 joints, then the 6 measured coordinates"),
              std::string::npos)
        << e.what();
  }
  const test_support::CliRun refused =
      test_support::runCli("check " + plan, test_support::Stderr::Only);
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.out.find("station2.csv: line 2: expected 12 readings"), std::string::npos)
      << refused.out;
  EXPECT_EQ(std::count(refused.out.begin(), refused.out.end(), '\n'), 1);
}

// The command line: pose readings through simulate, calibrate and verify (the angular table
// and its --json twin); a pose instrument on a model without orientation is exit 2, one line.
TEST_F(PoseCsv, CommandLineSimulatesCalibratesAndVerifiesPoses) {
  const std::string plan = write("tracker-pose.json", poseTrackerDocument().dump());
  write("truth.json", R"({"parameters": {"j2.theta": 0.01, "j3.d": 600.05, "probe.x": 150.03}})");
  const std::string simulated = path("simulated.json");
  ASSERT_EQ(test_support::runCli("simulate " + plan + " --truth " + path("truth.json") +
                                 " --seed 3 -o " + simulated)
                .status,
            0);
  const std::string machine = path("machine.json");
  ASSERT_EQ(test_support::runCli("calibrate " + simulated + " --write-machine " + machine).status,
            0);
  const test_support::CliRun verified =
      test_support::runCli("verify --json " + simulated + " --machine " + machine);
  ASSERT_EQ(verified.status, 0);
  const nlohmann::json out = nlohmann::json::parse(verified.out);
  ASSERT_TRUE(out["instrument"].contains("angular_all"));
  EXPECT_EQ(out["instrument"]["angular_all"]["readings"], 50);
  EXPECT_EQ(out["instrument"]["stations"][0]["angular"]["deviations"].size(), 25u);
  const test_support::CliRun table = test_support::runCli("verify " + simulated);
  EXPECT_NE(table.out.find("angular deviations of the held-out poses"), std::string::npos);

  nlohmann::json planar = nlohmann::json::parse(R"({
    "format": "artcal-plan/1",
    "machine": {"model": "planar2r", "parameters": {"l1": 150, "l2": 100, "dt2": 0}},
    "noise": {"probe": 0.01, "encoder": 0.001},
    "artifacts": {"tracker": {"type": "instrument", "measures": "pose", "noise": 0.02,
                              "noise_angle": 0.005}},
    "placements": [{"artifact": "tracker", "measurements": [
      {"joints": [0, 30]}, {"joints": [40, 60]}, {"joints": [80, 20]}]}]})");
  const std::string bad = write("planar-pose.json", planar.dump());
  const test_support::CliRun refused =
      test_support::runCli("check " + bad, test_support::Stderr::Only);
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.out.find(bad + ": /artifacts/tracker/measures: "), std::string::npos)
      << refused.out;
  EXPECT_EQ(std::count(refused.out.begin(), refused.out.end(), '\n'), 1);
}

}  // namespace instrument_test
}  // namespace artcal
