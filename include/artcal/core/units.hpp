#pragma once
// Units: files and output use mm and degrees; everything inside the library uses mm and radians.

#include <numbers>
#include <string_view>

namespace artcal {

inline constexpr double kDegree = std::numbers::pi / 180.0;

constexpr double degToRad(double deg) {
  return deg * kDegree;
}
constexpr double radToDeg(double rad) {
  return rad / kDegree;
}

/// What a parameter (or joint) measures and its unit in files: a length (mm), an angle (deg), or
/// a named coefficient unit with its scale, e.g. a Cartesian CMM's rotation error functions in
/// "um/m" (1e-6 rad per file unit, docs/models.md section 4). Internal values are mm or rad; `kind`
/// says which (a dimensionless rotation coefficient counts as an angle: it turns a lever into a
/// length, as the planner's scaling needs).
struct Quantity {
  enum class Kind { Length, Angle };
  Kind kind = Kind::Length;
  std::string_view unit = "mm";  ///< the unit in files and output
  double scale = 1.0;            ///< internal value per file unit

  static const Quantity Length;  ///< mm
  static const Quantity Angle;   ///< deg in files, rad inside
  /// A coefficient in file unit `unit`, `scale` internal units (mm or rad, after `kind`) each.
  static constexpr Quantity coefficient(Kind kind, std::string_view unit, double scale) {
    return {kind, unit, scale};
  }
  constexpr bool isAngle() const { return kind == Kind::Angle; }
  constexpr bool operator==(const Quantity&) const = default;
};

inline constexpr Quantity Quantity::Length{Quantity::Kind::Length, "mm", 1.0};
inline constexpr Quantity Quantity::Angle{Quantity::Kind::Angle, "deg", kDegree};
/// A rotation (or squareness) coefficient in micrometres per metre: 1e-6 rad per file unit.
inline constexpr Quantity kMicrometrePerMetre =
    Quantity::coefficient(Quantity::Kind::Angle, "um/m", 1e-6);

constexpr std::string_view unitName(const Quantity& q) {
  return q.unit;
}

/// Internal value (mm or rad) to the file unit (mm, deg or the coefficient's unit).
constexpr double toFileUnit(const Quantity& q, double internal) {
  return q.scale == 1.0 ? internal : internal / q.scale;
}
/// File unit (mm, deg or the coefficient's unit) to the internal value (mm or rad).
constexpr double fromFileUnit(const Quantity& q, double value) {
  return q.scale == 1.0 ? value : value * q.scale;
}

}  // namespace artcal
