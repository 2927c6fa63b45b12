#ifndef HPOSE_CORE_COMMON_VECTOR_LEVEL_H_
#define HPOSE_CORE_COMMON_VECTOR_LEVEL_H_

#include <string_view>

#include "core/common/status.h"

namespace hpose {

// The widest vector instructions core's own passes may take (the run sums, the whole-cloud
// passes, free space, the refinement's placement). Each pass still checks that the CPU has what
// it needs; the level only caps that choice, so one machine can run the AVX2 or the scalar forms
// of a CPU that lacks AVX-512 — to compare them, or to see what another machine does. Every level
// gives the same results. Loops the compiler clones for AVX2 follow the CPU whatever the level.
enum class VectorLevel { kScalar = 0, kAvx2 = 1, kAvx512 = 2 };

// The environment variable that sets the cap: "scalar", "avx2" or "avx512" (no cap).
inline constexpr char kVectorLevelVariable[] = "HPOSE_VECTOR_LEVEL";

// "scalar", "avx2" or "avx512" to a level; anything else is an error naming the accepted words.
Result<VectorLevel> ParseVectorLevel(std::string_view text);
const char* VectorLevelName(VectorLevel level);

// The cap HPOSE_VECTOR_LEVEL sets, read once a process: kAvx512 (none) when it is unset or empty,
// and when it names no level (programs refuse that at start: CheckVectorLevelVariable).
VectorLevel VectorLevelCap();

// Whether the passes capped at `level` may run: VectorLevelCap() >= level.
inline bool VectorLevelAllows(VectorLevel level) { return VectorLevelCap() >= level; }

// An error naming the variable and its value when HPOSE_VECTOR_LEVEL is set to no level.
Status CheckVectorLevelVariable();

}  // namespace hpose

#endif  // HPOSE_CORE_COMMON_VECTOR_LEVEL_H_
