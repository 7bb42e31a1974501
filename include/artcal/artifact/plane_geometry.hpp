#pragma once
// The geometry of a plane artifact (docs/planes.md): one or more flat faces of known relative
// geometry, each a feature of the artifact whose one valued coordinate is along its normal. In
// the artifact frame every face is perpendicular to an axis: a single plane (x = 0, outward
// normal +X), a gauge block (x = 0 with normal -X and x = L with normal +X) or a cube corner
// (x = 0, y = 0, z = 0 with normals +X, +Y, +Z; the cube fills the negative octant).

#include <Eigen/Core>
#include <vector>

#include "artcal/core/enum_names.hpp"

namespace artcal {

/// TableBall: not a face but the sphere of a double ball bar's length about a ball fixed on the
/// table (five-axis.md: a `"ball_bar"` with `"ends": "table-spindle"`); the tip (the spindle's
/// ball) lies on it. One row per reading, |W| - length; the placement is the table ball's
/// position (3 translations). Parsed from the ball bar's form only, not a plane's `"shape"`.
enum class PlaneShape { Single, GaugeBlock, CubeCorner, TableBall };
inline constexpr EnumNames<PlaneShape, 3> kPlaneShapeNames{
    {{PlaneShape::Single, "plane"},
     {PlaneShape::GaugeBlock, "gauge_block"},
     {PlaneShape::CubeCorner, "cube_corner"}}};

/// One face: the artifact coordinate `axis` equals `offset` on it; its outward normal is
/// `sign` times that axis (the side the tip touches it from).
struct PlaneFace {
  int axis = 0;
  double sign = 1.0;
  double offset = 0.0;
};

struct PlaneGeometry {
  PlaneShape shape = PlaneShape::Single;
  std::vector<PlaneFace> faces;
  /// Point contact: the ball's radius (mm); its centre sits this far out along the normal.
  double radius = 0.0;
  /// Flush contact (`"measures": "flush"`): the tip frame's origin lies on the face and its
  /// `tool_axis` (tip frame) is along the face's normal; 3 rows per reading instead of 1.
  bool flush = false;
  Eigen::Vector3d tool_axis = Eigen::Vector3d::UnitZ();
  /// A gauge block's length (mm), a cube corner's edge (mm: where its faces' features lie) or a
  /// table-spindle ball bar's length (mm).
  double length = 0.0;
  /// Planning only: touches are planned within +-extent (mm) of each face's middle, along the
  /// face's two in-plane axes.
  double extent = 100.0;
};

}  // namespace artcal
