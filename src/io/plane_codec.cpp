#include "artcal/io/plane_codec.hpp"

#include "artcal/core/units.hpp"

namespace artcal {

namespace {

Artifact parsePlaneArtifact(const std::string& id, const Node& node, const Machine& machine,
                            std::vector<std::string>& warnings) {
  node.warnUnknown({"type", "shape", "measures", "radius", "axis", "flatness", "u_tilt", "length",
                    "u_length", "extent"},
                   warnings);
  const int dimension = machine.dimension();
  PlaneGeometry geometry;
  if (const auto shape = node.find("shape")) {
    const auto value = fromName(kPlaneShapeNames, shape->string());
    if (!value)
      shape->fail("unknown shape \"" + shape->string() +
                  "\" (expected plane, gauge_block or cube_corner)");
    geometry.shape = *value;
  }
  if (const auto measures = node.find("measures")) {
    const std::string what = measures->string();
    if (what != "point" && what != "flush")
      measures->fail("unknown measures \"" + what + "\" (expected point or flush)");
    geometry.flush = what == "flush";
    if (geometry.flush && (dimension != 3 || !machine.mechanism->hasOrientation())) {
      measures->fail(
          "a \"flush\" contact needs a 3-D model whose forward kinematics gives an orientation "
          "(chain, serial-dh); model " +
          machine.mechanism->modelName() + " gives points: use \"point\"");
    }
  }
  if (const auto radius = node.find("radius")) {
    if (geometry.flush) radius->fail("a flush contact has no ball radius: leave \"radius\" out");
    geometry.radius = radius->nonNegative();
  }
  if (const auto axis = node.find("axis")) {
    if (!geometry.flush) axis->fail("\"axis\" is the tool axis of a flush contact only");
    const Eigen::Vector3d a = axis->numbers(3);
    if (!(a.norm() > 0.0)) axis->fail("expected a non-zero direction");
    geometry.tool_axis = a.normalized();
  }
  double u_tilt = 0.0;
  if (geometry.flush) {
    // The tilt rows need a noise of their own: the face's and the tool's flatness as angles.
    if (!node.has("u_tilt")) node.fail("a \"flush\" plane needs \"u_tilt\" (deg, > 0)");
    u_tilt = degToRad(node.at("u_tilt").standardDeviation(false));
  } else if (const auto tilt = node.find("u_tilt")) {
    tilt->fail("\"u_tilt\" is the tilt uncertainty of a flush contact only");
  }
  double u_length = 0.0;
  switch (geometry.shape) {
    case PlaneShape::GaugeBlock:
      geometry.length = node.at("length").positive();
      if (node.has("u_length")) u_length = node.at("u_length").standardDeviation(true);
      break;
    case PlaneShape::CubeCorner:
      geometry.length = node.has("length") ? node.at("length").positive() : 50.0;
      if (const auto u = node.find("u_length")) u->fail("\"u_length\" is a gauge block's only");
      break;
    case PlaneShape::Single:
      if (const auto l = node.find("length")) l->fail("a single plane has no \"length\"");
      if (const auto u = node.find("u_length")) u->fail("\"u_length\" is a gauge block's only");
      break;
    case PlaneShape::TableBall:  // a ball bar's form, not a plane's "shape" (plane_geometry.hpp)
      break;
  }
  // Where touches are planned on each face: a gauge block's faces are small.
  geometry.extent = geometry.shape == PlaneShape::GaugeBlock   ? 3.0
                    : geometry.shape == PlaneShape::CubeCorner ? 0.4 * geometry.length
                                                               : 100.0;
  if (const auto extent = node.find("extent")) geometry.extent = extent->positive();
  const double flatness = node.has("flatness") ? node.at("flatness").standardDeviation(true) : 0.0;
  return Artifact::planeArtifact(id, dimension, geometry, flatness, u_tilt, u_length);
}

}  // namespace

ArtifactCodec planeArtifactCodec() {
  return {"plane", parsePlaneArtifact};
}

}  // namespace artcal
