#include "core/depth/depth_to_cloud.h"

#include <cmath>
#include <cstring>
#include <random>
#include <string>

#include <gtest/gtest.h>

namespace hpose {
namespace {

// A tiny camera whose numbers make hand computation easy.
Intrinsics SmallCamera() {
  Intrinsics k;
  k.width = 4;
  k.height = 3;
  k.fx = 2.0;
  k.fy = 4.0;
  k.cx = 1.5;
  k.cy = 1.0;
  return k;
}

TEST(DepthToCloudTest, BackProjectsHandComputedPixels) {
  DepthImage depth(4, 3);
  depth.at(3, 2) = 2000;  // z = 2: x = (3 - 1.5) * 2 / 2 = 1.5, y = (2 - 1) * 2 / 4 = 0.5.
  depth.at(0, 0) = 1000;  // z = 1: x = -1.5 / 2 = -0.75, y = -1 / 4 = -0.25.
  const Result<PointCloud> cloud = DepthToCloud(depth, SmallCamera());
  ASSERT_TRUE(cloud.ok()) << cloud.error().ToString();
  ASSERT_EQ(cloud->size(), 2u);
  EXPECT_FALSE(cloud->organised());
  // Row-major order: (0, 0) first.
  EXPECT_NEAR(cloud->points[0].x(), -0.75f, 1e-6);
  EXPECT_NEAR(cloud->points[0].y(), -0.25f, 1e-6);
  EXPECT_NEAR(cloud->points[0].z(), 1.0f, 1e-6);
  EXPECT_NEAR(cloud->points[1].x(), 1.5f, 1e-6);
  EXPECT_NEAR(cloud->points[1].y(), 0.5f, 1e-6);
  EXPECT_NEAR(cloud->points[1].z(), 2.0f, 1e-6);
}

TEST(DepthToCloudTest, KinectPrincipalPointMapsOntoTheOpticalAxis) {
  const Intrinsics k = Intrinsics::KinectV1();
  DepthImage depth(640, 480);
  // Pixel 100 px right of and 50 px below the principal point (rounded to a pixel).
  const int u = 439, v = 293;
  depth.at(u, v) = 1500;
  const Result<PointCloud> cloud = DepthToCloud(depth, k);
  ASSERT_TRUE(cloud.ok());
  ASSERT_EQ(cloud->size(), 1u);
  EXPECT_NEAR(cloud->points[0].x(), (u - 339.3) * 1.5 / 594.2, 1e-5);
  EXPECT_NEAR(cloud->points[0].y(), (v - 242.7) * 1.5 / 591.0, 1e-5);
  EXPECT_NEAR(cloud->points[0].z(), 1.5, 1e-6);
}

TEST(DepthToCloudTest, DropsZeroAndOutOfRangeReadings) {
  DepthImage depth(4, 3);
  depth.at(0, 0) = 0;      // no reading.
  depth.at(1, 0) = 300;    // nearer than 0.4 m.
  depth.at(2, 0) = 400;    // exactly the minimum: kept.
  depth.at(3, 0) = 4500;   // exactly the maximum: kept.
  depth.at(0, 1) = 4501;   // beyond.
  depth.at(1, 1) = 65535;  // beyond.
  const Result<PointCloud> cloud = DepthToCloud(depth, SmallCamera());
  ASSERT_TRUE(cloud.ok());
  ASSERT_EQ(cloud->size(), 2u);
  EXPECT_NEAR(cloud->points[0].z(), 0.4f, 1e-6);
  EXPECT_NEAR(cloud->points[1].z(), 4.5f, 1e-6);
}

// An image with no point in range says why: no reading at all, or where its readings lie,
// with a word on units when they are all a few millimetres.
TEST(DepthToCloudTest, NoPointInRangeSaysWhereTheReadingsLie) {
  DepthImage depth(4, 3);
  EXPECT_EQ(NoPointInRangeReason(depth, {}),
            "no pixel of the 4x3 depth image holds a reading (every value is 0)");
  depth.at(1, 1) = 2;
  depth.at(2, 2) = 4;
  ASSERT_TRUE(DepthToCloud(depth, SmallCamera())->empty());
  const std::string metres = NoPointInRangeReason(depth, {});
  EXPECT_NE(metres.find("none of the 2 readings of the 4x3 depth image lies within 0.40-4.50 m "
                        "(they span 2-4 mm; depth images hold millimetres"),
            std::string::npos)
      << metres;
  depth.at(1, 1) = 5000;
  depth.at(2, 2) = 6000;
  const std::string far = NoPointInRangeReason(depth, {});
  EXPECT_NE(far.find("lies within 0.40-4.50 m (they span 5000-6000 mm)"), std::string::npos) << far;
  EXPECT_EQ(far.find("millimetres"), std::string::npos) << far;
}

TEST(DepthToCloudTest, OrganisedKeepsNaNForInvalidPixels) {
  DepthImage depth(4, 3);
  depth.at(1, 2) = 1000;
  DepthToCloudOptions options;
  options.keep_organised = true;
  const Result<PointCloud> cloud = DepthToCloud(depth, SmallCamera(), options);
  ASSERT_TRUE(cloud.ok());
  EXPECT_TRUE(cloud->organised());
  EXPECT_EQ(cloud->width, 4);
  EXPECT_EQ(cloud->height, 3);
  for (int i = 0; i < 12; ++i) {
    if (i == 2 * 4 + 1) {
      EXPECT_TRUE(cloud->points[i].allFinite());
      EXPECT_NEAR(cloud->points[i].x(), (1 - 1.5) * 1.0 / 2.0, 1e-6);
    } else {
      EXPECT_TRUE(std::isnan(cloud->points[i].x())) << i;
    }
  }
}

TEST(DepthToCloudTest, StrideSkipsPixelsAndKeepsTheirCoordinates) {
  const Intrinsics k = Intrinsics::KinectV1();
  DepthImage depth(640, 480);
  for (auto& mm : depth.mm) mm = 1000;
  DepthToCloudOptions options;
  options.stride = 2;
  options.keep_organised = true;
  const Result<PointCloud> cloud = DepthToCloud(depth, k, options);
  ASSERT_TRUE(cloud.ok());
  EXPECT_EQ(cloud->width, 320);
  EXPECT_EQ(cloud->height, 240);
  ASSERT_EQ(cloud->size(), 320u * 240u);
  // Output pixel (10, 7) is input pixel (20, 14).
  const Eigen::Vector3f p = cloud->points[7 * 320 + 10];
  EXPECT_NEAR(p.x(), (20 - 339.3) / 594.2, 1e-5);
  EXPECT_NEAR(p.y(), (14 - 242.7) / 591.0, 1e-5);
  // Odd sizes round up.
  DepthImage odd(5, 3);
  Intrinsics ko = SmallCamera();
  ko.width = 5;
  options.stride = 2;
  const Result<PointCloud> odd_cloud = DepthToCloud(odd, ko, options);
  ASSERT_TRUE(odd_cloud.ok());
  EXPECT_EQ(odd_cloud->width, 3);
  EXPECT_EQ(odd_cloud->height, 2);
}

TEST(DepthToCloudTest, RejectsMismatchedSizesAndBadOptions) {
  DepthImage depth(4, 3);
  Intrinsics wrong = SmallCamera();
  wrong.width = 8;
  Result<PointCloud> cloud = DepthToCloud(depth, wrong);
  ASSERT_FALSE(cloud.ok());
  EXPECT_EQ(cloud.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(cloud.error().message.find("4x3"), std::string::npos) << cloud.error().message;

  Intrinsics bad = SmallCamera();
  bad.fx = -1.0;
  cloud = DepthToCloud(depth, bad);
  ASSERT_FALSE(cloud.ok());
  EXPECT_NE(cloud.error().message.find("fx"), std::string::npos);

  DepthImage short_buffer(4, 3);
  short_buffer.mm.resize(5);
  cloud = DepthToCloud(short_buffer, SmallCamera());
  ASSERT_FALSE(cloud.ok());
  EXPECT_EQ(cloud.error().code, ErrorCode::kInvalidArgument);

  DepthToCloudOptions options;
  options.stride = 0;
  cloud = DepthToCloud(depth, SmallCamera(), options);
  ASSERT_FALSE(cloud.ok());
  EXPECT_NE(cloud.error().message.find("stride"), std::string::npos);

  options = {};
  options.min_range_m = 3.0;
  options.max_range_m = 1.0;
  cloud = DepthToCloud(depth, SmallCamera(), options);
  ASSERT_FALSE(cloud.ok());
  EXPECT_EQ(cloud.error().code, ErrorCode::kInvalidArgument);
}

// A vector back-projection against the scalar reference, to the bit: widths that are and are
// not multiples of sixteen and eight, readings below, within and beyond the range (and 0,
// 65535), organised or not, strides 1 and 2 (2 always takes the scalar loop).
void ExpectEqualToTheScalarReference(Result<PointCloud> (*project)(const DepthImage&,
                                                                   const Intrinsics&,
                                                                   const DepthToCloudOptions&),
                                     const char* name) {
  std::mt19937 rng(17);
  const std::uint16_t specials[] = {0, 1, 399, 400, 401, 4500, 4501, 65535};
  int compared = 0;
  for (const auto& [w, h] : {std::pair{640, 480}, std::pair{37, 5}, std::pair{16, 3},
                             std::pair{15, 4}, std::pair{1, 7}}) {
    Intrinsics k = Intrinsics::KinectV1();
    k.width = w;
    k.height = h;
    k.cx = 0.5 * w - 0.3;
    k.cy = 0.5 * h + 0.2;
    DepthImage depth(w, h);
    std::uniform_int_distribution<int> any(0, 5000), pick(0, 9);
    for (std::uint16_t& d : depth.mm) {
      const int r = pick(rng);
      d = r < 2 ? specials[any(rng) % 8] : static_cast<std::uint16_t>(any(rng));
    }
    for (const bool organised : {false, true}) {
      for (const int stride : {1, 2}) {
        DepthToCloudOptions o;
        o.keep_organised = organised;
        o.stride = stride;
        const Result<PointCloud> fast = project(depth, k, o);
        const Result<PointCloud> ref = DepthToCloudScalar(depth, k, o);
        ASSERT_TRUE(fast.ok() && ref.ok());
        ASSERT_EQ(fast->size(), ref->size()) << w << "x" << h;
        ASSERT_GT(ref->size(), 0u);
        EXPECT_EQ(fast->width, ref->width);
        EXPECT_EQ(fast->height, ref->height);
        for (size_t i = 0; i < ref->size(); ++i) {
          const Eigen::Vector3f& a = fast->points[i];
          const Eigen::Vector3f& b = ref->points[i];
          if (std::isnan(b.z())) {
            ASSERT_TRUE(std::isnan(a.x()) && std::isnan(a.y()) && std::isnan(a.z())) << i;
            continue;
          }
          ASSERT_EQ(std::memcmp(a.data(), b.data(), sizeof(float) * 3), 0)
              << name << " " << w << "x" << h << " point " << i << ": " << a.transpose() << " vs "
              << b.transpose();
          ++compared;
        }
      }
    }
  }
  EXPECT_GT(compared, 400000);
}

// The dispatched path (sixteen pixels a step with AVX-512, eight with AVX2).
TEST(DepthToCloudTest, VectorisedEqualsTheScalarReferenceToTheBit) {
  if (!DepthToCloudVectorised()) {
    GTEST_SKIP() << "no AVX-512 or AVX2 on this CPU: DepthToCloud is the scalar loop itself";
  }
  ExpectEqualToTheScalarReference(DepthToCloud, "dispatched");
}

TEST(DepthToCloudTest, EightPixelsAStepEqualTheScalarReferenceToTheBit) {
  if (!DepthToCloudAvx2Available()) GTEST_SKIP() << "no AVX2 on this CPU";
  ExpectEqualToTheScalarReference(DepthToCloudAvx2, "avx2");
}

}  // namespace
}  // namespace hpose
