#include "core/stereo/stereo_estimator.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/stereo/local_marker_estimator.h"
#include "core/stereo/stereo_scene_simulator.h"
#include "core/stereo/stereo_tracker.h"

namespace hpose {
namespace {

StereoSimNoiseOptions QuietNoise() {
  StereoSimNoiseOptions n;
  n.pixel_noise_sigma = 1.0;
  n.supersample = 2;
  n.gain_min = n.gain_max = 1.0;
  return n;
}

class StereoEstimatorTest : public testing::Test {
 protected:
  StereoEstimatorTest() : sim_(StereoSimCameraOptions{}, QuietNoise()) {}

  std::unique_ptr<StereoEstimator> Make(const StereoMarkerOptions& options = {}) {
    auto e = StereoEstimator::Create(sim_.calibration(), options);
    EXPECT_TRUE(e.ok());
    return e.ok() ? std::move(e).value() : nullptr;
  }
  SimScene Scene(bool ball = true) const {
    SimScene s = MakeFieldScene(StereoMarkerOptions().landmarks_world_m, true, 3);
    if (ball) s.balls.push_back(SimBall{Eigen::Vector3d(0.3, -0.1, 0.035), 0.035, {225, 105, 25}});
    return s;
  }

  StereoSceneSimulator sim_;
};

TEST_F(StereoEstimatorTest, LocatesRobotLandmarksAndBall) {
  auto est = Make();
  for (const Pose2D& robot : {Pose2D{0.05, -1.0, DegToRad(92)}, Pose2D{-0.25, -0.8, DegToRad(75)},
                              Pose2D{0.35, -1.25, DegToRad(100)}}) {
    const auto pair = sim_.RenderPair(robot, HeadSway{0.01, 0.0, 0.03, 0.0, 0.02}, Scene(), 1);
    auto r = est->Process(pair.left, pair.right, 1.5);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_TRUE(r->ok()) << r->reason;
    EXPECT_EQ(r->timestamp_s, 1.5);
    EXPECT_NEAR(r->robot.x, pair.truth.head.x, 0.015);
    EXPECT_NEAR(r->robot.y, pair.truth.head.y, 0.015);
    EXPECT_NEAR(AngleDiff(r->robot.theta, pair.truth.head.theta), 0.0, DegToRad(1.0));
    EXPECT_NEAR(r->camera_height_m, pair.truth.head_position_m.z(), 0.015);
    const Eigen::Isometry3d left_from_world = pair.truth.world_from_left.inverse();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d truth = left_from_world * est->options().landmarks_world_m[k];
      EXPECT_LT((r->landmark_camera_m[k] - truth).norm(), 0.012) << "landmark " << k;
    }
    EXPECT_TRUE(r->closed_form_ok);
    EXPECT_LT(r->svd.orthonormality_error, 1e-9);
    ASSERT_TRUE(r->object_in_world) << r->object_reason;
    EXPECT_LT((r->object_world_m - pair.truth.object_world_m).head<2>().norm(), 0.01);
  }
}

TEST_F(StereoEstimatorTest, ReportsTheConfiguredRobotPoint) {
  StereoMarkerOptions options;
  options.head_to_reference_m = Eigen::Vector2d(-0.04, 0.01);  // head ahead of the torso.
  auto est = Make(options);
  const auto pair = sim_.RenderPair(Pose2D{0.0, -0.9, DegToRad(80)}, HeadSway{}, Scene(), 2);
  auto r = est->Process(pair.left, pair.right, 0.0);
  ASSERT_TRUE(r.ok() && r->ok());
  EXPECT_NEAR(r->head.x, pair.truth.head.x, 0.015);
  const double c = std::cos(r->head.theta), s = std::sin(r->head.theta);
  EXPECT_NEAR(r->robot.x, r->head.x + c * -0.04 - s * 0.01, 1e-9);
  EXPECT_NEAR(r->robot.y, r->head.y + s * -0.04 + c * 0.01, 1e-9);
  EXPECT_EQ(r->robot.theta, r->head.theta);
}

TEST_F(StereoEstimatorTest, ClosedFormMethodGivesTheSamePose) {
  StereoMarkerOptions options;
  options.method = RigidFitMethod::kClosedForm;
  auto est = Make(options);
  const auto pair = sim_.RenderPair(Pose2D{0.0, -0.9, kPi / 2}, HeadSway{}, Scene(), 2);
  auto r = est->Process(pair.left, pair.right, 0.0);
  ASSERT_TRUE(r.ok() && r->ok());
  EXPECT_EQ(r->method, RigidFitMethod::kClosedForm);
  EXPECT_NEAR(r->robot.x, pair.truth.head.x, 0.015);
  EXPECT_NEAR(r->robot.y, pair.truth.head.y, 0.015);
}

TEST_F(StereoEstimatorTest, RejectsMissingLandmark) {
  auto est = Make();
  SimScene missing = Scene();
  missing.discs.erase(missing.discs.begin() + 1);
  auto pair = sim_.RenderPair(Pose2D{0.05, -1.0, kPi / 2}, HeadSway{}, missing, 3);
  auto r = est->Process(pair.left, pair.right, 0.0);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->status, StereoFrameStatus::kMissingLandmark);
  EXPECT_NE(r->reason.find("2 landmark blob"), std::string::npos) << r->reason;
  // The ball is still seen in the camera frame, but it has no world position.
  EXPECT_TRUE(r->object_in_camera);
  EXPECT_FALSE(r->object_in_world);
}

TEST_F(StereoEstimatorTest, ExtraLandmarkColouredBlobsCostNothing) {
  auto est = Make();
  // A landmark's twin, a larger disc, a cloth of the landmark colour and speckles.
  SimScene extra = Scene();
  extra.discs.push_back(SimDisc{Eigen::Vector2d(-0.3, -0.1), 0.06, kSimLandmarkColor});
  extra.discs.push_back(SimDisc{Eigen::Vector2d(0.45, 0.7), 0.1, kSimLandmarkColor});
  extra.patches.push_back(
      SimPatch{Eigen::Vector2d(0.0, 0.25), Eigen::Vector2d(0.08, 0.03), 0.4, kSimLandmarkColor});
  StereoSimNoiseOptions noisy = QuietNoise();
  noisy.speckles_per_image = 4;
  noisy.speckle_colors = {kSimLandmarkColor};
  const StereoSceneSimulator sim(StereoSimCameraOptions{}, noisy);
  const auto pair = sim.RenderPair(Pose2D{0.05, -1.0, kPi / 2}, HeadSway{}, extra, 4);
  auto r = est->Process(pair.left, pair.right, 0.0);
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r->ok()) << r->reason;
  EXPECT_GE(r->landmark_blobs_left, 5);
  EXPECT_GE(r->landmark_candidates, 4);
  EXPECT_GT(r->landmark_runner_up_rms_m, 1.5 * r->landmark_best_rms_m);
  const Eigen::Isometry3d left_from_world = pair.truth.world_from_left.inverse();
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d truth = left_from_world * est->options().landmarks_world_m[k];
    EXPECT_LT((r->landmark_camera_m[k] - truth).norm(), 0.015) << "landmark " << k;
  }
  EXPECT_NEAR(r->robot.x, pair.truth.head.x, 0.015);
  EXPECT_NEAR(r->robot.y, pair.truth.head.y, 0.015);
}

TEST_F(StereoEstimatorTest, BallColouredDistractorsAreNotTheBall) {
  auto est = Make();
  // A bigger sphere and a cloth of the ball's colour, both larger than the ball in the image.
  SimScene scene = Scene();
  scene.balls.push_back(SimBall{Eigen::Vector3d(-0.35, 0.05, 0.08), 0.08, kSimBallColor});
  scene.patches.push_back(
      SimPatch{Eigen::Vector2d(0.4, 0.5), Eigen::Vector2d(0.12, 0.03), 0.2, kSimBallColor});
  const auto pair = sim_.RenderPair(Pose2D{0.05, -1.0, kPi / 2}, HeadSway{}, scene, 6);
  auto r = est->Process(pair.left, pair.right, 0.0);
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r->ok()) << r->reason;
  ASSERT_TRUE(r->object_in_world) << r->object_reason;
  EXPECT_LT((r->object_world_m - pair.truth.object_world_m).head<2>().norm(), 0.02);

  // Without the ball, neither distractor is reported as the ball.
  scene.balls.erase(scene.balls.begin());
  const auto no_ball = sim_.RenderPair(Pose2D{0.05, -1.0, kPi / 2}, HeadSway{}, scene, 7);
  r = est->Process(no_ball.left, no_ball.right, 0.0);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->object_in_world);
  EXPECT_FALSE(r->object_reason.empty());
}

TEST_F(StereoEstimatorTest, TwinBallsAreToldApartByTheTrack) {
  auto est = Make();
  SimScene scene = Scene();  // the ball at (0.3, -0.1).
  scene.balls.push_back(SimBall{Eigen::Vector3d(-0.3, 0.05, 0.035), 0.035, kSimBallColor});
  const auto pair = sim_.RenderPair(Pose2D{0.05, -1.0, kPi / 2}, HeadSway{}, scene, 10);
  for (const Eigen::Vector3d& was :
       {Eigen::Vector3d(0.28, -0.12, 0.035), Eigen::Vector3d(-0.31, 0.08, 0.035)}) {
    StereoObjectPrior prior;
    prior.world_m = was;
    prior.timestamp_s = 0.9;
    auto r = est->Process(pair.left, pair.right, 1.0, &prior);
    ASSERT_TRUE(r.ok());
    ASSERT_TRUE(r->ok()) << r->reason;
    ASSERT_TRUE(r->object_in_world) << r->object_reason;
    EXPECT_LT((r->object_world_m - was).head<2>().norm(), 0.04);
  }
  // The tracker hands out the last located position.
  StereoTracker tracker;
  StereoObjectPrior prior;
  EXPECT_FALSE(tracker.ObjectPrior(&prior));
  auto first = est->Process(pair.left, pair.right, 2.0);
  ASSERT_TRUE(first.ok() && first->object_in_world);
  tracker.Update(*first);
  ASSERT_TRUE(tracker.ObjectPrior(&prior));
  EXPECT_EQ(prior.timestamp_s, 2.0);
  EXPECT_EQ(prior.world_m, first->object_world_m);
}

TEST_F(StereoEstimatorTest, PartlyHiddenLandmarkIsDownWeightedOrRejected) {
  auto est = Make();
  SimScene scene = Scene();
  const double r = scene.discs[1].radius_m;
  // A grey sheet over a third of P1 (its edge 0.2 r from the centre hides about 37 %).
  const Eigen::Vector2d p1 = scene.discs[1].centre_m;
  scene.patches.push_back(SimPatch{p1 + Eigen::Vector2d(0.2 * r + 0.08, 0.0),
                                   Eigen::Vector2d(0.08, 0.12),
                                   0.0,
                                   {200, 200, 195}});
  auto pair = sim_.RenderPair(Pose2D{0.05, -1.0, kPi / 2}, HeadSway{}, scene, 8);
  auto res = est->Process(pair.left, pair.right, 0.0);
  ASSERT_TRUE(res.ok());
  ASSERT_TRUE(res->ok()) << res->reason;
  EXPECT_TRUE(res->landmark_downweighted[1]) << res->landmark_notes;
  EXPECT_FALSE(res->landmark_downweighted[0]);
  EXPECT_FALSE(res->landmark_downweighted[2]);
  EXPECT_NEAR(res->landmark_visible_fraction[1], 1.0 - DiscCapFraction(0.2 * r, r), 0.15);
  EXPECT_NE(res->landmark_notes.find("P1"), std::string::npos);
  // Most of it hidden: the frame is rejected and says which landmark.
  scene.patches.back().centre_m = p1 + Eigen::Vector2d(-0.6 * r + 0.08, 0.0);
  pair = sim_.RenderPair(Pose2D{0.05, -1.0, kPi / 2}, HeadSway{}, scene, 9);
  res = est->Process(pair.left, pair.right, 0.0);
  ASSERT_TRUE(res.ok());
  EXPECT_FALSE(res->ok());
  EXPECT_FALSE(res->reason.empty());
}

// A landmark-coloured cloth lying against P1 merges with it into one blob about three times the
// disc's area: that blob is not P1 (its centroid is not P1's centre), so it is set aside and,
// with no other P1 in view, the frame is rejected with both reasons rather than posed off.
TEST_F(StereoEstimatorTest, BlobTooLargeForItsLandmarkIsSetAside) {
  SimScene scene = Scene();
  const Pose2D robot{0.05, -1.0, kPi / 2};
  auto est = Make();
  auto pair = sim_.RenderPair(robot, HeadSway{}, scene, 8);
  auto res = est->Process(pair.left, pair.right, 0.0);
  ASSERT_TRUE(res.ok());
  ASSERT_TRUE(res->ok()) << res->reason;
  EXPECT_TRUE(res->landmark_blobs_excluded.empty()) << res->landmark_blobs_excluded;

  // The cloth reaches from under the disc 0.2 m away from the robot: the merged blob is about
  // three discs' area, a little higher in the image but no wider.
  scene.patches.push_back(SimPatch{scene.discs[1].centre_m + Eigen::Vector2d(0.0, 0.14),
                                   Eigen::Vector2d(0.05, 0.12), 0.0, kSimLandmarkColor});
  pair = sim_.RenderPair(robot, HeadSway{}, scene, 8);
  res = est->Process(pair.left, pair.right, 0.0);
  ASSERT_TRUE(res.ok());
  EXPECT_FALSE(res->ok());
  EXPECT_NE(res->landmark_blobs_excluded.find("times the area of landmark P"), std::string::npos)
      << res->reason << " / " << res->landmark_notes;
  EXPECT_NE(res->reason.find("after excluding blobs too large for a landmark"), std::string::npos)
      << res->reason;
  // Allowing such blobs brings the old behaviour back: a pose, off by the merged centroid.
  StereoMarkerOptions lenient;
  lenient.max_landmark_area_ratio = 10;
  res = Make(lenient)->Process(pair.left, pair.right, 0.0);
  ASSERT_TRUE(res.ok());
  EXPECT_TRUE(res->landmark_blobs_excluded.empty());
}

TEST(StereoMarkerOptionsTest, LandmarkAreaRatioFromTheOptionsFile) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("hpose_area_ratio_" + std::to_string(::getpid()) + ".yaml"))
                               .string();
  std::ofstream(path) << "%YAML:1.0\nmax_landmark_area_ratio: 2.5\n";
  Result<StereoMarkerOptions> loaded = LoadStereoMarkerOptions(path);
  ASSERT_TRUE(loaded.ok()) << loaded.error().ToString();
  EXPECT_DOUBLE_EQ(loaded->max_landmark_area_ratio, 2.5);
  std::ofstream(path)
      << "%YAML:1.0\nmax_landmark_area_ratio: 0.5\n";  // smaller than the disc itself.
  loaded = LoadStereoMarkerOptions(path);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.error().message.find("max_landmark_area_ratio"), std::string::npos)
      << loaded.error().message;
  std::filesystem::remove(path);
}

// Every kind of key, in YAML and in XML as OpenCV writes them, and a clear error for each
// kind of wrong value.
TEST(StereoMarkerOptionsTest, EveryKeyKindReadsFromYamlAndXml) {
  const std::string base = (std::filesystem::temp_directory_path() /
                            ("hpose_marker_options_" + std::to_string(::getpid())))
                               .string();
  const std::string yaml = base + ".yaml", xml = base + ".xml";
  std::ofstream(yaml) << "%YAML:1.0\n---\n"
                         "landmarks_world_m: !!opencv-matrix\n   rows: 3\n   cols: 3\n"
                         "   dt: d\n   data: [ 0., 0., 0., 0.5, 0.9, 0., -0.5, 0.9, 0. ]\n"
                         "landmark_color: [ 340, 20, 0.5, 1, 0.3, 1 ]\n"
                         "method: closed_form\n"
                         "depth_weighted_fit: 0\n"
                         "robot_region_m: [ -2, 2, -3, 0.1 ]\n"
                         "head_to_reference_m: [ 0.01, -0.02 ]\n"
                         "min_blob_area_px: 12\n"
                         "fit_rms_sigmas: 1.5\n"
                         "max_ball_aspect: 1.6\n";
  std::ofstream(xml) << "<?xml version=\"1.0\"?>\n<opencv_storage>\n"
                        "<landmarks_world_m type_id=\"opencv-matrix\">\n  <rows>3</rows>\n"
                        "  <cols>3</cols>\n  <dt>d</dt>\n  <data>\n"
                        "    0. 0. 0. 0.5 0.9 0. -0.5 0.9 0.</data></landmarks_world_m>\n"
                        "<landmark_color>\n  340 20 0.5 1 0.3 1</landmark_color>\n"
                        "<method>closed_form</method>\n<depth_weighted_fit>0</depth_weighted_fit>\n"
                        "<robot_region_m>\n  -2 2 -3 0.1</robot_region_m>\n"
                        "<head_to_reference_m>\n  0.01 -0.02</head_to_reference_m>\n"
                        "<min_blob_area_px>12</min_blob_area_px>\n"
                        "<fit_rms_sigmas>1.5</fit_rms_sigmas>\n"
                        "<max_ball_aspect>1.6</max_ball_aspect>\n</opencv_storage>\n";
  for (const std::string& path : {yaml, xml}) {
    Result<StereoMarkerOptions> o = LoadStereoMarkerOptions(path);
    ASSERT_TRUE(o.ok()) << o.error().ToString();
    EXPECT_EQ(o->landmarks_world_m[1], Eigen::Vector3d(0.5, 0.9, 0.0)) << path;
    EXPECT_EQ(o->landmarks_world_m[2], Eigen::Vector3d(-0.5, 0.9, 0.0)) << path;
    EXPECT_EQ(o->landmark_color.hue_min_deg, 340);
    EXPECT_EQ(o->landmark_color.val_min, 0.3);
    EXPECT_EQ(o->method, RigidFitMethod::kClosedForm);
    EXPECT_FALSE(o->depth_weighted_fit);
    EXPECT_EQ(o->robot_region_y_max_m, 0.1);
    EXPECT_EQ(o->head_to_reference_m.y(), -0.02);
    EXPECT_EQ(o->segmentation.min_blob_area_px, 12);
    EXPECT_EQ(o->fit_rms_sigmas, 1.5);
    EXPECT_EQ(o->max_ball_aspect, 1.6);
  }
  const std::pair<const char*, const char*> bad[] = {
      {"landmark_color: [ 1, 2, 3 ]\n", "landmark_color: must be a list of 6 numbers"},
      {"method: 3\n", "method:"},
      {"depth_weighted_fit: 2\n", "depth_weighted_fit: must be 0 or 1"},
      {"min_blob_area_px: 99999999999\n", "min_blob_area_px: must be an integer"},
      {"landmarks_world_m: [ 1, 2, 3 ]\n", "landmarks_world_m: must be a 3x3 matrix"},
      {"max_ball_aspect: .nan\n", "max_ball_aspect: must be a finite number"},
      {"max_ball_aspect: \"2\"\n", "max_ball_aspect: must be a finite number"},
      {"no_such_key: 1\n", "no_such_key: unknown key"},
  };
  for (const auto& [text, says] : bad) {
    std::ofstream(yaml) << "%YAML:1.0\n" << text;
    Result<StereoMarkerOptions> o = LoadStereoMarkerOptions(yaml);
    ASSERT_FALSE(o.ok()) << text;
    EXPECT_EQ(o.error().code, ErrorCode::kInvalidArgument) << text;
    EXPECT_NE(o.error().message.find(says), std::string::npos) << o.error().message;
  }
  std::ofstream(yaml) << "%YAML:1.0\n- 1\n";
  Result<StereoMarkerOptions> seq = LoadStereoMarkerOptions(yaml);
  ASSERT_FALSE(seq.ok());
  EXPECT_EQ(seq.error().code, ErrorCode::kDataLoss);
  std::filesystem::remove(yaml);
  std::filesystem::remove(xml);
}

TEST_F(StereoEstimatorTest, RejectsCollinearLandmarks) {
  // Discs laid out on a line, while the estimator expects the triangle.
  SimScene line = Scene(false);
  line.discs[0].centre_m = Eigen::Vector2d(-0.3, 0.2);
  line.discs[1].centre_m = Eigen::Vector2d(0.0, 0.2);
  line.discs[2].centre_m = Eigen::Vector2d(0.3, 0.2);
  auto est = Make();
  auto pair = sim_.RenderPair(Pose2D{0.0, -0.9, kPi / 2}, HeadSway{}, line, 5);
  auto r = est->Process(pair.left, pair.right, 0.0);
  ASSERT_TRUE(r.ok());
  // No three blobs are spaced like the landmark triangle.
  EXPECT_EQ(r->status, StereoFrameStatus::kNoConsistentMatch) << r->reason;
  EXPECT_NE(r->reason.find("layout"), std::string::npos) << r->reason;
  // Collinear landmark positions in the options are refused up front.
  StereoMarkerOptions bad;
  bad.landmarks_world_m[2] = Eigen::Vector3d(-0.5, 0.8, 0.0);
  auto e = StereoEstimator::Create(sim_.calibration(), bad);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("collinear"), std::string::npos);
}

TEST_F(StereoEstimatorTest, RejectsAmbiguousArrangement) {
  // An equilateral triangle with no region prior: three labellings fit equally well.
  StereoMarkerOptions options;
  const double s = 0.5;
  options.landmarks_world_m = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(-s / 2, s * 0.866025, 0),
                               Eigen::Vector3d(s / 2, s * 0.866025, 0)};
  options.robot_region_y_max_m = 1e9;
  SimScene scene = MakeFieldScene(options.landmarks_world_m, false, 1);
  auto est = Make(options);
  auto pair = sim_.RenderPair(Pose2D{0.0, -0.9, kPi / 2}, HeadSway{}, scene, 6);
  auto r = est->Process(pair.left, pair.right, 0.0);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->status, StereoFrameStatus::kAmbiguousMatch) << r->reason;
  // With the paper's region prior (robot on P0's side) the same frame is accepted.
  options.robot_region_y_max_m = 0.0;
  auto est2 = Make(options);
  r = est2->Process(pair.left, pair.right, 0.0);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->ok()) << r->reason;
  EXPECT_NEAR(r->robot.y, pair.truth.head.y, 0.02);
}

TEST_F(StereoEstimatorTest, BadInputGivesClearErrors) {
  auto est = Make();
  const auto pair = sim_.RenderPair(Pose2D{0.0, -0.9, kPi / 2}, HeadSway{}, Scene(), 7);
  RgbImage small(100, 50);
  auto r = est->Process(pair.left, small, 0.0);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(r.error().message.find("100x50"), std::string::npos);
  r = est->Process(small, small, 0.0);  // same sizes, but not the calibration's.
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("calibration"), std::string::npos);
  RgbImage broken = pair.left;
  broken.pixels.resize(10);
  EXPECT_FALSE(est->Process(broken, pair.right, 0.0).ok());
  EXPECT_FALSE(est->Process(RgbImage(), pair.right, 0.0).ok());
  EXPECT_FALSE(est->Process(pair.left, pair.right, std::nan("")).ok());

  StereoCalibration bad_cal = sim_.calibration();
  bad_cal.right_t_left *= 1000.0;  // millimetres read as metres.
  EXPECT_FALSE(StereoEstimator::Create(bad_cal).ok());
  StereoMarkerOptions bad_options;
  bad_options.ambiguity_ratio = 0.5;
  EXPECT_FALSE(StereoEstimator::Create(sim_.calibration(), bad_options).ok());
}

TEST(LocalMarkerEstimatorTest, ObjectRelativeToMarkerMidpoint) {
  const StereoSceneSimulator sim(StereoSimCameraOptions{}, QuietNoise());
  LocalMarkerOptions options;
  options.marker_spacing_m = 0.12;
  options.object_height_above_markers_m = 0.035;
  auto est = LocalMarkerEstimator::Create(sim.calibration().left, options);
  ASSERT_TRUE(est.ok());
  Eigen::Isometry3d down = Eigen::Isometry3d::Identity();
  down.linear().col(0) = Eigen::Vector3d(0, -1, 0);  // image right = robot right.
  down.linear().col(1) = Eigen::Vector3d(-1, 0, 0);  // image down = robot back.
  down.linear().col(2) = Eigen::Vector3d(0, 0, -1);  // looking down.
  down.translation() = Eigen::Vector3d(0.08, 0.01, 0.45);
  for (const Eigen::Vector2d& ball : {Eigen::Vector2d(0.15, 0.05), Eigen::Vector2d(0.1, -0.12)}) {
    SimScene scene;
    scene.discs.push_back(SimDisc{Eigen::Vector2d(0, -0.06), 0.015, {190, 50, 150}});
    scene.discs.push_back(SimDisc{Eigen::Vector2d(0, 0.06), 0.015, {190, 50, 150}});
    scene.balls.push_back(
        SimBall{Eigen::Vector3d(ball.x(), ball.y(), 0.035), 0.035, {225, 105, 25}});
    auto r = (*est)->Process(sim.Render(StereoSide::kLeft, down, scene, 1.0, 9));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_NEAR(r->object_in_robot_m.x(), ball.x(), 0.005);
    EXPECT_NEAR(r->object_in_robot_m.y(), ball.y(), 0.005);
    EXPECT_NEAR(r->marker_depth_m, 0.45, 0.01);
    EXPECT_GT(r->marker_px[0].x(), r->marker_px[1].x());  // [0] is the right marker.
    // One marker hidden: refused with the reason.
    scene.discs.pop_back();
    auto missing = (*est)->Process(sim.Render(StereoSide::kLeft, down, scene, 1.0, 9));
    ASSERT_FALSE(missing.ok());
    EXPECT_EQ(missing.error().code, ErrorCode::kFailedPrecondition);
    EXPECT_NE(missing.error().message.find("1 marker blob"), std::string::npos);
  }
}

}  // namespace
}  // namespace hpose
