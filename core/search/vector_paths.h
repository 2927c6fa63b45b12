#ifndef HPOSE_CORE_SEARCH_VECTOR_PATHS_H_
#define HPOSE_CORE_SEARCH_VECTOR_PATHS_H_

#include <string>

namespace hpose {

// The vector paths the estimator takes on this CPU, for logs and benchmark headers: the search's
// run sums and the whole-cloud passes (each AVX-512, AVX2 or scalar), and the cap
// HPOSE_VECTOR_LEVEL sets if any, e.g. "run sums AVX2, whole-cloud passes AVX2 (capped by
// HPOSE_VECTOR_LEVEL=avx2)".
std::string VectorPathsInUse();

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_VECTOR_PATHS_H_
