#pragma once
// The files tests read: plans/ (ARTCAL_PLANS_DIR) and tests/data (ARTCAL_TEST_DATA), both set
// by tests/CMakeLists.txt. Joined as filesystem paths: GCC 12 at -O1 warns falsely
// (-Warray-bounds, in char_traits::copy) on an inlined std::string(LITERAL) + "/name.json".

#include <filesystem>
#include <string>

namespace artcal::test_support {

/// plans/NAME
inline std::string planFile(const std::string& name) {
  return (std::filesystem::path(ARTCAL_PLANS_DIR) / name).string();
}

/// tests/data/NAME
inline std::string testDataFile(const std::string& name) {
  return (std::filesystem::path(ARTCAL_TEST_DATA) / name).string();
}

}  // namespace artcal::test_support
