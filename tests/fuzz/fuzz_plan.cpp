// libFuzzer harness of the plan parser (artcal check/evaluate PLAN) and the evaluator behind it.
// Build and run: tools/fuzz.sh. Any abort, sanitizer report or escaping exception is a finding.

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace artcal;
  if (size > fuzz::kMaxInputBytes) return -1;
  const std::string text(reinterpret_cast<const char*>(data), size);
  Plan plan;
  try {
    plan = parsePlan(parseJsonText(text, "fuzz.json"), "fuzz.json");
  } catch (const InputError& e) {
    if (std::string(e.what()).empty()) fuzz::finding("an InputError without a message");
    return 0;
  }
  fuzz::evaluateBounded(std::move(plan));
  return 0;
}
