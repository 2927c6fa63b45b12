#ifndef HPOSE_CORE_SCORING_GATHER_SUMS_H_
#define HPOSE_CORE_SCORING_GATHER_SUMS_H_

#include <cstddef>
#include <cstdint>

namespace hpose {

// The sum over c in [0, n) of popcount(masks[c] & data[base + cy[c] * row + cxe[c]]): one
// masked lookup per template column or cell group, the inner loop of the exact search's values
// and bounds (ColumnOccupancy's aligned path). Every offset cy[c] * row + cxe[c] must fit in 32
// bits (occupancy boxes are a few hundred cells a side).
//
// GatherPopcountSum takes eight lookups at a time with AVX-512 gathers and 64-bit popcounts
// where the CPU has them (GatherPopcountSumVectorised()), and the scalar loop otherwise;
// GatherPopcountSumScalar is that loop, the reference. Integer sums, so both are equal.
int GatherPopcountSum(const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row,
                      const std::int32_t* cxe, const std::int32_t* cy, const std::uint64_t* masks,
                      int n);
int GatherPopcountSumScalar(const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row,
                            const std::int32_t* cxe, const std::int32_t* cy,
                            const std::uint64_t* masks, int n);
// GatherPopcountSum at base, base + dy, base + dx and base + dx + dy into out[0], out[1], out[2]
// and out[3] (the four blocks of a bound a whole number of cells apart), in one pass; the same
// dispatch, and the scalar reference.
void GatherPopcountSum4(const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row,
                        std::ptrdiff_t dx, std::ptrdiff_t dy, const std::int32_t* cxe,
                        const std::int32_t* cy, const std::uint64_t* masks, int n, int out[4]);
void GatherPopcountSum4Scalar(const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row,
                              std::ptrdiff_t dx, std::ptrdiff_t dy, const std::int32_t* cxe,
                              const std::int32_t* cy, const std::uint64_t* masks, int n,
                              int out[4]);
bool GatherPopcountSumVectorised();

// The same sum over runs of consecutive words: run r adds popcount(masks[k] & words[i]) for
// the run_len[r] (at most 8) words from plane + base + run_cy[r] * row + run_cx[r], k counting
// on through `masks` run after run (CellGroups' runs over a plane of one word per cell). With
// AVX-512 a run is one masked load; the scalar loop is the reference.
int RunPopcountSum(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                   const std::int32_t* run_cx, const std::int32_t* run_cy,
                   const std::int32_t* run_len, const std::uint64_t* masks, int runs);
int RunPopcountSumScalar(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                         const std::int32_t* run_cx, const std::int32_t* run_cy,
                         const std::int32_t* run_len, const std::uint64_t* masks, int runs);
// RunPopcountSum at base, base + dy, base + dx and base + dx + dy into out[0 .. 3].
void RunPopcountSum4(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                     std::ptrdiff_t dx, std::ptrdiff_t dy, const std::int32_t* run_cx,
                     const std::int32_t* run_cy, const std::int32_t* run_len,
                     const std::uint64_t* masks, int runs, int out[4]);
void RunPopcountSum4Scalar(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                           std::ptrdiff_t dx, std::ptrdiff_t dy, const std::int32_t* run_cx,
                           const std::int32_t* run_cy, const std::int32_t* run_len,
                           const std::uint64_t* masks, int runs, int out[4]);

}  // namespace hpose

#endif  // HPOSE_CORE_SCORING_GATHER_SUMS_H_
