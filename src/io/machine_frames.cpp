#include "artcal/io/machine_frames.hpp"

#include <Eigen/LU>
#include <map>
#include <set>

#include "artcal/core/assignment.hpp"
#include "artcal/core/error.hpp"
#include "artcal/io/json_node.hpp"

namespace artcal {

nlohmann::json framesToJson(const Plan& plan, const std::vector<RigidTransform>& poses) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t j = 0; j < plan.placements.size() && j < poses.size(); ++j) {
    const RigidTransform& pose = poses[j];
    nlohmann::json rotation = nlohmann::json::array();
    for (int r = 0; r < pose.R.rows(); ++r) {
      nlohmann::json row = nlohmann::json::array();
      for (int c = 0; c < pose.R.cols(); ++c) row.push_back(pose.R(r, c));
      rotation.push_back(row);
    }
    out.push_back(
        {{"placement", placementLabel(plan.placements, j)},
         {"artifact", plan.artifacts[static_cast<std::size_t>(plan.placements[j].artifact)].id},
         {"rotation", rotation},
         {"translation", std::vector<double>(pose.t.data(), pose.t.data() + pose.t.size())}});
  }
  return out;
}

std::vector<CalibratedFrame> parseMachineFrames(const nlohmann::json& document,
                                                const std::string& source, int dimension) {
  const Node root(document, "", source);
  root.object();
  std::vector<CalibratedFrame> out;
  const auto frames = root.find("frames");
  if (!frames) return out;
  constexpr std::size_t kMaxFrames = 1'000'000;  // as the plan's placements
  const std::size_t n = frames->arraySize(0, kMaxFrames);
  const auto d = static_cast<std::size_t>(dimension);
  std::set<std::string> seen;
  for (std::size_t i = 0; i < n; ++i) {
    const Node entry = (*frames)[i];
    entry.object();
    std::vector<std::string> ignored;  // unknown members are refused, not warned about
    entry.warnUnknown({"placement", "artifact", "rotation", "translation"}, ignored);
    CalibratedFrame frame;
    frame.placement = entry.at("placement").string();
    frame.artifact = entry.at("artifact").string();
    if (!seen.insert(frame.placement).second)
      entry.at("placement").fail("placement \"" + frame.placement + "\" has two frames");
    const Node rotation = entry.at("rotation");
    rotation.arraySize(d, d);
    frame.pose.R.resize(dimension, dimension);
    for (std::size_t r = 0; r < d; ++r)
      frame.pose.R.row(static_cast<int>(r)) = rotation[r].numbers(d).transpose();
    const Eigen::MatrixXd& R = frame.pose.R;
    if (!(R.transpose() * R - Eigen::MatrixXd::Identity(dimension, dimension)).isZero(1e-6) ||
        R.determinant() < 0.0) {
      rotation.fail("expected a rotation matrix (orthonormal rows, determinant +1)");
    }
    frame.pose.t = entry.at("translation").numbers(d);
    out.push_back(std::move(frame));
  }
  return out;
}

std::vector<std::optional<CalibrationFrame>> framesForPlacements(
    const Plan& plan, const std::vector<CalibratedFrame>& frames, const std::string& frame_of,
    const std::string& source) {
  std::vector<std::optional<CalibrationFrame>> out(plan.placements.size());
  auto artifactOf = [&](std::size_t j) {
    return plan.artifacts[static_cast<std::size_t>(plan.placements[j].artifact)].id;
  };
  if (!frame_of.empty()) {
    const CalibratedFrame* chosen = nullptr;
    std::string names;
    for (const CalibratedFrame& frame : frames) {
      if (frame.placement == frame_of) chosen = &frame;
      names += (names.empty() ? "" : ", ") + ("\"" + frame.placement + "\"");
    }
    if (!chosen) {
      throw InputError(source, "/frames",
                       "no frame of a placement \"" + frame_of + "\"" +
                           (names.empty() ? std::string(" (the file carries none: write it with "
                                                        "calibrate --write-machine)")
                                          : " (the file has " + names + ")"));
    }
    bool used = false;
    for (std::size_t j = 0; j < plan.placements.size(); ++j) {
      if (artifactOf(j) != chosen->artifact) continue;
      out[j] = CalibrationFrame{chosen->placement, chosen->pose};
      used = true;
    }
    if (!used) {
      throw InputError(source, "/frames",
                       "the frame of \"" + frame_of + "\" places artifact \"" + chosen->artifact +
                           "\", which no placement of " + plan.source + " places");
    }
    return out;
  }
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const std::string label = placementLabel(plan.placements, j);
    for (const CalibratedFrame& frame : frames) {
      if (frame.placement == label && frame.artifact == artifactOf(j))
        out[j] = CalibrationFrame{frame.placement, frame.pose};
    }
  }
  return out;
}

std::vector<std::optional<CalibrationFrame>> framesForPlacements(
    const Plan& plan, const std::vector<CalibratedFrame>& frames,
    const std::vector<std::string>& frame_of, const std::string& source) {
  std::vector<std::string> names;
  std::vector<std::pair<std::string, std::string>> pairs;
  // Given twice: the same entry again counts once; a placement paired twice with two frames is
  // refused (options given twice, docs/hardening.md).
  for (const std::string& entry : distinctEntries(frame_of)) {
    if (entry.find('=') == std::string::npos) {
      names.push_back(entry);
    } else if (auto assignment = splitAssignment(entry)) {
      pairs.push_back(std::move(*assignment));
    } else {
      throw InputError("--frame-of", entry, "expected NAME or HELD=CALIBRATED");
    }
  }
  if (names.size() > 1) {
    throw InputError("--frame-of", names[1],
                     "a second calibrated placement for every placement of its artifact: pair "
                     "each held-out placement with its own as HELD=CALIBRATED");
  }
  auto out =
      framesForPlacements(plan, frames, names.empty() ? std::string() : names.front(), source);
  std::map<std::string, std::string> paired;  // held -> calibrated
  for (const auto& pair : pairs) {
    const std::string& held = pair.first;
    const std::string& calibrated = pair.second;
    const auto [earlier, first] = paired.emplace(held, calibrated);
    if (!first) {
      throw InputError("--frame-of", held + "=" + calibrated,
                       "placement \"" + held + "\" is paired twice, with \"" + earlier->second +
                           "\" and \"" + calibrated + "\": give one --frame-of per placement");
    }
    const auto frame = std::find_if(frames.begin(), frames.end(), [&](const CalibratedFrame& f) {
      return f.placement == calibrated;
    });
    if (frame == frames.end())
      throw InputError(source, "/frames", "no frame of a placement \"" + calibrated + "\"");
    bool found = false;
    for (std::size_t j = 0; j < plan.placements.size(); ++j) {
      if (placementLabel(plan.placements, j) != held) continue;
      const std::string& id =
          plan.artifacts[static_cast<std::size_t>(plan.placements[j].artifact)].id;
      if (id != frame->artifact) {
        throw InputError("--frame-of", held + "=" + calibrated,
                         "placement \"" + held + "\" places artifact \"" + id +
                             "\", the frame of \"" + calibrated + "\" artifact \"" +
                             frame->artifact + "\"");
      }
      out[j] = CalibrationFrame{frame->placement, frame->pose};
      found = true;
    }
    if (!found) {
      throw InputError("--frame-of", held + "=" + calibrated,
                       "no placement \"" + held + "\" in " + plan.source);
    }
  }
  return out;
}

}  // namespace artcal
