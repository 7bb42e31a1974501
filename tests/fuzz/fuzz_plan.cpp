// libFuzzer harness of the plan parser (artcal check/evaluate PLAN) and the evaluator behind it.
// Build and run: tools/fuzz.sh. Any abort, sanitizer report or escaping exception is a finding.

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace artcal;
  if (size > fuzz::kMaxInputBytes) return -1;
  const std::string text(reinterpret_cast<const char*>(data), size);
  // An InputError is the proper answer of the parser, or of the evaluator to a plan it cannot
  // evaluate (no usable workspace configuration): the command line's exit status 2.
  try {
    fuzz::evaluateBounded(parsePlan(parseJsonText(text, "fuzz.json"), "fuzz.json"));
  } catch (const InputError& e) {
    if (std::string(e.what()).empty()) fuzz::finding("an InputError without a message");
  }
  return 0;
}
