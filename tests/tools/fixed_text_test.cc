// The figures and phrases the commands print (tools/fixed_text.h).
#include "tools/fixed_text.h"

#include <gtest/gtest.h>

namespace hpose::tools {
namespace {

TEST(FixedTextTest, FixedKeepsTheDecimalsAsked) {
  EXPECT_EQ(Fixed(3.14159, 2), "3.14");
  EXPECT_EQ(Fixed(-0.126, 2), "-0.13");
  EXPECT_EQ(Fixed(12.0, 3), "12.000");
}

TEST(FixedTextTest, FormatNumberFollowsItsFormat) {
  EXPECT_EQ(FormatNumber("%.1f s", 2.26), "2.3 s");
  EXPECT_EQ(FormatNumber("x %g m", 0.5), "x 0.5 m");
  EXPECT_EQ(FormatNumber("%.0f", -3.6), "-4");
  EXPECT_EQ(FormatNumber("%.3g", 1234.5), "1.23e+03");
}

// A closest approach still to come reads "in"; one already past reads "ago", not "in -13 s".
TEST(FixedTextTest, ApproachTextSaysWhetherItIsToComeOrPast) {
  EXPECT_EQ(ApproachText(0.3134, 0.447), ", passes 313 mm from the robot in 0.45 s");
  EXPECT_EQ(ApproachText(0.6772, -13.19), ", passed 677 mm from the robot 13.19 s ago");
  EXPECT_EQ(ApproachText(0.1, 0.0), ", passes 100 mm from the robot in 0.00 s");
}

}  // namespace
}  // namespace hpose::tools
