#include "core/depth/intrinsics.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace hpose {
namespace {

TEST(IntrinsicsTest, KinectV1NativeMatchesPublishedValues) {
  const Intrinsics k = Intrinsics::KinectV1();
  EXPECT_EQ(k.width, 640);
  EXPECT_EQ(k.height, 480);
  EXPECT_DOUBLE_EQ(k.fx, 594.2);
  EXPECT_DOUBLE_EQ(k.fy, 591.0);
  EXPECT_DOUBLE_EQ(k.cx, 339.3);
  EXPECT_DOUBLE_EQ(k.cy, 242.7);
  EXPECT_TRUE(k.Validate().ok());
}

TEST(IntrinsicsTest, KinectV1ScalesWithResolution) {
  const Intrinsics half = Intrinsics::KinectV1(320, 240);
  EXPECT_EQ(half.width, 320);
  EXPECT_EQ(half.height, 240);
  EXPECT_DOUBLE_EQ(half.fx, 594.2 / 2);
  EXPECT_DOUBLE_EQ(half.fy, 591.0 / 2);
  EXPECT_DOUBLE_EQ(half.cx, 339.3 / 2);
  EXPECT_DOUBLE_EQ(half.cy, 242.7 / 2);
  // Anisotropic scaling scales each axis on its own.
  const Intrinsics odd = Intrinsics::KinectV1(1280, 240);
  EXPECT_DOUBLE_EQ(odd.fx, 594.2 * 2);
  EXPECT_DOUBLE_EQ(odd.fy, 591.0 / 2);
}

TEST(IntrinsicsTest, ValidateNamesTheOffendingField) {
  struct Case {
    const char* field;
    void (*mutate)(Intrinsics*);
  };
  const Case cases[] = {
      {"width", [](Intrinsics* k) { k->width = 0; }},
      {"width", [](Intrinsics* k) { k->width = 8193; }},
      {"height", [](Intrinsics* k) { k->height = -4; }},
      {"fx", [](Intrinsics* k) { k->fx = 0.0; }},
      {"fx", [](Intrinsics* k) { k->fx = -500.0; }},
      {"fy", [](Intrinsics* k) { k->fy = std::numeric_limits<double>::quiet_NaN(); }},
      {"fy", [](Intrinsics* k) { k->fy = std::numeric_limits<double>::infinity(); }},
      {"cx", [](Intrinsics* k) { k->cx = std::numeric_limits<double>::quiet_NaN(); }},
      {"cy", [](Intrinsics* k) { k->cy = -std::numeric_limits<double>::infinity(); }},
      // Finite but absurd: back-projected points would overflow downstream.
      {"fx", [](Intrinsics* k) { k->fx = 1e-30; }},
      {"fx", [](Intrinsics* k) { k->fx = 30.0; }},  // rays 84+ degrees off axis.
      {"fy", [](Intrinsics* k) { k->fy = 1e30; }},
      {"cx", [](Intrinsics* k) { k->cx = 1e12; }},
      {"cy", [](Intrinsics* k) { k->cy = -8193.0; }},
      {"cx", [](Intrinsics* k) { k->cx = 640.0 + 8193.0; }},
  };
  for (const Case& c : cases) {
    Intrinsics k = Intrinsics::KinectV1();
    c.mutate(&k);
    const Status status = k.Validate();
    ASSERT_FALSE(status.ok()) << c.field;
    EXPECT_EQ(status.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(status.error().message.find(c.field), std::string::npos) << status.error().message;
  }
  // Numbers as a person writes them, not in six fixed decimals (1e30 ran to 37 digits).
  Intrinsics k = Intrinsics::KinectV1();
  k.fy = 1e30;
  const Status huge = k.Validate();
  ASSERT_FALSE(huge.ok());
  EXPECT_NE(huge.error().message.find("fy 1e+30 is outside [24.27, 1000000] px"), std::string::npos)
      << huge.error().message;
}

TEST(IntrinsicsTest, PrincipalPointOutsideTheImageIsAllowed) {
  Intrinsics k = Intrinsics::KinectV1();
  k.cx = -10.0;  // cropped images can have it outside.
  EXPECT_TRUE(k.Validate().ok());
  // A 40x40 window at the far corner of a 640x480 image: the principal point is 280 px and
  // 200 px before the window's first column and row.
  Intrinsics corner = Intrinsics::KinectV1();
  corner.width = corner.height = 40;
  corner.cx -= 600.0;
  corner.cy -= 440.0;
  EXPECT_TRUE(corner.Validate().ok()) << corner.Validate().error().message;
  k.cx = 1280.0;
  k.fx = 128.0;  // the widest ray, 1280 px at 128 px focal length, is at the 84 degree limit.
  EXPECT_TRUE(k.Validate().ok());
  k.fx = 127.0;
  EXPECT_FALSE(k.Validate().ok());
}

}  // namespace
}  // namespace hpose
