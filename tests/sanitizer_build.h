// How much longer a program may take in tests: instrumented builds (AddressSanitizer, with or
// without libFuzzer's coverage) run several times slower, so the time limits tests put on
// programs they start are multiplied by kTimeScale there (1 in a normal build).
#pragma once

namespace hpose::testing {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr int kTimeScale = 6;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr int kTimeScale = 6;
#else
inline constexpr int kTimeScale = 1;
#endif
#else
inline constexpr int kTimeScale = 1;
#endif

}  // namespace hpose::testing
