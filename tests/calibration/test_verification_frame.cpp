// verify in the calibration's frame (issue 29 point 3; docs/models.md section 6): held-out
// readings scored with the station (or artifact placement) the calibration estimated, not
// refitted, beside the re-registered figures. Expected values computed here from a known station
// and the noise drawn, and the least-squares bound: with every reading held out the re-registered
// RMS is the minimum over stations, so the in-frame RMS is never below it.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "artcal/artcal.hpp"
#include "artcal/calibration/station_verification.hpp"
#include "artcal/calibration/verification.hpp"
#include "artcal/io/machine_frames.hpp"
#include "artcal/model/rotation_vector.hpp"
#include "cli_runner.hpp"
#include "temp_folder.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace verification_frame_test {

using nlohmann::json;
using test_support::runCli;
using test_support::Stderr;

/// A known station: rotation vector (0.1, -0.2, 0.3) rad, translation (1000, -500, 200) mm.
RigidTransform knownStation() {
  RigidTransform T;
  T.R = rotationFromVector(Eigen::Vector3d(0.1, -0.2, 0.3));
  T.t = Eigen::Vector3d(1000.0, -500.0, 200.0);
  return T;
}

// Station 1's readings measured from the known station with noise e_i drawn here: scored in that
// station, each deviation is |e_i| exactly; in a station moved by delta, |e_i - delta|. Station 2
// has no frame and no in-frame figures.
TEST(VerifyInCalibrationFrame, KnownStationGivesTheDrawnNoiseAsDeviations) {
  Plan plan = loadPlan(test_support::planFile("tracker-arm6-2stations.json"));
  const Eigen::VectorXd& p = plan.machine.nominal;
  const RigidTransform T = knownStation();
  std::mt19937 random(29);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<Eigen::Vector3d> drawn;
  for (Measurement& m : plan.placements[0].measurements) {
    m.stationing = false;  // every reading held out, the station refitted on all of them
    Eigen::VectorXd x;
    forwardOrThrow(*plan.machine.mechanism, p, m.joints, x);
    const Eigen::Vector3d e(noise(random), noise(random), noise(random));
    drawn.push_back(e);
    m.point = T.apply(x) + e;
  }
  std::vector<std::optional<CalibrationFrame>> frames(plan.placements.size());
  frames[0] = CalibrationFrame{"training station", T};
  const StationsVerification v = verifyStations(plan, p, std::nullopt, frames);
  ASSERT_EQ(v.stations.size(), 2u);
  ASSERT_TRUE(v.stations[0].in_frame);
  EXPECT_FALSE(v.stations[1].in_frame);
  const InFrameDeviations& f = *v.stations[0].in_frame;
  EXPECT_EQ(f.frame_of, "training station");
  ASSERT_EQ(f.deviations.size(), static_cast<Eigen::Index>(drawn.size()));
  double sum2 = 0.0;
  for (std::size_t i = 0; i < drawn.size(); ++i) {
    EXPECT_NEAR(f.deviations[static_cast<Eigen::Index>(i)], drawn[i].norm(), 1e-9) << i;
    sum2 += drawn[i].squaredNorm();
  }
  EXPECT_NEAR(f.summary.rms, std::sqrt(sum2 / static_cast<double>(drawn.size())), 1e-9);
  // Re-registered: the least-squares station over the same readings, never worse.
  EXPECT_GE(f.summary.rms, v.stations[0].summary.rms);
  ASSERT_TRUE(v.in_frame_all && v.reregistered_all);
  EXPECT_DOUBLE_EQ(v.in_frame_all->rms, f.summary.rms);
  EXPECT_DOUBLE_EQ(v.reregistered_all->rms, v.stations[0].summary.rms);

  // The station moved by delta since the calibration: every deviation is |e_i - delta|.
  const Eigen::Vector3d delta(0.3, -0.4, 1.2);
  RigidTransform moved = T;
  moved.t += delta;
  frames[0] = CalibrationFrame{"training station", moved};
  const StationsVerification w = verifyStations(plan, p, std::nullopt, frames);
  for (std::size_t i = 0; i < drawn.size(); ++i) {
    EXPECT_NEAR(w.stations[0].in_frame->deviations[static_cast<Eigen::Index>(i)],
                (drawn[i] - delta).norm(), 1e-9);
  }
  // The re-registered figures do not depend on the frame given.
  EXPECT_DOUBLE_EQ(w.stations[0].summary.rms, v.stations[0].summary.rms);
}

// An artifact placement scored in a given pose: each residual is |[R x_i + t - W*_i]_valued|,
// computed here from the forward kinematics; in the refitted pose itself it equals the
// re-registered residual.
TEST(VerifyInCalibrationFrame, ArtifactPlacementResidualsInAGivenPose) {
  const Plan plan = loadPlan(test_support::planFile("aacmm-6axis-3bars.json"));
  const Eigen::VectorXd& p = plan.machine.nominal;
  const Verification refit = verifyMachine(plan, p, std::nullopt);
  VerifyOptions options;
  options.calibration_frames.resize(plan.placements.size());
  options.calibration_frames[0] = CalibrationFrame{"a", refit.placements[0].pose};
  RigidTransform shifted = refit.placements[1].pose;
  shifted.t += Eigen::Vector3d(0.5, 0.0, -0.25);
  options.calibration_frames[1] = CalibrationFrame{"b", shifted};
  const Verification v = verifyMachine(plan, p, std::nullopt, options);
  ASSERT_TRUE(v.placements[0].in_frame && v.placements[1].in_frame);
  EXPECT_FALSE(v.placements[2].in_frame);
  const Eigen::VectorXd& same = v.placements[0].in_frame->residuals;
  EXPECT_LT((same - v.placements[0].residuals).cwiseAbs().maxCoeff(), 1e-12);
  const Placement& placement = plan.placements[1];
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  double sum2 = 0.0;
  for (std::size_t i = 0; i < placement.measurements.size(); ++i) {
    const Measurement& m = placement.measurements[i];
    Eigen::VectorXd x;
    forwardOrThrow(*plan.machine.mechanism, p, m.joints, x);
    const double expected =
        (shifted.R * x + shifted.t - artifact.feature(m.feature, Eigen::VectorXd()))
            .head(artifact.valuedPerFeature())
            .norm();
    EXPECT_NEAR(v.placements[1].in_frame->residuals[static_cast<Eigen::Index>(i)], expected, 1e-9);
    sum2 += expected * expected;
  }
  EXPECT_NEAR(v.placements[1].in_frame->residual_rms,
              std::sqrt(sum2 / static_cast<double>(placement.measurements.size())), 1e-9);
  EXPECT_EQ(v.in_frame_placements, 2);
}

// The figures over every placement scored in a frame: the in-frame RMS pools the residuals of
// placements 0 and 1 (each computed here from the forward kinematics in its frame), the
// re-registered RMS the same readings in their refitted poses; placement 2, which has no frame,
// is in neither. Every placement's frame moved by its own offset so that no placement's
// residuals are another's.
TEST(VerifyInCalibrationFrame, AllPlacementsInFrameRmsPoolsExactlyThePlacementsWithAFrame) {
  const Plan plan = loadPlan(test_support::planFile("aacmm-6axis-3bars.json"));
  ASSERT_EQ(plan.placements.size(), 3u);
  const Eigen::VectorXd& p = plan.machine.nominal;
  const Verification refit = verifyMachine(plan, p, std::nullopt);
  VerifyOptions options;
  options.calibration_frames.resize(plan.placements.size());
  const std::vector<Eigen::Vector3d> offsets = {Eigen::Vector3d(0.2, 0.0, 0.1),
                                                Eigen::Vector3d(0.0, -0.7, 0.3)};
  for (std::size_t j = 0; j < offsets.size(); ++j) {
    RigidTransform frame = refit.placements[j].pose;
    frame.t += offsets[j];
    options.calibration_frames[j] = CalibrationFrame{"placement " + std::to_string(j), frame};
  }
  const Verification v = verifyMachine(plan, p, std::nullopt, options);
  double in_frame2 = 0.0, reregistered2 = 0.0;
  int readings = 0;
  for (std::size_t j = 0; j < offsets.size(); ++j) {
    const Placement& placement = plan.placements[j];
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    const RigidTransform& frame = options.calibration_frames[j]->pose;
    const RigidTransform& fitted = refit.placements[j].pose;
    for (const Measurement& m : placement.measurements) {
      Eigen::VectorXd x;
      forwardOrThrow(*plan.machine.mechanism, p, m.joints, x);
      const Eigen::VectorXd feature = artifact.feature(m.feature, Eigen::VectorXd());
      const int k = artifact.valuedPerFeature();
      in_frame2 += (frame.R * x + frame.t - feature).head(k).squaredNorm();
      reregistered2 += (fitted.R * x + fitted.t - feature).head(k).squaredNorm();
      ++readings;
    }
  }
  EXPECT_EQ(v.in_frame_placements, 2);
  EXPECT_NEAR(v.in_frame_residual_rms, std::sqrt(in_frame2 / readings), 1e-9);
  EXPECT_NEAR(v.reregistered_residual_rms, std::sqrt(reregistered2 / readings), 1e-9);
}

class VerifyFrameCli : public test_support::TempFolder {
 protected:
  VerifyFrameCli() : TempFolder("verify-frame") {}
};

// The documented path: calibrate --write-machine carries the stations it estimated; verify of a
// second session from the same stations (the same simulated stations, new noise) scores it in
// them and re-registered, naming which is which, in the table and the JSON. The in-frame RMS is
// never below the re-registered one (every reading held out), and near the readings' noise;
// --frame-of scores every station in one calibrated station's frame; a name it lacks is exit 2.
TEST_F(VerifyFrameCli, CalibrationFramesTravelInTheMachineFileAndScoreTheNextSession) {
  const std::string plan = test_support::planFile("tracker-arm6-2stations.json");
  const std::string truth = test_support::planFile("tracker-arm6/truth.json");
  ASSERT_EQ(runCli("simulate " + plan + " --truth " + truth + " --seed 1 -o " + path("train.json"))
                .status,
            0);
  ASSERT_EQ(
      runCli("simulate " + plan + " --truth " + truth + " --seed 2 -o " + path("held.json")).status,
      0);
  // Every held-out reading scored (the plan marks 8 of each station's 25 for stationing).
  json held = readJsonFile(path("held.json"));
  for (json& placement : held["placements"])
    for (json& m : placement["measurements"]) m.erase("stationing");
  std::ofstream(path("held.json")) << held.dump(1);
  const auto calibrated =
      runCli("calibrate " + path("train.json") + " --write-machine " + path("cal.json"));
  ASSERT_EQ(calibrated.status, 0) << calibrated.out;
  const json machine = readJsonFile(path("cal.json"));
  ASSERT_EQ(machine["frames"].size(), 2u);
  EXPECT_EQ(machine["frames"][0]["placement"], "station 1");
  EXPECT_EQ(machine["frames"][0]["artifact"], "tracker");

  const auto run = runCli("verify --json " + path("held.json") + " --machine " + path("cal.json"));
  ASSERT_EQ(run.status, 0) << run.out;
  const json doc = json::parse(run.out)["instrument"];
  ASSERT_TRUE(doc.contains("in_calibration_frame")) << doc.dump(1);
  const double in_frame = doc["in_calibration_frame"]["all"]["rms"].get<double>();
  const double reregistered = doc["in_calibration_frame"]["reregistered"]["rms"].get<double>();
  EXPECT_DOUBLE_EQ(reregistered, doc["all"]["rms"].get<double>());
  EXPECT_GE(in_frame, reregistered);
  // The stations did not move between the sessions: in their calibrated frames the held-out
  // readings deviate by little more than re-registered (the calibration's frame error adds to the
  // noise, which both share).
  EXPECT_LT(in_frame, 2.0 * reregistered);
  EXPECT_EQ(doc["stations"][1]["in_calibration_frame"]["frame_of"], "station 2");

  const auto table = runCli("verify " + path("held.json") + " --machine " + path("cal.json"));
  ASSERT_EQ(table.status, 0);
  EXPECT_NE(table.out.find("the same held-out readings in the calibration's frame (the station "
                           "calibrate estimated, not refitted"),
            std::string::npos)
      << table.out;

  // Both held-out stations scored in station 1's frame: station 2 is elsewhere, far worse.
  const auto one = runCli("verify --json " + path("held.json") + " --machine " + path("cal.json") +
                          " --frame-of 'station 1'");
  ASSERT_EQ(one.status, 0) << one.out;
  const json both = json::parse(one.out)["instrument"]["stations"];
  EXPECT_EQ(both[1]["in_calibration_frame"]["frame_of"], "station 1");
  EXPECT_NEAR(both[0]["in_calibration_frame"]["rms"].get<double>(),
              doc["stations"][0]["in_calibration_frame"]["rms"].get<double>(), 1e-12);
  const auto missing = runCli(
      "verify " + path("held.json") + " --machine " + path("cal.json") + " --frame-of 'station 9'",
      Stderr::Only);
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.out.find("cal.json: /frames: no frame of a placement \"station 9\" (the file "
                             "has \"station 1\", \"station 2\")"),
            std::string::npos)
      << missing.out;
}

}  // namespace verification_frame_test
}  // namespace artcal
