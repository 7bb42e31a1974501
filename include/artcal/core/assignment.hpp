#pragma once
// NAME=VALUE options (`--hold JOINT=VALUE`, `--tip-of PLACEMENT=TIP`, `--frame-of
// HELD=CALIBRATED`): one split for all of them, each caller naming its own option and form in its
// message.

#include <optional>
#include <string>
#include <utility>

namespace artcal {

/// `entry` split at its first '=' into a non-empty name and a non-empty value; std::nullopt when
/// it holds no '=', or either side is empty.
inline std::optional<std::pair<std::string, std::string>> splitAssignment(
    const std::string& entry) {
  const auto equals = entry.find('=');
  if (equals == std::string::npos || equals == 0 || equals + 1 == entry.size()) return std::nullopt;
  return std::make_pair(entry.substr(0, equals), entry.substr(equals + 1));
}

}  // namespace artcal
