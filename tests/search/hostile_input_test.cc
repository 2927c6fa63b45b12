// Crafted inputs that used to turn into NaN or infinite coordinates inside the estimator (and
// then into PCL's kd-tree assertion, which aborts the process) are refused with
// kInvalidArgument, or estimated without harm; none of them may crash.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/depth/depth_to_cloud.h"
#include "core/search/estimator.h"
#include "core/sim/frame_simulator.h"
#include "core/sim/humanoid_model.h"

namespace hpose {
namespace {

VoxelTemplate StandingTemplate() {
  const HumanoidModel model = *HumanoidModel::FromPreset("standing");
  const std::vector<Eigen::Vector3f> pts = *model.SampleSurface(0.004);
  return *MakeTemplateFromPoints(pts, "standing", 0.016, "standing", "test");
}

class HostileInputTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    estimator_ = Estimator::Create(DefaultEstimatorOptions(), {StandingTemplate()})->release();
    FrameSpec spec;
    spec.intrinsics = Intrinsics::KinectV1(320, 240);
    spec.clutter = 2;
    spec.seed = 3;
    frame_ = new SimulatedFrame(*SimulateFrame(spec));
    intrinsics_ = new Intrinsics(spec.intrinsics);
  }
  static void TearDownTestSuite() {
    delete estimator_;
    delete frame_;
    delete intrinsics_;
  }

  static PointCloud FrameCloud() { return *DepthToCloud(frame_->depth, *intrinsics_); }

  static Estimator* estimator_;
  static SimulatedFrame* frame_;
  static Intrinsics* intrinsics_;
};

Estimator* HostileInputTest::estimator_ = nullptr;
SimulatedFrame* HostileInputTest::frame_ = nullptr;
Intrinsics* HostileInputTest::intrinsics_ = nullptr;

TEST_F(HostileInputTest, TheUnharmedFrameIsEstimated) {
  Result<Estimate> e = estimator_->EstimateCloud(FrameCloud());
  ASSERT_TRUE(e.ok()) << e.error().ToString();
  EXPECT_FALSE(e->Humanoids().empty());
}

// A depth frame with no reading in range (a covered lens, or an image in metres) is refused
// with what the image holds, not as an empty cloud.
TEST_F(HostileInputTest, DepthWithoutReadingsInRangeSaysWhatItHolds) {
  DepthImage blank(intrinsics_->width, intrinsics_->height);
  Result<Estimate> e = estimator_->EstimateDepth(blank, *intrinsics_);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(e.error().message.find("no depth to estimate from: no pixel of the 320x240 depth "
                                   "image holds a reading"),
            std::string::npos)
      << e.error().message;
  DepthImage in_metres = frame_->depth;
  for (std::uint16_t& v : in_metres.mm) v = static_cast<std::uint16_t>(v / 1000);
  e = estimator_->EstimateDepth(in_metres, *intrinsics_);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("one in metres reads so"), std::string::npos)
      << e.error().message;
  EXPECT_TRUE(estimator_->EstimateDepth(frame_->depth, *intrinsics_).ok());
}

TEST_F(HostileInputTest, ExtremeFocalLengthsAreInvalidArgument) {
  for (const double f : {1e-34, 1e-35, 1e-30, 1e-40, 1e-300, 1e-3, 1e30, 1e300}) {
    Intrinsics k = *intrinsics_;
    k.fx = f;
    Result<Estimate> e = estimator_->EstimateDepth(frame_->depth, k);
    ASSERT_FALSE(e.ok()) << "fx " << f;
    EXPECT_EQ(e.error().code, ErrorCode::kInvalidArgument) << e.error().ToString();
    EXPECT_NE(e.error().message.find("fx"), std::string::npos) << e.error().message;
    k = *intrinsics_;
    k.fy = f;
    e = estimator_->EstimateDepth(frame_->depth, k);
    ASSERT_FALSE(e.ok()) << "fy " << f;
    EXPECT_NE(e.error().message.find("fy"), std::string::npos) << e.error().message;
  }
}

TEST_F(HostileInputTest, FarPrincipalPointIsInvalidArgument) {
  Intrinsics k = *intrinsics_;
  k.cx = 1e12;
  Result<Estimate> e = estimator_->EstimateDepth(frame_->depth, k);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(e.error().message.find("cx"), std::string::npos) << e.error().message;
}

TEST_F(HostileInputTest, HugeCoordinatesAreInvalidArgument) {
  for (const float v : {1e38f, -3e38f, 1e20f, 2000.0f}) {
    for (int axis = 0; axis < 3; ++axis) {
      PointCloud cloud = FrameCloud();
      cloud.points[cloud.size() / 2][axis] = v;
      // Many of them: they share the last voxel of the downsampling grid, whose centroid sum
      // overflows to infinity.
      for (size_t i = 0; i < cloud.size(); i += 50) cloud.points[i] = Eigen::Vector3f::Constant(v);
      Result<Estimate> e = estimator_->EstimateCloud(cloud);
      ASSERT_FALSE(e.ok()) << v << " on axis " << axis;
      EXPECT_EQ(e.error().code, ErrorCode::kInvalidArgument) << e.error().ToString();
      EXPECT_NE(e.error().message.find("point"), std::string::npos) << e.error().message;
    }
  }
}

TEST_F(HostileInputTest, InfiniteCoordinatesAreInvalidArgument) {
  const float inf = std::numeric_limits<float>::infinity();
  PointCloud cloud = FrameCloud();
  cloud.points[10] = Eigen::Vector3f(0.0f, inf, 1.0f);
  Result<Estimate> e = estimator_->EstimateCloud(cloud);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(e.error().message.find("point 10"), std::string::npos) << e.error().message;
}

TEST_F(HostileInputTest, MissingPointsAreStillSkipped) {
  PointCloud cloud = FrameCloud();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (size_t i = 0; i < cloud.size(); i += 7) cloud.points[i] = Eigen::Vector3f(nan, 0.0f, 1.0f);
  Result<Estimate> e = estimator_->EstimateCloud(cloud);
  ASSERT_TRUE(e.ok()) << e.error().ToString();
  EXPECT_LT(e->cloud_points, static_cast<int>(cloud.size()));
}

// Clouds built to make the floor fit and the ground transform degenerate: every point in one
// spot, a single line along the optical axis, points almost at the optical centre (huge ray
// slopes for the free-space range image), one plane containing the optical axis.
TEST_F(HostileInputTest, DegenerateCloudsDoNotCrash) {
  std::vector<PointCloud> clouds(5);
  for (int i = 0; i < 5000; ++i) {
    const float t = static_cast<float>(i) / 5000.0f;
    clouds[0].points.emplace_back(0.1f, 0.2f, 1.0f);
    clouds[1].points.emplace_back(0.0f, 0.0f, 0.5f + 3.0f * t);
    clouds[2].points.emplace_back(1e-3f * (t - 0.5f), 0.3f, 1e-30f * t);
    clouds[3].points.emplace_back(2.0f * (t - 0.5f), 0.0f, 0.5f + 3.0f * std::fmod(t * 37, 1.0f));
    clouds[4].points.emplace_back(999.0f * (t - 0.5f), 999.0f * std::fmod(t * 37, 1.0f),
                                  1e-20f + 999.0f * std::fmod(t * 91, 1.0f));
  }
  // Plus the frame with the same additions (a floor is found, the rest must not disturb it).
  for (int c = 0; c < 5; ++c) {
    PointCloud with_frame = FrameCloud();
    with_frame.points.insert(with_frame.points.end(), clouds[c].points.begin(),
                             clouds[c].points.end());
    clouds.push_back(with_frame);
  }
  for (size_t c = 0; c < clouds.size(); ++c) {
    Result<Estimate> e = estimator_->EstimateCloud(clouds[c]);
    if (!e.ok()) {
      EXPECT_TRUE(e.error().code == ErrorCode::kInvalidArgument ||
                  e.error().code == ErrorCode::kFailedPrecondition)
          << "cloud " << c << ": " << e.error().ToString();
      continue;
    }
    EXPECT_TRUE(e->floor.ground_from_sensor.matrix().allFinite()) << "cloud " << c;
    for (const Candidate& cand : e->candidates) {
      EXPECT_TRUE(std::isfinite(cand.pose.x) && std::isfinite(cand.pose.y) &&
                  std::isfinite(cand.score))
          << "cloud " << c;
    }
  }
}

// Refused when the estimator is made (before: by every frame, with the same error).
TEST(HostileFloorTest, DegenerateFixedFloorIsInvalidArgument) {
  EstimatorOptions options = DefaultEstimatorOptions();
  options.use_fixed_floor = true;
  // Looking straight down: the optical axis has no horizontal direction to define +x.
  options.fixed_floor = FloorEstimate::FromPlane(Eigen::Vector4d(0.0, 0.0, -1.0, 0.5));
  Result<std::unique_ptr<Estimator>> estimator = Estimator::Create(options, {StandingTemplate()});
  ASSERT_FALSE(estimator.ok());
  EXPECT_EQ(estimator.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(estimator.error().message.find("floor"), std::string::npos)
      << estimator.error().message;
}

}  // namespace
}  // namespace hpose
