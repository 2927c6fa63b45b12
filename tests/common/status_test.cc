#include "core/common/status.h"

#include <gtest/gtest.h>

namespace hpose {
namespace {

TEST(ResultTest, HoldsValueOrError) {
  Result<int> good = 7;
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(*good, 7);
  Result<int> bad = MakeError(ErrorCode::kNotFound, "x.bt: no such file");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, ErrorCode::kNotFound);
  EXPECT_EQ(bad.error().ToString(), "not_found: x.bt: no such file");
}

TEST(StatusTest, DefaultIsOk) {
  EXPECT_TRUE(Status().ok());
  Status s = MakeError(ErrorCode::kDataLoss, "truncated");
  EXPECT_FALSE(s.ok());
  EXPECT_STREQ(ErrorCodeName(s.error().code), "data_loss");
}

}  // namespace
}  // namespace hpose
