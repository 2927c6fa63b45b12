#include "core/common/closest_name.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace hpose {
namespace {

const std::vector<std::string> kNames = {"estimate", "estimate-stereo", "simulate", "template",
                                         "record",   "replay",          "query",    "plot"};

TEST(ClosestNameTest, OneSlipFindsTheName) {
  EXPECT_EQ(ClosestName("estmate", kNames), "estimate");    // a letter dropped.
  EXPECT_EQ(ClosestName("esttimate", kNames), "estimate");  // one added.
  EXPECT_EQ(ClosestName("estinate", kNames), "estimate");   // one changed.
  EXPECT_EQ(ClosestName("etsimate", kNames), "estimate");   // two neighbours swapped.
  EXPECT_EQ(ClosestName("replya", kNames), "replay");       // swapped at the end.
  EXPECT_EQ(ClosestName("qeury", kNames), "query");         // a swap in a short name.
  EXPECT_EQ(ClosestName("estimate-sterio", kNames), "estimate-stereo");
}

TEST(ClosestNameTest, OtherWordsAndExactNamesGetNone) {
  EXPECT_EQ(ClosestName("estimate", kNames), "");  // a name: nothing to suggest.
  EXPECT_EQ(ClosestName("calibrate", kNames), "");
  EXPECT_EQ(ClosestName("no-such-flag", kNames), "");
  EXPECT_EQ(ClosestName("", kNames), "");
  EXPECT_EQ(ClosestName("x", kNames), "");
  EXPECT_EQ(ClosestName("estimate", {}), "");
  // Short names take one edit only: "plt" is "plot", "pt" is not.
  EXPECT_EQ(ClosestName("plt", kNames), "plot");
  EXPECT_EQ(ClosestName("pt", kNames), "");
  // Two edits in an eight-letter name are still a slip; three are not.
  EXPECT_EQ(ClosestName("stimat", kNames), "estimate");
  EXPECT_EQ(ClosestName("stimt", kNames), "");
}

TEST(ClosestNameTest, TheNearestWinsAndTiesGoToTheFirstListed) {
  EXPECT_EQ(ClosestName("ab", {"abc", "ab_"}), "abc");
  EXPECT_EQ(ClosestName("abcdefx", {"abcdexy", "abcdefy"}), "abcdefy");  // 2 edits, then 1.
}

TEST(ClosestNameTest, DidYouMeanQuotesTheNameWithItsPrefix) {
  EXPECT_EQ(DidYouMean("tempalte", {"template", "out"}, "--"), " (did you mean '--template'?)");
  EXPECT_EQ(DidYouMean("sttus", {"status"}), " (did you mean 'status'?)");
  EXPECT_EQ(DidYouMean("nothing-like", {"status"}), "");
}

}  // namespace
}  // namespace hpose
