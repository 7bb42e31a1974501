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

/// What a quantity measures; decides its unit in files ("mm" or "deg").
enum class Quantity { Length, Angle };

constexpr std::string_view unitName(Quantity q) {
  return q == Quantity::Angle ? "deg" : "mm";
}

/// Internal value (mm or rad) to the file unit (mm or deg).
constexpr double toFileUnit(Quantity q, double internal) {
  return q == Quantity::Angle ? radToDeg(internal) : internal;
}
/// File unit (mm or deg) to the internal value (mm or rad).
constexpr double fromFileUnit(Quantity q, double value) {
  return q == Quantity::Angle ? degToRad(value) : value;
}

}  // namespace artcal
