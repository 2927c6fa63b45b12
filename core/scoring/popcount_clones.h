#ifndef HPOSE_CORE_SCORING_POPCOUNT_CLONES_H_
#define HPOSE_CORE_SCORING_POPCOUNT_CLONES_H_

// The bound loops are popcount-bound. Without -mpopcnt, __builtin_popcountll is a call into
// libgcc; on x86-64 compile a POPCNT clone too, chosen at load time (ifunc) where the CPU has it.
// Private to the scoring sources.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__POPCNT__) && defined(__has_attribute)
#if __has_attribute(target_clones) && defined(__gnu_linux__)
#define HPOSE_POPCNT_CLONES __attribute__((target_clones("popcnt", "default")))
#endif
#endif
#ifndef HPOSE_POPCNT_CLONES
#define HPOSE_POPCNT_CLONES
#endif

#endif  // HPOSE_CORE_SCORING_POPCOUNT_CLONES_H_
