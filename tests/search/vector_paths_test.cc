// The cap HPOSE_VECTOR_LEVEL sets, in a process of its own: it is read once, at the first
// check of a vector path, so the variable is set before anything else here runs.
#include "core/search/vector_paths.h"

#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "core/common/vector_level.h"
#include "core/depth/point_lanes.h"
#include "core/scoring/gather_sums.h"

namespace hpose {
namespace {

TEST(VectorPathsTest, TheCapKeepsEveryPathAtOrBelowAvx2AndIsNamed) {
  ASSERT_EQ(setenv(kVectorLevelVariable, "avx2", 1), 0);
  EXPECT_EQ(VectorLevelCap(), VectorLevel::kAvx2);
  EXPECT_FALSE(PointLanesAvailable());
  EXPECT_NE(FastestRunSumPath(), RunSumPath::kAvx512);
  EXPECT_FALSE(RunSumPathAvailable(RunSumPath::kAvx512));
  EXPECT_FALSE(GatherPopcountSumVectorised());
  const std::string paths = VectorPathsInUse();
  EXPECT_EQ(paths.find("AVX-512"), std::string::npos) << paths;
  EXPECT_EQ(paths.rfind("run sums ", 0), 0u) << paths;
  EXPECT_NE(paths.find(", whole-cloud passes "), std::string::npos) << paths;
  EXPECT_NE(paths.find(" (capped by HPOSE_VECTOR_LEVEL=avx2)"), std::string::npos) << paths;
  // Read once: a later change of the variable changes nothing in this process.
  ASSERT_EQ(setenv(kVectorLevelVariable, "scalar", 1), 0);
  EXPECT_EQ(VectorLevelCap(), VectorLevel::kAvx2);
  EXPECT_EQ(VectorPathsInUse(), paths);
}

}  // namespace
}  // namespace hpose
