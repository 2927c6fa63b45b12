#include "core/depth/cloud_validation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

namespace hpose {
namespace {

PointCloud SmallCloud() {
  PointCloud cloud;
  for (int i = 0; i < 10; ++i) cloud.points.emplace_back(0.1f * i, -0.2f, 1.0f + 0.1f * i);
  return cloud;
}

TEST(CloudValidationTest, OrdinaryAndMissingPointsPass) {
  PointCloud cloud = SmallCloud();
  EXPECT_TRUE(ValidateCloud(cloud).ok());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cloud.points[3] = Eigen::Vector3f(nan, nan, nan);
  // One NaN coordinate marks the point missing whatever the others hold.
  cloud.points[4] = Eigen::Vector3f(nan, std::numeric_limits<float>::infinity(), 1e30f);
  EXPECT_TRUE(ValidateCloud(cloud).ok());
  cloud.points[5] = Eigen::Vector3f(-1000.0f, 1000.0f, 999.0f);  // the limit itself is fine.
  EXPECT_TRUE(ValidateCloud(cloud).ok());
  EXPECT_TRUE(ValidateCloud(PointCloud()).ok());
  // The count of points that are not missing comes from the same pass.
  std::size_t finite = 99;
  EXPECT_TRUE(ValidateCloud(cloud, {}, &finite).ok());
  EXPECT_EQ(finite, 8u);
  EXPECT_TRUE(ValidateCloud(PointCloud(), {}, &finite).ok());
  EXPECT_EQ(finite, 0u);
}

TEST(CloudValidationTest, InfiniteAndHugeCoordinatesNameThePoint) {
  for (const float v : {std::numeric_limits<float>::infinity(), -1e38f, 1000.5f}) {
    for (int axis = 0; axis < 3; ++axis) {
      PointCloud cloud = SmallCloud();
      cloud.points[7][axis] = v;
      cloud.points[8][axis] = v;
      const Status s = ValidateCloud(cloud);
      ASSERT_FALSE(s.ok()) << v << " axis " << axis;
      EXPECT_EQ(s.error().code, ErrorCode::kInvalidArgument);
      EXPECT_NE(s.error().message.find("point 7 "), std::string::npos) << s.error().message;
      EXPECT_NE(s.error().message.find("2 of 10"), std::string::npos) << s.error().message;
    }
  }
}

using Validator = Status (*)(const PointCloud&, const CloudLimits&, std::size_t*);

// Large clouds, on every path this CPU has (the sixteen- or eight-point passes, the scalar
// reference): the count of points that are not missing equals a straightforward count, and one
// offending point anywhere, alone or among others, is named with the number of them.
void ExpectCountsAndNames(Validator validate) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (const int n : {1000, 1003, 307200}) {
    PointCloud cloud;
    size_t expected_finite = 0;
    for (int i = 0; i < n; ++i) {
      Eigen::Vector3f p(u(rng), u(rng), u(rng));
      if (i % 13 == 0) p[i % 3] = nan;
      if (i % 97 == 0) p = Eigen::Vector3f(-1000.0f, 1000.0f, 999.0f);  // on the limit: fine.
      expected_finite += p.array().isNaN().any() ? 0 : 1;
      cloud.points.push_back(p);
    }
    std::size_t finite = 0;
    ASSERT_TRUE(validate(cloud, {}, &finite).ok()) << n;
    EXPECT_EQ(finite, expected_finite) << n;
    for (const int at : {0, 17, n / 2 + 5, n - 1}) {
      PointCloud bad = cloud;
      bad.points[at] = Eigen::Vector3f(0.0f, (at % 2) ? 1000.5f : -INFINITY, 1.0f);
      const Status one = validate(bad, {}, nullptr);
      ASSERT_FALSE(one.ok()) << n << " at " << at;
      EXPECT_NE(one.error().message.find("point " + std::to_string(at) + " "), std::string::npos)
          << one.error().message;
      EXPECT_NE(one.error().message.find("1 of " + std::to_string(n)), std::string::npos)
          << one.error().message;
      bad.points[n - 2] = Eigen::Vector3f(2000.0f, 0.0f, 0.0f);
      const Status two = validate(bad, {}, nullptr);
      ASSERT_FALSE(two.ok());
      const int first = std::min(at, n - 2);
      EXPECT_NE(two.error().message.find("point " + std::to_string(first) + " "), std::string::npos)
          << two.error().message;
      EXPECT_NE(two.error().message.find((at == n - 2 ? "1 of " : "2 of ") + std::to_string(n)),
                std::string::npos)
          << two.error().message;
    }
  }
}

TEST(CloudValidationTest, LargeCloudsCountAndNameLikeTheDefinition) {
  ExpectCountsAndNames(&ValidateCloud);
}

TEST(CloudValidationTest, ScalarPassCountsAndNamesLikeTheDefinition) {
  ExpectCountsAndNames(&ValidateCloudScalar);
}

TEST(CloudValidationTest, Avx2PassCountsAndNamesLikeTheDefinition) {
  if (!CloudValidationAvx2Available()) GTEST_SKIP() << "this CPU has no AVX2";
  ExpectCountsAndNames(&ValidateCloudAvx2);
}

TEST(CloudValidationTest, LimitsAreConfigurable) {
  CloudLimits limits;
  limits.max_abs_coordinate_m = 1.0;
  EXPECT_FALSE(ValidateCloud(SmallCloud(), limits).ok());  // z reaches 1.9 m.
  limits.max_abs_coordinate_m = 2.0;
  EXPECT_TRUE(ValidateCloud(SmallCloud(), limits).ok());
  limits.max_points = 9;
  const Status s = ValidateCloud(SmallCloud(), limits);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("10 points"), std::string::npos) << s.error().message;
}

TEST(CloudValidationTest, FloorMustBeARigidFrameAboveTheFloor) {
  EXPECT_TRUE(ValidateFloor(FloorEstimate::FromHeightPitchRoll(0.4, 0.3, -0.1)).ok());
  // Optical axis along the floor normal: no horizontal +x, the rotation degenerates.
  Status s = ValidateFloor(FloorEstimate::FromPlane(Eigen::Vector4d(0.0, 0.0, -1.0, 0.5)));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("floor"), std::string::npos);
  FloorEstimate nan_floor = FloorEstimate::FromHeightPitchRoll(0.4, 0.0, 0.0);
  nan_floor.ground_from_sensor.translation().x() = std::nan("");
  EXPECT_FALSE(ValidateFloor(nan_floor).ok());
  EXPECT_FALSE(ValidateFloor(FloorEstimate::FromHeightPitchRoll(5000.0, 0.0, 0.0)).ok());
  FloorEstimate scaled = FloorEstimate::FromHeightPitchRoll(0.4, 0.0, 0.0);
  scaled.ground_from_sensor.linear() *= 2.0;
  EXPECT_FALSE(ValidateFloor(scaled).ok());
}

}  // namespace
}  // namespace hpose
