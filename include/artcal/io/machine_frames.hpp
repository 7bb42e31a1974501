#pragma once
// The frames a calibration estimated, carried in a machine file (`calibrate --write-machine`
// writes them beside the machine block; `verify --machine` reads them to score held-out readings
// in the calibration's frame, docs/models.md section 6):
//   "frames": [{"placement": "station 1", "artifact": "tracker",
//               "rotation": [[r00, r01, r02], [r10, r11, r12], [r20, r21, r22]],
//               "translation": [tx, ty, tz]}, ...]
// one per placement of the calibration's plan: the rigid transform W = R x + t from the machine
// frame to the artifact's (or the instrument station's) frame, t in mm (2 x 2 and 2 numbers in a
// planar plan). "placement" is the placement's label (its name, or its index when it has none).

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "artcal/artifact/rigid_transform.hpp"
#include "artcal/calibration/verification.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

struct CalibratedFrame {
  std::string placement;  ///< the calibration plan's placement label
  std::string artifact;   ///< the artifact id it placed
  RigidTransform pose;    ///< machine -> artifact, mm
};

/// The "frames" member for the placements of `plan` at `poses` (one per placement).
nlohmann::json framesToJson(const Plan& plan, const std::vector<RigidTransform>& poses);

/// The "frames" member of a machine file (empty when there is none). InputError naming `source`
/// and the pointer when malformed: a rotation that is not one (|R^T R - I| > 1e-6, det < 0), a
/// translation beyond the input bound, a placement named twice.
std::vector<CalibratedFrame> parseMachineFrames(const nlohmann::json& document,
                                                const std::string& source, int dimension);

/// Which calibrated frame scores each placement of the held-out `plan` (none: re-registered
/// only). With `frame_of` empty, a placement takes the frame of the calibration's placement of
/// the same label and artifact, when there is one; with `frame_of` naming a calibrated placement,
/// every placement of that placement's artifact takes its frame (an instrument that stood still
/// between the sessions). InputError naming `source` (the machine file) when `frame_of` names no
/// frame of the file, or when its artifact is placed nowhere in `plan`.
std::vector<std::optional<CalibrationFrame>> framesForPlacements(
    const Plan& plan, const std::vector<CalibratedFrame>& frames, const std::string& frame_of,
    const std::string& source);

/// framesForPlacements with --frame-of's entries: at most one NAME (as above) and any number of
/// HELD=CALIBRATED pairs, each scoring the held-out placement HELD in the frame of the
/// calibration's placement CALIBRATED (two planes touched on two days, each with its own
/// held-out session). InputError naming the entry when a name is unknown or the artifacts differ.
std::vector<std::optional<CalibrationFrame>> framesForPlacements(
    const Plan& plan, const std::vector<CalibratedFrame>& frames,
    const std::vector<std::string>& frame_of, const std::string& source);

}  // namespace artcal
