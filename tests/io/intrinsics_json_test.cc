#include "core/io/intrinsics_json.h"

#include <gtest/gtest.h>

#include "tests/io/temp_dir.h"

namespace hpose {
namespace {

const char kValid[] =
    R"({"width": 640, "height": 480, "fx": 525.0, "fy": 525.5, "cx": 319.5, "cy": 239.5})";

TEST(IntrinsicsJsonTest, ParsesAValidDocument) {
  const Result<Intrinsics> k = ParseIntrinsicsJson(kValid, "cam.json");
  ASSERT_TRUE(k.ok()) << k.error().ToString();
  EXPECT_EQ(k->width, 640);
  EXPECT_EQ(k->height, 480);
  EXPECT_DOUBLE_EQ(k->fx, 525.0);
  EXPECT_DOUBLE_EQ(k->fy, 525.5);
  EXPECT_DOUBLE_EQ(k->cx, 319.5);
  EXPECT_DOUBLE_EQ(k->cy, 239.5);
}

TEST(IntrinsicsJsonTest, RoundTripsThroughAFileExactly) {
  TempDir dir;
  Intrinsics k = Intrinsics::KinectV1(320, 240);
  k.cx = 0.1 + 0.2;  // a value without a short decimal form.
  const std::string path = dir.File("intrinsics.json");
  ASSERT_TRUE(WriteIntrinsicsJson(k, path).ok());
  const Result<Intrinsics> back = ReadIntrinsicsJson(path);
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(back->width, k.width);
  EXPECT_EQ(back->height, k.height);
  EXPECT_EQ(back->fx, k.fx);
  EXPECT_EQ(back->fy, k.fy);
  EXPECT_EQ(back->cx, k.cx);
  EXPECT_EQ(back->cy, k.cy);
  EXPECT_EQ(ParseIntrinsicsJson(IntrinsicsToJson(k), "s")->cx, k.cx);
}

struct BadCase {
  const char* json;
  const char* must_mention;
};

class IntrinsicsJsonBadTest : public ::testing::TestWithParam<BadCase> {};

TEST_P(IntrinsicsJsonBadTest, IsInvalidArgumentNamingTheProblem) {
  const BadCase c = GetParam();
  const Result<Intrinsics> k = ParseIntrinsicsJson(c.json, "cam.json");
  ASSERT_FALSE(k.ok()) << c.json;
  EXPECT_EQ(k.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(k.error().message.find("cam.json"), std::string::npos) << k.error().message;
  EXPECT_NE(k.error().message.find(c.must_mention), std::string::npos) << k.error().message;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, IntrinsicsJsonBadTest,
    ::testing::Values(
        BadCase{"", "not valid JSON"}, BadCase{"{\"width\": 640,", "not valid JSON"},
        BadCase{"[1, 2, 3]", "object"},
        BadCase{R"({"width": 640, "height": 480, "fx": 1, "fy": 1, "cx": 1, "cy": 1, "k1": 0})",
                "unknown key 'k1'"},
        BadCase{R"({"width": 640, "height": 480, "fx": 1, "fy": 1, "cx": 1})", "missing key 'cy'"},
        BadCase{R"({"width": "640", "height": 480, "fx": 1, "fy": 1, "cx": 1, "cy": 1})",
                "'width' must be an integer"},
        BadCase{R"({"width": 640.5, "height": 480, "fx": 1, "fy": 1, "cx": 1, "cy": 1})",
                "'width' must be an integer"},
        BadCase{R"({"width": 640, "height": 0, "fx": 1, "fy": 1, "cx": 1, "cy": 1})", "height"},
        BadCase{R"({"width": 640, "height": 480, "fx": -525, "fy": 1, "cx": 1, "cy": 1})", "fx"},
        BadCase{R"({"width": 640, "height": 480, "fx": 1, "fy": null, "cx": 1, "cy": 1})",
                "'fy' must be a number"},
        BadCase{R"({"width": 640, "height": 480, "fx": 1, "fy": 1, "cx": true, "cy": 1})",
                "'cx' must be a number"},
        // NaN and Infinity are not JSON; the parser's message gives the position.
        BadCase{R"({"width": 640, "height": 480, "fx": NaN, "fy": 1, "cx": 1, "cy": 1})",
                "not valid JSON"},
        BadCase{R"({"width": 640, "height": 480, "fx": 1, "fy": 1, "cx": 1, "cy": "NaN"})",
                "'cy' must be a number"},
        // Beyond double: rejected by the parser (an exception inside, an error outside).
        BadCase{R"({"width": 640, "height": 480, "fx": 1e999, "fy": 1, "cx": 1, "cy": 1})",
                "1e999"}));

TEST(IntrinsicsJsonTest, FileErrors) {
  TempDir dir;
  Result<Intrinsics> k = ReadIntrinsicsJson(dir.File("none.json"));
  ASSERT_FALSE(k.ok());
  EXPECT_EQ(k.error().code, ErrorCode::kNotFound);
  k = ReadIntrinsicsJson(dir.Write("garbage.json", std::string("\x89PNG\r\n\x1a\n\0\0", 10)));
  ASSERT_FALSE(k.ok());
  EXPECT_EQ(k.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(k.error().message.find("garbage.json"), std::string::npos);
  Intrinsics bad = Intrinsics::KinectV1();
  bad.fy = 0.0;
  const Status written = WriteIntrinsicsJson(bad, dir.File("bad.json"));
  ASSERT_FALSE(written.ok());
  EXPECT_NE(written.error().message.find("fy"), std::string::npos);
}

}  // namespace
}  // namespace hpose
