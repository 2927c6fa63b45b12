// Unit tests of the daemon's stereo and world-frame parts without a server: config keys, the
// world-frame conversion of depth estimates, the stereo result conversion and the stereo
// pipeline on a small simulated sequence.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <thread>

#include "core/common/pose2d.h"
#include "core/stereo/stereo_calibration.h"
#include "core/stereo/stereo_estimator.h"
#include "core/stereo/stereo_sequence.h"
#include "core/stereo/stereo_sim_sequence.h"
#include "server/daemon_config.h"
#include "server/proto_convert.h"
#include "server/publish_signal.h"
#include "server/stereo_pipeline.h"
#include "server/stereo_proto_convert.h"
#include "server/world_frame.h"

namespace hpose::server {
namespace {

using namespace std::chrono_literals;

TEST(StereoConfigTest, ParsesStereoAndWorldKeysAndResolvesPaths) {
  const char* yaml = R"(
stereo: {source: runs/stereo, calibration: cal/stereo.yaml, calibration_unit: mm,
         options: opts.yaml, rate: fast, loop: true, fps: 12, stale_after_s: 0.5}
world_from_ground: {x_m: 0.5, y_m: -2, yaw_rad: 1.5}
)";
  Result<DaemonConfig> c = ParseDaemonConfig(yaml, "test.yaml", "/etc/hpose");
  ASSERT_TRUE(c.ok()) << c.error().ToString();
  EXPECT_EQ(c->stereo.source, "/etc/hpose/runs/stereo");
  EXPECT_EQ(c->stereo.calibration, "/etc/hpose/cal/stereo.yaml");
  EXPECT_EQ(c->stereo.options, "/etc/hpose/opts.yaml");
  EXPECT_EQ(c->stereo.calibration_unit, "mm");
  EXPECT_FALSE(c->stereo.realtime);
  EXPECT_TRUE(c->stereo.loop);
  EXPECT_DOUBLE_EQ(c->stereo.fps, 12.0);
  EXPECT_DOUBLE_EQ(c->stereo.stale_after_s, 0.5);
  EXPECT_TRUE(c->stereo.enabled());
  EXPECT_TRUE(c->world_from_ground.configured);
  EXPECT_DOUBLE_EQ(c->world_from_ground.x_m, 0.5);
  EXPECT_DOUBLE_EQ(c->world_from_ground.y_m, -2.0);
  EXPECT_DOUBLE_EQ(c->world_from_ground.yaw_rad, 1.5);
  c->templates = {"/t/standing.bt"};
  EXPECT_TRUE(ValidateDaemonConfig(*c).ok());

  // The YAML form reads back the same, world frame included.
  Result<DaemonConfig> back = ParseDaemonConfig(DaemonConfigToYaml(*c), "back", "");
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(back->stereo.source, c->stereo.source);
  EXPECT_TRUE(back->world_from_ground.configured);
  EXPECT_DOUBLE_EQ(back->world_from_ground.yaw_rad, 1.5);
  EXPECT_EQ(DaemonConfigToYaml(*back), DaemonConfigToYaml(*c));
}

TEST(StereoConfigTest, AbsentKeysMeanNoStereoAndNoWorldFrame) {
  Result<DaemonConfig> c = ParseDaemonConfig("listen: 127.0.0.1:1", "x", "");
  ASSERT_TRUE(c.ok());
  EXPECT_FALSE(c->stereo.enabled());
  EXPECT_FALSE(c->world_from_ground.configured);
  EXPECT_EQ(DaemonConfigToYaml(*c).find("world_from_ground"), std::string::npos);
}

TEST(StereoConfigTest, ErrorsNameTheKey) {
  struct Case {
    const char* yaml;
    const char* expected;
  } cases[] = {
      {"stereo: {rate: slow}", "stereo.rate"},
      {"stereo: {sorce: x}", "stereo.sorce: unknown key"},
      {"stereo: {fps: fast}", "stereo.fps"},
      {"world_from_ground: {x_m: 1, z_m: 2}", "world_from_ground.z_m: unknown key"},
      {"world_from_ground: {yaw_rad: north}", "world_from_ground.yaw_rad"},
      {"world_from_ground: [1, 2, 3]", "world_from_ground: expected a mapping"},
  };
  for (const Case& c : cases) {
    Result<DaemonConfig> r = ParseDaemonConfig(c.yaml, "cfg.yaml", "");
    ASSERT_FALSE(r.ok()) << c.yaml;
    EXPECT_NE(r.error().message.find(c.expected), std::string::npos)
        << c.yaml << " -> " << r.error().message;
  }
  DaemonConfig config;
  config.templates = {"/t/standing.bt"};
  config.stereo.calibration_unit = "cm";
  Status s = ValidateDaemonConfig(config);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("stereo.calibration_unit"), std::string::npos);
  config.stereo.calibration_unit = "m";
  config.stereo.fps = 0.0;
  s = ValidateDaemonConfig(config);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("stereo.fps"), std::string::npos);
  // A placement no field has: finite but 1e300 m away, or turned 1e300 rad.
  config.stereo.fps = 15.0;
  config.world_from_ground.configured = true;
  config.world_from_ground.x_m = 1e300;
  s = ValidateDaemonConfig(config);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("world_from_ground"), std::string::npos);
  config.world_from_ground.x_m = 3.0;
  EXPECT_TRUE(ValidateDaemonConfig(config).ok());
  config.world_from_ground.yaw_rad = 1e300;
  EXPECT_FALSE(ValidateDaemonConfig(config).ok());
}

TEST(WorldFrameTest, GroundPosesMoveByWorldFromGround) {
  const Pose2D world_from_ground{0.5, -2.0, kPi / 2};
  // The ground origin and axes land where world_from_ground says.
  Pose2D p = GroundPoseToWorld(world_from_ground, Pose2D{0.0, 0.0, 0.0});
  EXPECT_NEAR(p.x, 0.5, 1e-12);
  EXPECT_NEAR(p.y, -2.0, 1e-12);
  EXPECT_NEAR(p.theta, kPi / 2, 1e-12);
  // 1 m along ground +x is 1 m along world +y; 1 m along ground +y is 1 m along world -x.
  p = GroundPoseToWorld(world_from_ground, Pose2D{1.0, 0.0, 0.0});
  EXPECT_NEAR(p.x, 0.5, 1e-12);
  EXPECT_NEAR(p.y, -1.0, 1e-12);
  p = GroundPoseToWorld(world_from_ground, Pose2D{0.0, 1.0, 0.0});
  EXPECT_NEAR(p.x, -0.5, 1e-12);
  EXPECT_NEAR(p.y, -2.0, 1e-12);
  // Headings add and wrap into (-pi, pi].
  p = GroundPoseToWorld(world_from_ground, Pose2D{0.0, 0.0, 3.0});
  EXPECT_NEAR(p.theta, 3.0 + kPi / 2 - 2 * kPi, 1e-12);
  // yaw given outside (-pi, pi] is wrapped.
  const Pose2D w = WorldFromGround(WorldFrameConfig{true, 1.0, 2.0, 2 * kPi + 0.25});
  EXPECT_NEAR(w.theta, 0.25, 1e-12);
}

Estimate OneHumanoidEstimate() {
  Estimate e;
  Candidate c;
  c.template_name = "standing";
  c.pose = Pose2D{1.0, 0.2, 0.1};
  c.score = 70.0;
  c.has_runner_up = true;
  c.runner_up_pose = Pose2D{1.0, 0.2, 0.1 + kPi};
  c.runner_up_score = 60.0;
  e.candidates.push_back(c);
  Detection d;
  d.best = c;
  d.is_humanoid = true;
  e.detections.push_back(d);
  return e;
}

TEST(WorldFrameTest, DepthEstimatesGetWorldPosesForEveryCandidate) {
  const Estimate estimate = OneHumanoidEstimate();
  v1::PoseEstimate msg;
  FillPoseEstimate(1, 0.0, std::chrono::system_clock::now(), "test", &estimate, nullptr, &msg);
  EXPECT_FALSE(msg.has_robot_pose_world());
  const Pose2D world_from_ground{-1.0, 0.5, -kPi / 2};
  AddDepthWorldFrame(world_from_ground, &msg);
  const Pose2D expected = GroundPoseToWorld(world_from_ground, Pose2D{1.0, 0.2, 0.1});
  ASSERT_TRUE(msg.has_robot_pose_world());
  EXPECT_NEAR(msg.robot_pose_world().x(), expected.x, 1e-12);
  EXPECT_NEAR(msg.robot_pose_world().y(), expected.y, 1e-12);
  EXPECT_NEAR(msg.robot_pose_world().theta(), expected.theta, 1e-12);
  EXPECT_NEAR(expected.x, -1.0 + 0.2, 1e-12);  // ground +y = world +x here.
  const v1::DepthTemplateResult& r = msg.depth_template();
  EXPECT_DOUBLE_EQ(r.world_from_ground().theta(), -kPi / 2);
  EXPECT_NEAR(r.candidates(0).pose_world().x(), expected.x, 1e-12);
  EXPECT_NEAR(r.detections(0).best().pose_world().y(), expected.y, 1e-12);
  EXPECT_NEAR(r.best().best().runner_up_pose_world().theta(), NormalizeAngle(0.1 + kPi - kPi / 2),
              1e-12);

  // Not a humanoid: world poses for the candidates, none for the estimate.
  Estimate weak = OneHumanoidEstimate();
  weak.detections[0].is_humanoid = false;
  v1::PoseEstimate weak_msg;
  FillPoseEstimate(2, 0.0, std::chrono::system_clock::now(), "test", &weak, nullptr, &weak_msg);
  AddDepthWorldFrame(world_from_ground, &weak_msg);
  EXPECT_FALSE(weak_msg.has_robot_pose_world());
  EXPECT_TRUE(weak_msg.depth_template().best().best().has_pose_world());

  // Stereo estimates are already in the world frame: left alone.
  v1::PoseEstimate stereo;
  stereo.set_estimator(v1::ESTIMATOR_KIND_STEREO_MARKER);
  stereo.mutable_stereo_marker()->set_status("ok");
  AddDepthWorldFrame(world_from_ground, &stereo);
  EXPECT_FALSE(stereo.has_robot_pose_world());
  EXPECT_FALSE(stereo.has_depth_template());
}

TEST(StereoProtoConvertTest, FrameAndTrackFillTheResult) {
  StereoFrameResult f;
  f.status = StereoFrameStatus::kOk;
  f.robot = Pose2D{0.1, -0.9, 1.4};
  f.camera_height_m = 0.45;
  f.method = RigidFitMethod::kSvd;
  f.svd.rotation = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  f.svd.translation = Eigen::Vector3d(0.1, -0.9, 0.45);
  f.svd.rms_residual_m = 0.004;
  f.landmark_blobs_left = f.landmark_blobs_right = 3;
  f.object_in_camera = f.object_in_world = true;
  f.object_world_m = Eigen::Vector3d(0.3, 0.1, 0.035);
  StereoTrackState t;
  t.robot_valid = true;
  t.robot_mean = Pose2D{0.11, -0.91, 1.41};
  t.robot_frames = 8;
  t.object_moving = true;
  t.motion_start_s = 1.7;
  t.path_valid = true;
  t.path.t0_s = 1.6;
  t.path.origin_m = Eigen::Vector2d(0.35, 0.1);
  t.path.velocity_mps = Eigen::Vector2d(-0.1, -0.4);

  v1::PoseEstimate msg;
  FillStereoPoseEstimate(7, 2.0, std::chrono::system_clock::now(), "000030.png", &f, &t, nullptr,
                         0.002, &msg);
  EXPECT_EQ(msg.estimator(), v1::ESTIMATOR_KIND_STEREO_MARKER);
  EXPECT_EQ(msg.sequence(), 7u);
  EXPECT_DOUBLE_EQ(msg.timings().total(), 0.002);
  ASSERT_TRUE(msg.has_robot_pose_world());
  EXPECT_DOUBLE_EQ(msg.robot_pose_world().theta(), 1.4);
  const v1::StereoMarkerResult& r = msg.stereo_marker();
  EXPECT_EQ(r.status(), "ok");
  EXPECT_TRUE(r.robot_found());
  EXPECT_EQ(r.fit_method(), "svd");
  EXPECT_DOUBLE_EQ(r.fit_rms_residual(), 0.004);
  EXPECT_NEAR(r.camera_in_world().orientation().z(), std::sin(0.15), 1e-12);
  EXPECT_NEAR(r.camera_in_world().orientation().w(), std::cos(0.15), 1e-12);
  EXPECT_DOUBLE_EQ(r.camera_in_world().position().z(), 0.45);
  EXPECT_DOUBLE_EQ(r.robot_pose_world_mean().x(), 0.11);
  EXPECT_EQ(r.robot_mean_frames(), 8);
  EXPECT_TRUE(r.object_found());
  EXPECT_DOUBLE_EQ(r.object_position_world().x(), 0.3);
  EXPECT_TRUE(r.object_moving());
  EXPECT_DOUBLE_EQ(r.motion_start_time(), 1.7);
  ASSERT_TRUE(r.has_path());
  EXPECT_DOUBLE_EQ(r.path().velocity().y(), -0.4);
  ASSERT_TRUE(r.path().has_closest_approach());
  // The path from (0.35, 0.1) along (-0.1, -0.4) passes the robot's mean position; the closest
  // approach is reported with its distance.
  const PathPrediction::Approach a =
      t.path.ClosestApproach(Eigen::Vector2d(t.robot_mean.x, t.robot_mean.y));
  EXPECT_DOUBLE_EQ(r.path().closest_approach_distance(), a.distance_m);

  // A rejected frame: no pose anywhere, the reason is kept.
  StereoFrameResult bad;
  bad.status = StereoFrameStatus::kMissingLandmark;
  bad.reason = "left image shows 2 landmark blob(s), need exactly 3";
  bad.object_reason = "not seen";
  v1::PoseEstimate bad_msg;
  FillStereoPoseEstimate(8, 2.1, std::chrono::system_clock::now(), "x", &bad, nullptr, nullptr, 0.0,
                         &bad_msg);
  EXPECT_FALSE(bad_msg.has_robot_pose_world());
  EXPECT_FALSE(bad_msg.stereo_marker().robot_found());
  EXPECT_FALSE(bad_msg.stereo_marker().has_robot_pose_world());
  EXPECT_EQ(bad_msg.stereo_marker().status(), "missing_landmark");
  EXPECT_EQ(bad_msg.stereo_marker().status_reason(), bad.reason);
  EXPECT_EQ(bad_msg.stereo_marker().object_reason(), "not seen");

  // A pair that could not be read: the error, and no result.
  const Error error = MakeError(ErrorCode::kDataLoss, "left/000001.png: not an image");
  v1::PoseEstimate err_msg;
  FillStereoPoseEstimate(9, 2.2, std::chrono::system_clock::now(), "x", nullptr, nullptr, &error,
                         0.0, &err_msg);
  EXPECT_EQ(err_msg.error().code(), "data_loss");
  EXPECT_FALSE(err_msg.has_stereo_marker());
}

TEST(StereoProtoConvertTest, ColorImagesAreCheckedAndRoundTrip) {
  RgbImage image(4, 2);
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = static_cast<std::uint8_t>(i);
  v1::ColorImage msg;
  ColorImageToProto(image, &msg);
  Result<RgbImage> back = ColorImageFromProto(msg, "left");
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->pixels, image.pixels);
  msg.mutable_data()->pop_back();
  back = ColorImageFromProto(msg, "left");
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(back.error().message.find("left.data: expected width * height * 3 = 24 bytes, got 23"),
            std::string::npos)
      << back.error().message;
  msg.set_width(0);
  back = ColorImageFromProto(msg, "right");
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().message.find("right: width and height"), std::string::npos);
}

// A small simulated sequence in a fresh directory.
class StereoPipelineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (std::filesystem::temp_directory_path() /
            ("hpose_stereo_pipeline_" + std::to_string(::getpid())))
               .string();
    std::filesystem::remove_all(dir_);
    StereoSimSequenceSpec spec;
    spec.frames = 3;
    spec.noise.supersample = 1;
    ASSERT_TRUE(WriteStereoSimSequence(spec, dir_).ok());
    Result<StereoSequence> seq = StereoSequence::Open(dir_);
    ASSERT_TRUE(seq.ok());
    sequence_ = std::make_unique<StereoSequence>(std::move(*seq));
    Result<StereoCalibration> cal = ReadStereoCalibration({sequence_->calibration_path()});
    ASSERT_TRUE(cal.ok());
    Result<std::unique_ptr<StereoEstimator>> est = StereoEstimator::Create(*cal);
    ASSERT_TRUE(est.ok());
    estimator_ = std::move(*est);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string dir_;
  std::unique_ptr<StereoSequence> sequence_;
  std::unique_ptr<StereoEstimator> estimator_;
};

TEST_F(StereoPipelineTest, FastReplayPublishesEveryPairThenFinishes) {
  StereoConfig config;
  config.realtime = false;
  PublishSignal signal;
  StereoPipeline pipeline(*sequence_, estimator_.get(), config, &signal);
  EXPECT_EQ(pipeline.Latest(), nullptr);
  pipeline.Start();
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (pipeline.Status().state != SourceState::kFinished &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(10ms);
  }
  const PipelineStatus s = pipeline.Status();
  EXPECT_EQ(s.state, SourceState::kFinished);
  EXPECT_EQ(s.kind, "stereo-dir");
  EXPECT_EQ(s.frames_in, 3u);
  EXPECT_EQ(s.frames_dropped, 0u);
  EXPECT_EQ(s.frames_estimated, 3u);  // every simulated pair gives a pose.
  EXPECT_EQ(s.frames_failed, 0u);
  EXPECT_EQ(s.latency_samples, 3u);
  EXPECT_GE(signal.count(), 3u);
  auto latest = pipeline.Latest();
  ASSERT_NE(latest, nullptr);
  EXPECT_EQ(latest->sequence, 3u);
  EXPECT_EQ(latest->publish_id, 3u);
  EXPECT_EQ(latest->origin, "000002.png");
  EXPECT_DOUBLE_EQ(latest->source_time_s, sequence_->frame(2).timestamp_s);
  ASSERT_TRUE(latest->ok);
  EXPECT_TRUE(latest->frame.ok());
  EXPECT_EQ(latest->track.robot_frames, 3);  // the tracker saw all three.
  std::string reason;
  EXPECT_TRUE(pipeline.IsStale(*latest, &reason));
  EXPECT_NE(reason.find("finished"), std::string::npos) << reason;
  pipeline.Stop();
}

TEST_F(StereoPipelineTest, LoopingRestartsTheTracker) {
  StereoConfig config;
  config.realtime = true;  // 15 Hz: every publication can be observed.
  config.loop = true;
  StereoPipeline pipeline(*sequence_, estimator_.get(), config);
  pipeline.Start();
  std::uint64_t last = 0;
  int observed = 0;
  std::uint64_t max_sequence = 0;
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (max_sequence < 7 && std::chrono::steady_clock::now() < deadline) {
    auto e = pipeline.WaitNewer(last, std::chrono::steady_clock::now() + 1s);
    if (!e || e->publish_id <= last) continue;
    last = e->publish_id;
    ++observed;
    max_sequence = e->sequence;
    ASSERT_TRUE(e->ok);
    // Position within the loop: 1, 2, 3, 1, 2, 3, ... frames of history at most.
    const int in_loop = static_cast<int>((e->sequence - 1) % 3) + 1;
    EXPECT_LE(e->track.robot_frames, in_loop) << "sequence " << e->sequence;
    EXPECT_DOUBLE_EQ(e->source_time_s, sequence_->frame(in_loop - 1).timestamp_s);
    std::string reason;
    EXPECT_FALSE(pipeline.IsStale(*e, &reason)) << reason;
  }
  EXPECT_GE(max_sequence, 7u);
  EXPECT_GE(observed, 4);
  EXPECT_EQ(pipeline.Status().state, SourceState::kRunning);
  pipeline.Stop();
}

}  // namespace
}  // namespace hpose::server
