#pragma once
// Reading a JSON document with the JSON pointer of every value at hand, so that every check of
// the input names the exact place of a fault: InputError(file, pointer, message)
// (docs/plan-format.md, "Errors"). Used by the plan reader and by every model family's codec.

#include <Eigen/Core>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "artcal/core/error.hpp"

namespace artcal {

/// Largest magnitude of a number in a plan or machine file but a joint reading (mm, deg, mm^2 ...):
/// 10^9 mm is 1000 km. Bounded where numbers enter, so that their squares and products (the
/// information, the tip variance) stay far inside double range (docs/hardening.md).
inline constexpr double kMaxInputMagnitude = 1e9;
/// The range of a standard deviation (noise, prior, artifact u; mm or deg): its inverse square
/// weighs the readings, 10^-15 .. 10^6 keeps the weights between 10^-12 and 10^30.
inline constexpr double kMinStandardDeviation = 1e-15;
inline constexpr double kMaxStandardDeviation = 1e6;

/// A JSON pointer token with '~' and '/' escaped (RFC 6901).
std::string escapePointerToken(const std::string& token);

/// "a number", "a string", ... for messages.
std::string jsonTypeName(const nlohmann::json& value);

/// A value of the document with its JSON pointer: every check names the exact place of a fault.
/// The node refers to the document and to the source name; both must outlive it.
class Node {
 public:
  Node(const nlohmann::json& value, std::string pointer, const std::string& source)
      : value_(&value), pointer_(std::move(pointer)), source_(&source) {}

  /// Raises InputError(source, pointer, message).
  [[noreturn]] void fail(const std::string& message) const;
  const nlohmann::json& value() const { return *value_; }
  const std::string& pointer() const { return pointer_; }
  const std::string& source() const { return *source_; }

  /// The value as an object; InputError when it is not one.
  const nlohmann::json& object() const;
  bool has(const std::string& key) const { return object().contains(key); }
  /// The member `key`; InputError "missing field" when absent.
  Node at(const std::string& key) const;
  std::optional<Node> find(const std::string& key) const;
  /// The size of an array of min..max entries; InputError otherwise.
  std::size_t arraySize(std::size_t min, std::size_t max) const;
  Node operator[](std::size_t i) const;
  /// A finite number of magnitude at most kMaxInputMagnitude.
  double number() const;
  /// A finite number of any magnitude (a joint reading: its joint limits bound it).
  double anyFiniteNumber() const;
  /// A standard deviation in [kMinStandardDeviation, kMaxStandardDeviation]; 0 too when
  /// `zero_allowed` (an exact encoder, an artifact without calibration uncertainty).
  double standardDeviation(bool zero_allowed) const;
  double nonNegative() const;
  double positive() const;
  /// A whole number in [min, max] (a float with no fractional part is accepted).
  long integer(long min, long max) const;
  std::string string() const;
  /// An array of exactly `count` numbers (number()).
  Eigen::VectorXd numbers(std::size_t count) const;
  /// An array of exactly `count` finite numbers of any magnitude (anyFiniteNumber()).
  Eigen::VectorXd finiteNumbers(std::size_t count) const;
  /// Refuses members not in `known` (InputError naming the member, with "did you mean" when a
  /// known key is a few edits away): a misspelled optional field would otherwise take its
  /// default silently (`u_lenght`). Keys starting with "x-" are extensions, ignored
  /// (docs/plan-format.md, "Unknown fields"). `warnings` is kept for callers; nothing is added.
  void warnUnknown(std::initializer_list<const char*> known,
                   std::vector<std::string>& warnings) const;
  /// This node with further names that warnUnknown may suggest but does not accept (members a
  /// caller has already read and taken out of the object, e.g. a machine block's shared ones).
  Node withSuggestions(std::span<const char* const> names) const {
    Node node = *this;
    node.suggestions_ = names;
    return node;
  }

 private:
  long checkRange(long v, long min, long max) const;
  std::string describeArray() const;
  void checkNumberArray(std::size_t count) const;

  const nlohmann::json* value_;
  std::string pointer_;
  const std::string* source_;
  std::span<const char* const> suggestions_;
};

}  // namespace artcal
