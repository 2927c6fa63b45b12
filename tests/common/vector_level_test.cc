#include "core/common/vector_level.h"

#include <gtest/gtest.h>

namespace hpose {
namespace {

TEST(VectorLevelTest, NamesParseBackToTheirLevels) {
  for (VectorLevel level : {VectorLevel::kScalar, VectorLevel::kAvx2, VectorLevel::kAvx512}) {
    const Result<VectorLevel> parsed = ParseVectorLevel(VectorLevelName(level));
    ASSERT_TRUE(parsed.ok()) << VectorLevelName(level);
    EXPECT_EQ(*parsed, level);
  }
  EXPECT_STREQ(VectorLevelName(VectorLevel::kAvx2), "avx2");
}

TEST(VectorLevelTest, OtherWordsAreRefusedNamingTheAcceptedOnes) {
  for (const char* text : {"", "AVX2", "avx", "sse4", "avx2 ", "avx512f"}) {
    const Result<VectorLevel> parsed = ParseVectorLevel(text);
    ASSERT_FALSE(parsed.ok()) << text;
    EXPECT_EQ(parsed.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(parsed.error().message.find("scalar, avx2 or avx512"), std::string::npos)
        << parsed.error().message;
    EXPECT_NE(parsed.error().message.find(std::string("\"") + text + "\""), std::string::npos)
        << parsed.error().message;
  }
}

TEST(VectorLevelTest, LevelsAreOrderedFromScalarToAvx512) {
  EXPECT_LT(VectorLevel::kScalar, VectorLevel::kAvx2);
  EXPECT_LT(VectorLevel::kAvx2, VectorLevel::kAvx512);
  // Whatever this process's cap, the scalar passes are always allowed.
  EXPECT_TRUE(VectorLevelAllows(VectorLevel::kScalar));
}

}  // namespace
}  // namespace hpose
