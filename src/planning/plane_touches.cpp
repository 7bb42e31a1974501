#include "artcal/planning/plane_touches.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "artcal/estimation/plane_rows.hpp"
#include "artcal/model/inverse_kinematics.hpp"

namespace artcal {

std::vector<Measurement> planeTouches(const Machine& reading_machine, const Artifact& artifact,
                                      const RigidTransform& placed, int face, int count,
                                      std::mt19937_64& rng, int stylus) {
  const PlaneGeometry& plane = artifact.plane;
  const PlaneFace& the_face = plane.faces.at(static_cast<std::size_t>(face));
  const RigidTransform to_machine = placed.inverse();
  std::uniform_real_distribution<double> offset(-plane.extent, plane.extent);
  std::vector<Measurement> out;
  constexpr int kAttemptsPerTouch = 40;
  IkOptions ik;
  ik.stylus = std::max(stylus, 0);
  for (int attempt = 0; attempt < kAttemptsPerTouch * count && static_cast<int>(out.size()) < count;
       ++attempt) {
    Eigen::VectorXd W = artifact.features.col(face);
    if (plane.shape == PlaneShape::TableBall) {
      // A table-spindle ball bar: the spindle ball anywhere on the sphere of the bar's length.
      std::normal_distribution<double> normal;
      Eigen::Vector3d d(normal(rng), normal(rng), normal(rng));
      W = plane.length * d.normalized();
    } else {
      for (int k = 0; k < artifact.dimension; ++k)
        if (k != the_face.axis) W[k] += offset(rng);
    }
    const std::vector<Eigen::VectorXd> postures =
        posturesFor(reading_machine, reading_machine.nominal, to_machine.apply(W), 1, rng, ik);
    if (postures.empty()) continue;
    Measurement m{face, postures.front(), ik.stylus};
    if (plane.flush) {
      auto q = touchPlane(artifact, reading_machine, reading_machine.nominal, m, placed,
                          Eigen::VectorXd(), Eigen::VectorXd::Zero(3), Eigen::Vector3d(W));
      if (!q) continue;
      // A revolute joint turned by whole turns reads the same configuration.
      for (int i = 0; i < q->size(); ++i) {
        if (reading_machine.mechanism->jointKind(i) == JointKind::Revolute)
          (*q)[i] = std::remainder((*q)[i], 2.0 * std::numbers::pi);
      }
      if (!reading_machine.withinLimits(*q)) continue;
      m.joints = *q;
      // The tool axis must point into the face (not out of the material).
      Eigen::VectorXd x;
      Eigen::Matrix3d R;
      forwardPoseOrThrow(*reading_machine.mechanism, reading_machine.nominal, m.joints, x, R,
                         nullptr, nullptr, nullptr, nullptr, m.stylus);
      const Eigen::Vector3d v = placed.R * (R * plane.tool_axis);
      if (the_face.sign * v[the_face.axis] > 0.0) continue;
      // Still on the face's planned part.
      const Eigen::VectorXd touched = placed.apply(x);
      bool inside = true;
      for (int k = 0; k < 3; ++k)
        if (k != the_face.axis &&
            std::abs(touched[k] - artifact.features(k, face)) > 1.5 * plane.extent)
          inside = false;
      if (!inside) continue;
    }
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace artcal
