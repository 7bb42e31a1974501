#pragma once
// Whether the test is built with AddressSanitizer (tools/sanitize.sh), for the few tests that
// scale their work down there (3x slower, 3x the memory). GCC says __SANITIZE_ADDRESS__; clang,
// which tools/sanitize.sh builds with, says it through __has_feature.

namespace artcal::test_support {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kUnderSanitizers = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kUnderSanitizers = true;
#else
inline constexpr bool kUnderSanitizers = false;
#endif
#else
inline constexpr bool kUnderSanitizers = false;
#endif

}  // namespace artcal::test_support
