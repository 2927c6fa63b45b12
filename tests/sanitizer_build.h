// Tests built with the sanitizers (AddressSanitizer, with or without libFuzzer's coverage; see
// `make test-asan`) run many times slower than in the Release build. There:
// - time limits that tests put on programs they start are multiplied by kTimeScale;
// - tests that repeat the same work many times (random scenes, many frames) do fewer rounds
//   (kSanitizerBuild), so every code path is still checked once or more;
// - HPOSE_SKIP_IF_SANITIZED() skips a test whose work alone takes minutes there; it still runs
//   in the Release suite, and the skip says so.
#pragma once

#include <gtest/gtest.h>

namespace hpose::testing {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitizerBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitizerBuild = true;
#else
inline constexpr bool kSanitizerBuild = false;
#endif
#else
inline constexpr bool kSanitizerBuild = false;
#endif

inline constexpr int kTimeScale = kSanitizerBuild ? 6 : 1;

}  // namespace hpose::testing

#define HPOSE_SKIP_IF_SANITIZED()        \
  if (::hpose::testing::kSanitizerBuild) \
  GTEST_SKIP() << "takes minutes under the sanitizers; it runs in the Release suite"
