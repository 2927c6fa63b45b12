#include "core/depth/floor_tracker.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/depth/floor_fitter.h"
#include "tests/depth/synthetic_scene.h"

namespace hpose {
namespace {

using testing_scene::Cylinder;
using testing_scene::GroundFromSensor;
using testing_scene::Render;
using testing_scene::RenderOptions;
using testing_scene::Scene;

constexpr double kDeg = M_PI / 180.0;
constexpr double kKinectNoise = 1.425e-3;  // sigma_z = k z^2 (SPEC §5).

// A noisy organised 320x240 frame of a floor with a person and a robot-sized cylinder seen from
// a sensor at `height_m`, pitched and rolled (degrees); `seed` changes the noise.
PointCloud Frame(double height_m, double pitch_deg, double roll_deg, unsigned seed,
                 double person_x = 2.0, bool organised = true) {
  Scene scene;
  scene.cylinders.push_back(Cylinder{person_x, 0.4, 0.2, 1.7});
  scene.cylinders.push_back(Cylinder{1.2, -0.3, 0.12, 0.58});
  RenderOptions render;
  render.noise_sigma_k = kKinectNoise;
  render.organised = organised;
  render.seed = seed;
  return Render(scene, GroundFromSensor(height_m, pitch_deg * kDeg, roll_deg * kDeg),
                Intrinsics::KinectV1(320, 240), render);
}

double TiltBetweenDeg(const FloorEstimate& a, const FloorEstimate& b) {
  const double c = std::clamp(a.plane_sensor.head<3>().dot(b.plane_sensor.head<3>()), -1.0, 1.0);
  return std::acos(c) / kDeg;
}

TEST(FloorTrackerTest, FirstFrameIsTheFullFit) {
  const PointCloud cloud = Frame(0.6, 15.0, 3.0, 1);
  FloorTracker tracker;
  const Result<FloorEstimate> tracked = tracker.Update(cloud);
  ASSERT_TRUE(tracked.ok()) << tracked.error().ToString();
  EXPECT_TRUE(tracker.refitted());
  EXPECT_EQ(tracker.refit_reason(), "first frame");
  const Result<FloorEstimate> fitted = FitFloor(cloud);
  ASSERT_TRUE(fitted.ok());
  EXPECT_EQ(tracked->plane_sensor, fitted->plane_sensor);
  EXPECT_EQ(tracked->inliers, fitted->inliers);
  EXPECT_NEAR(tracked->height_m, 0.6, 0.02);
}

TEST(FloorTrackerTest, KeepsTheFloorOfAFixedSensorAndStaysAsGoodAsAFreshFit) {
  FloorTracker tracker;
  ASSERT_TRUE(tracker.Update(Frame(0.6, 15.0, 3.0, 1)).ok());
  const FloorEstimate first = *tracker.floor();
  // New noise and a person walking: the sensor has not moved.
  for (unsigned seed = 2; seed < 8; ++seed) {
    const PointCloud cloud = Frame(0.6, 15.0, 3.0, seed, 1.5 + 0.3 * seed);
    const Result<FloorEstimate> tracked = tracker.Update(cloud);
    ASSERT_TRUE(tracked.ok()) << tracked.error().ToString();
    EXPECT_FALSE(tracker.refitted()) << "frame " << seed << ": " << tracker.refit_reason();
    EXPECT_TRUE(tracker.refit_reason().empty());
    EXPECT_EQ(tracked->plane_sensor, first.plane_sensor);
    EXPECT_EQ(tracker.frames_since_fit(), static_cast<int>(seed) - 1);
    // The reference path on the same frame: within the fit's own tolerance of the kept floor.
    const Result<FloorEstimate> fitted = FitFloor(cloud);
    ASSERT_TRUE(fitted.ok());
    EXPECT_LT(TiltBetweenDeg(*tracked, *fitted), 1.0);
    EXPECT_NEAR(tracked->height_m, fitted->height_m, 0.02);
  }
}

TEST(FloorTrackerTest, UnorganisedCloudsAreCheckedToo) {
  FloorTracker tracker;
  ASSERT_TRUE(tracker.Update(Frame(1.0, 30.0, 0.0, 1, 2.0, /*organised=*/false)).ok());
  ASSERT_TRUE(tracker.Update(Frame(1.0, 30.0, 0.0, 2, 2.5, /*organised=*/false)).ok());
  EXPECT_FALSE(tracker.refitted()) << tracker.refit_reason();
  const Result<FloorEstimate> moved = tracker.Update(Frame(1.1, 30.0, 0.0, 3, 2.5, false));
  ASSERT_TRUE(moved.ok());
  EXPECT_TRUE(tracker.refitted());
  EXPECT_NEAR(moved->height_m, 1.1, 0.02);
}

struct Move {
  const char* what;
  double height_m, pitch_deg, roll_deg;
};

class FloorTrackerMoveTest : public ::testing::TestWithParam<Move> {};

TEST_P(FloorTrackerMoveTest, RefitsWhenTheSensorMoves) {
  const Move m = GetParam();
  FloorTracker tracker;
  ASSERT_TRUE(tracker.Update(Frame(0.6, 15.0, 3.0, 1)).ok());
  ASSERT_TRUE(tracker.Update(Frame(0.6, 15.0, 3.0, 2)).ok());
  ASSERT_FALSE(tracker.refitted());
  const PointCloud moved = Frame(m.height_m, m.pitch_deg, m.roll_deg, 3);
  const Result<FloorEstimate> tracked = tracker.Update(moved);
  ASSERT_TRUE(tracked.ok()) << tracked.error().ToString();
  EXPECT_TRUE(tracker.refitted()) << m.what;
  EXPECT_FALSE(tracker.refit_reason().empty());
  EXPECT_EQ(tracker.frames_since_fit(), 0);
  // The refit is the full fit of the new frame.
  const Result<FloorEstimate> fitted = FitFloor(moved);
  ASSERT_TRUE(fitted.ok());
  EXPECT_EQ(tracked->plane_sensor, fitted->plane_sensor);
  EXPECT_NEAR(tracked->height_m, m.height_m, 0.02);
  EXPECT_NEAR(tracked->pitch_rad / kDeg, m.pitch_deg, 1.0);
  // And the new floor is kept from then on.
  ASSERT_TRUE(tracker.Update(Frame(m.height_m, m.pitch_deg, m.roll_deg, 4)).ok());
  EXPECT_FALSE(tracker.refitted()) << tracker.refit_reason();
}

INSTANTIATE_TEST_SUITE_P(Moves, FloorTrackerMoveTest,
                         ::testing::Values(Move{"lifted 3 cm", 0.63, 15.0, 3.0},
                                           Move{"lowered 10 cm", 0.5, 15.0, 3.0},
                                           Move{"pitched 2 degrees more", 0.6, 17.0, 3.0},
                                           Move{"rolled 3 degrees", 0.6, 15.0, 0.0},
                                           Move{"pitched 20 degrees more", 0.6, 35.0, 3.0}));

TEST(FloorTrackerTest, ForcedRefitAfterMaxReuseFrames) {
  FloorTrackerOptions options;
  options.max_reuse_frames = 2;
  FloorTracker tracker(options);
  const bool expected_refit[] = {true, false, false, true, false, false, true};
  for (unsigned i = 0; i < 7; ++i) {
    ASSERT_TRUE(tracker.Update(Frame(0.6, 15.0, 3.0, i + 1)).ok());
    EXPECT_EQ(tracker.refitted(), expected_refit[i]) << "frame " << i;
  }
}

TEST(FloorTrackerTest, ResetForcesAFit) {
  FloorTracker tracker;
  ASSERT_TRUE(tracker.Update(Frame(0.6, 15.0, 3.0, 1)).ok());
  tracker.Reset();
  EXPECT_FALSE(tracker.floor().has_value());
  ASSERT_TRUE(tracker.Update(Frame(0.6, 15.0, 3.0, 2)).ok());
  EXPECT_TRUE(tracker.refitted());
  EXPECT_EQ(tracker.refit_reason(), "first frame");
}

TEST(FloorTrackerTest, FailuresAreReportedAndTheNextFrameIsFittedAgain) {
  FloorTracker tracker;
  EXPECT_EQ(tracker.Update(PointCloud{}).error().code, ErrorCode::kInvalidArgument);
  ASSERT_TRUE(tracker.Update(Frame(0.6, 15.0, 3.0, 1)).ok());
  // A view without a floor (only a wall right in front) fails like FitFloor does ...
  Scene wall;
  wall.floor = false;
  wall.boxes.push_back({Eigen::Vector3d(1.0, -3.0, 0.0), Eigen::Vector3d(1.1, 3.0, 3.0)});
  const PointCloud no_floor =
      Render(wall, GroundFromSensor(0.6, 15.0 * kDeg, 3.0 * kDeg), Intrinsics::KinectV1(320, 240));
  const Result<FloorEstimate> failed = tracker.Update(no_floor);
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_FALSE(tracker.floor().has_value());
  // ... and the next good frame is a full fit.
  ASSERT_TRUE(tracker.Update(Frame(0.6, 15.0, 3.0, 2)).ok());
  EXPECT_TRUE(tracker.refitted());
}

TEST(FloorTrackerTest, InvalidOptionsAreRejected) {
  FloorTrackerOptions options;
  options.check_points = 0;
  FloorTracker tracker(options);
  const Result<FloorEstimate> r = tracker.Update(Frame(0.6, 15.0, 3.0, 1));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(r.error().message.find("check_points"), std::string::npos);
}

}  // namespace
}  // namespace hpose
