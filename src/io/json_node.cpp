#include "artcal/io/json_node.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>

namespace artcal {

using nlohmann::json;

std::string escapePointerToken(const std::string& token) {
  std::string out;
  for (char c : token) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
  return out;
}

std::string jsonTypeName(const json& v) {
  if (v.is_number()) return "a number";
  if (v.is_string()) return "a string";
  if (v.is_boolean()) return "a boolean";
  if (v.is_null()) return "null";
  if (v.is_array()) return "an array";
  return "an object";
}

void Node::fail(const std::string& message) const {
  throw InputError(*source_, pointer_.empty() ? "/" : pointer_, message);
}

const json& Node::object() const {
  if (!value_->is_object()) fail("expected an object, got " + jsonTypeName(*value_));
  return *value_;
}

Node Node::at(const std::string& key) const {
  const auto& obj = object();
  const auto it = obj.find(key);
  if (it == obj.end()) {
    throw InputError(*source_, pointer_ + "/" + escapePointerToken(key), "missing field");
  }
  return {*it, pointer_ + "/" + escapePointerToken(key), *source_};
}

std::optional<Node> Node::find(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return at(key);
}

std::size_t Node::arraySize(std::size_t min, std::size_t max) const {
  if (!value_->is_array()) fail("expected an array, got " + jsonTypeName(*value_));
  const std::size_t n = value_->size();
  if (n < min)
    fail("expected at least " + std::to_string(min) + " entries, got " + std::to_string(n));
  if (n > max)
    fail("expected at most " + std::to_string(max) + " entries, got " + std::to_string(n));
  return n;
}

Node Node::operator[](std::size_t i) const {
  return {(*value_)[i], pointer_ + "/" + std::to_string(i), *source_};
}

namespace {

std::string shortNumber(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

}  // namespace

double Node::anyFiniteNumber() const {
  if (!value_->is_number()) fail("expected a number, got " + jsonTypeName(*value_));
  const double v = value_->get<double>();
  if (!std::isfinite(v)) fail("expected a finite number");
  return v;
}

double Node::number() const {
  const double v = anyFiniteNumber();
  if (std::abs(v) > kMaxInputMagnitude) {
    fail("magnitude " + shortNumber(std::abs(v)) + " beyond " + shortNumber(kMaxInputMagnitude) +
         ": check the value and its units (mm, deg)");
  }
  return v;
}

double Node::standardDeviation(bool zero_allowed) const {
  const double v = zero_allowed ? nonNegative() : positive();
  if (v == 0.0) return v;
  if (v < kMinStandardDeviation || v > kMaxStandardDeviation) {
    fail("a standard deviation of " + shortNumber(v) + " is outside " +
         shortNumber(kMinStandardDeviation) + " .. " + shortNumber(kMaxStandardDeviation) +
         (zero_allowed ? " (or 0)" : "") + ": check the value and its units (mm, deg)");
  }
  return v;
}

double Node::nonNegative() const {
  const double v = number();
  if (v < 0.0) fail("must not be negative, got " + json(v).dump());
  return v;
}

double Node::positive() const {
  const double v = number();
  if (v <= 0.0) fail("must be positive, got " + json(v).dump());
  return v;
}

long Node::integer(long min, long max) const {
  if (!value_->is_number_integer() && !value_->is_number_unsigned()) {
    if (value_->is_number_float()) {
      const double d = value_->get<double>();
      if (std::isfinite(d) && d == std::floor(d) && std::abs(d) < 9e15)
        return checkRange(static_cast<long>(d), min, max);
    }
    fail("expected a whole number, got " + jsonTypeName(*value_));
  }
  if (value_->is_number_unsigned() &&
      value_->get<std::uint64_t>() > static_cast<std::uint64_t>(max)) {
    fail("must be at most " + std::to_string(max) + ", got " + value_->dump());
  }
  return checkRange(value_->get<long>(), min, max);
}

std::string Node::string() const {
  if (!value_->is_string()) fail("expected a string, got " + jsonTypeName(*value_));
  return value_->get<std::string>();
}

void Node::checkNumberArray(std::size_t count) const {
  if (!value_->is_array() || value_->size() != count ||
      !std::all_of(value_->begin(), value_->end(), [](const json& v) { return v.is_number(); })) {
    fail("expected " + std::to_string(count) + " numbers, got " + describeArray());
  }
}

Eigen::VectorXd Node::numbers(std::size_t count) const {
  checkNumberArray(count);
  Eigen::VectorXd v(count);
  for (std::size_t i = 0; i < count; ++i) v[static_cast<int>(i)] = (*this)[i].number();
  return v;
}

Eigen::VectorXd Node::finiteNumbers(std::size_t count) const {
  checkNumberArray(count);
  Eigen::VectorXd v(count);
  for (std::size_t i = 0; i < count; ++i) v[static_cast<int>(i)] = (*this)[i].anyFiniteNumber();
  return v;
}

namespace {

// Levenshtein distance (insertions, deletions, substitutions), for "did you mean".
std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

void Node::warnUnknown(std::initializer_list<const char*> known,
                       std::vector<std::string>& /*warnings*/) const {
  for (const auto& item : object().items()) {
    // Not a structured binding: clang 14 (the fuzz build) cannot capture one in a lambda.
    const std::string& key = item.key();
    if (key.rfind("x-", 0) == 0) continue;  // an extension
    if (std::any_of(known.begin(), known.end(), [&](const char* k) { return key == k; })) continue;
    // The nearest known key within a third of the name's length (at least 2 edits).
    std::string best;
    std::size_t best_distance = std::max<std::size_t>(2, key.size() / 3) + 1;
    for (const auto& candidates :
         {std::span<const char* const>(known.begin(), known.size()), suggestions_}) {
      for (const char* k : candidates) {
        const std::size_t d = editDistance(key, k);
        if (d < best_distance) {
          best = k;
          best_distance = d;
        }
      }
    }
    std::string message = "unknown field";
    if (!best.empty()) message += " (did you mean \"" + best + "\"?)";
    throw InputError(*source_, pointer_ + "/" + escapePointerToken(key),
                     message + "; extensions go under keys starting with x-");
  }
}

long Node::checkRange(long v, long min, long max) const {
  if (v < min) fail("must be at least " + std::to_string(min) + ", got " + std::to_string(v));
  if (v > max) fail("must be at most " + std::to_string(max) + ", got " + std::to_string(v));
  return v;
}

std::string Node::describeArray() const {
  if (!value_->is_array()) return jsonTypeName(*value_);
  for (const auto& v : *value_) {
    if (!v.is_number()) return "an array holding " + jsonTypeName(v);
  }
  return std::to_string(value_->size());
}

}  // namespace artcal
