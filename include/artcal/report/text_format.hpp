#pragma once
// Number formatting shared by the report files (internal, not installed): one printf-style
// format of any length, fixed decimals, the exact text of a data-value, and the micro sign.
// The files use these through `using` declarations, so that their unity build sees one
// definition of each.

#include <cmath>
#include <cstdio>
#include <string>

namespace artcal::report_text {

/// printf-style formatting, any length.
template <class... Args>
std::string format(const char* pattern, Args... args) {
  const int size = std::snprintf(nullptr, 0, pattern, args...);
  if (size <= 0) return {};
  std::string out(static_cast<std::size_t>(size) + 1, '\0');
  std::snprintf(out.data(), out.size(), pattern, args...);
  out.resize(static_cast<std::size_t>(size));
  return out;
}

/// `value` with `decimals` decimals ("%.*f").
inline std::string fixed(double value, int decimals) {
  return format("%.*f", decimals, value);
}

/// A data-value: the number's shortest exact text ("%.17g"); "null" (as the JSON holds it) when
/// it is not finite, never "nan" or "inf".
inline std::string exact(double value) {
  return std::isfinite(value) ? format("%.17g", value) : "null";
}

/// The micro sign (UTF-8) and micrometres.
inline constexpr const char* kMicroSign = "\xC2\xB5";
inline constexpr const char* kMicrometreSymbol = "\xC2\xB5m";

}  // namespace artcal::report_text
