#include "core/search/vector_paths.h"

#include "core/common/vector_level.h"
#include "core/depth/point_lanes.h"
#include "core/scoring/gather_sums.h"

namespace hpose {

std::string VectorPathsInUse() {
  const RunSumPath run = FastestRunSumPath();
  std::string out = std::string("run sums ") +
                    (run == RunSumPath::kAvx512 ? "AVX-512"
                     : run == RunSumPath::kAvx2 ? "AVX2"
                                                : "scalar") +
                    ", whole-cloud passes " +
                    (PointLanesAvailable()    ? "AVX-512"
                     : PointLanes8Available() ? "AVX2"
                                              : "scalar");
  if (VectorLevelCap() != VectorLevel::kAvx512) {
    out += std::string(" (capped by ") + kVectorLevelVariable + "=" +
           VectorLevelName(VectorLevelCap()) + ")";
  }
  return out;
}

}  // namespace hpose
