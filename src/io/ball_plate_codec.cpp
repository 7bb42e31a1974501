#include "artcal/io/ball_plate_codec.hpp"

#include "artcal/core/linear_algebra.hpp"

namespace artcal {
namespace {

/// "centers i and j coincide" for the first pair of ball-plate centres closer than a 10^-9 of
/// the plate's size (docs: the centres must be distinct), else "".
std::string coincidentCenters(const Eigen::MatrixXd& points) {
  const Eigen::MatrixXd centred = points.colwise() - points.rowwise().mean();
  const double size = centred.colwise().norm().maxCoeff();
  for (int i = 0; i < points.cols(); ++i) {
    for (int j = i + 1; j < points.cols(); ++j) {
      if ((points.col(i) - points.col(j)).norm() <= 1e-9 * size) {
        return "centers " + std::to_string(i) + " and " + std::to_string(j) +
               " coincide: every ball of a plate must have its own centre";
      }
    }
  }
  return "";
}

Artifact readBallPlate(const std::string& id, const Node& entry, const Machine& machine,
                       std::vector<std::string>& warnings) {
  entry.warnUnknown({"type", "centers", "u"}, warnings);
  const int dimension = machine.dimension();
  const Node centers = entry.at("centers");
  const std::size_t n = centers.arraySize(2, kMaxArtifactFeatures);
  Eigen::MatrixXd points(dimension, static_cast<int>(n));
  for (std::size_t i = 0; i < n; ++i) {
    points.col(static_cast<int>(i)) = centers[i].numbers(static_cast<std::size_t>(dimension));
  }
  // Every pair of centres must be distinct; in 3-D the centres must not all lie on one line
  // (N(r) = 6 needs it: a collinear plate is a ball bar).
  const Eigen::MatrixXd centred = points.colwise() - points.rowwise().mean();
  const Eigen::VectorXd sv = singularValues(centred);
  if (sv[0] <= 0.0) centers.fail("centers must not coincide");
  if (const std::string pair = coincidentCenters(points); !pair.empty()) centers.fail(pair);
  if (dimension == 3 && (sv.size() < 2 || sv[1] <= 1e-9 * sv[0])) {
    centers.fail("centers of a 3-D ball plate must not be collinear");
  }
  return Artifact::ballPlate(id, points, artifactUncertainty(entry, "u"));
}

}  // namespace

ArtifactCodec ballPlateArtifactCodec() {
  return {"ball_plate", readBallPlate};
}

}  // namespace artcal
