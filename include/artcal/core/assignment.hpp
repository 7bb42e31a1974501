#pragma once
// NAME=VALUE options (`--hold JOINT=VALUE`, `--tip-of PLACEMENT=TIP`, `--frame-of
// HELD=CALIBRATED`): one split for all of them, each caller naming its own option and form in its
// message.

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace artcal {

/// `entry` split at its first '=' into a non-empty name and a non-empty value; std::nullopt when
/// it holds no '=', or either side is empty.
inline std::optional<std::pair<std::string, std::string>> splitAssignment(
    const std::string& entry) {
  const auto equals = entry.find('=');
  if (equals == std::string::npos || equals == 0 || equals + 1 == entry.size()) return std::nullopt;
  return std::make_pair(entry.substr(0, equals), entry.substr(equals + 1));
}

/// A repeatable option's entries with an entry given again counted once, in the order first
/// given (options given twice, docs/hardening.md: the same value again counts once; entries that
/// conflict are refused where they are read).
inline std::vector<std::string> distinctEntries(const std::vector<std::string>& entries) {
  std::vector<std::string> out;
  for (const std::string& entry : entries)
    if (std::find(out.begin(), out.end(), entry) == out.end()) out.push_back(entry);
  return out;
}

/// `text` as a decimal number: an optional sign, digits with at most one '.', an optional
/// exponent (1.5, -2, 3e-4); std::nullopt for anything else, hexadecimal (0x10), inf and nan
/// among them, and for a value that is not finite (1e400).
inline std::optional<double> decimalNumber(const std::string& text) {
  std::size_t i = 0;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
  std::size_t digits = 0, dots = 0;
  for (; i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.');
       ++i) {
    text[i] == '.' ? ++dots : ++digits;
  }
  if (digits == 0 || dots > 1) return std::nullopt;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    const std::size_t start = i;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
    if (i == start) return std::nullopt;
  }
  if (i != text.size()) return std::nullopt;
  const char* begin = text.data() + (text[0] == '+' ? 1 : 0);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(begin, text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
    return std::nullopt;
  return value;
}

}  // namespace artcal
