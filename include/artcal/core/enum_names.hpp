#pragma once
// One name table per enum instead of a switch to a name and a loop back (issue 20 point 4):
//   inline constexpr EnumNames<Criterion, 6> kCriterionNames{{{Criterion::WorstTip, "worst-tip"},
//                                                            ...}};
//   nameOf(kCriterionNames, c)  and  fromName(kCriterionNames, "worst-tip")
// A value missing from its table is a programming error (std::logic_error), never a name.

#include <array>
#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

namespace artcal {

template <class Enum, std::size_t N>
using EnumNames = std::array<std::pair<Enum, std::string_view>, N>;

/// The name of `value` in `table`; std::logic_error when the table lacks it.
template <class Enum, std::size_t N>
std::string nameOf(const EnumNames<Enum, N>& table, Enum value) {
  for (const auto& [entry, name] : table) {
    if (entry == value) return std::string(name);
  }
  throw std::logic_error("an enum value without a name in its table");
}

/// The value named `name` in `table`, or std::nullopt.
template <class Enum, std::size_t N>
std::optional<Enum> fromName(const EnumNames<Enum, N>& table, std::string_view name) {
  for (const auto& [entry, entry_name] : table) {
    if (entry_name == name) return entry;
  }
  return std::nullopt;
}

}  // namespace artcal
