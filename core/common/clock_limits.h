#ifndef HPOSE_CORE_COMMON_CLOCK_LIMITS_H_
#define HPOSE_CORE_COMMON_CLOCK_LIMITS_H_

namespace hpose {

// Rates and waits every program accepts, so that each stays where a clock can count it: a frame
// every 100 s at the slowest and 10 000 a second at the fastest, waits and timeouts of at most
// a day (longer ones overflow the milliseconds and ticks they become). hposed's config, replay,
// record, query and the stereo simulation all check against these.
inline constexpr double kMinFrameRateHz = 0.01;
inline constexpr double kMaxFrameRateHz = 10000.0;
inline constexpr double kMaxWaitS = 86400.0;

// fps in [kMinFrameRateHz, kMaxFrameRateHz]; false for NaN.
inline bool FrameRateInRange(double fps) {
  return fps >= kMinFrameRateHz && fps <= kMaxFrameRateHz;
}

// seconds in (0, kMaxWaitS]; false for NaN.
inline bool WaitInRange(double seconds) { return seconds > 0.0 && seconds <= kMaxWaitS; }

}  // namespace hpose

#endif  // HPOSE_CORE_COMMON_CLOCK_LIMITS_H_
