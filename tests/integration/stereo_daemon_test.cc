// The daemon running both estimators on loopback: a simulated stereo sequence beside simulated
// depth frames, with the depth sensor placed in the world frame. Checks the served stereo poses
// against the simulator's ground truth, the estimator marking, the world-frame depth poses, the
// EstimateStereo call and the start-up errors of bad stereo configurations.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/common/pose2d.h"
#include "core/io/atomic_file.h"
#include "core/sim/sim_truth.h"
#include "core/stereo/rgb_image_io.h"
#include "core/stereo/stereo_calibration.h"
#include "core/stereo/stereo_sequence.h"
#include "core/stereo/stereo_sim_sequence.h"
#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/daemon.h"
#include "server/proto_convert.h"
#include "server/stereo_proto_convert.h"
#include "server/world_frame.h"
#include "tests/integration/daemon_fixture.h"
#include "tests/integration/test_util.h"
#include "tests/sanitizer_build.h"

namespace hpose::server {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
namespace tu = hpose::testing_util;

// Tolerances against the simulator's truth: the stereo estimator measures the head to about
// 2 cm at 1 m from the landmarks (SPEC: mean 26 mm under 1 m); the depth-template search works
// on a 16 mm lattice with 5 degree steps in its first pass.
constexpr double kStereoTolM = 0.05;
constexpr double kStereoTolRad = 5.0 * kPi / 180.0;
constexpr double kDepthTolM = 0.1;
constexpr double kDepthTolRad = 12.0 * kPi / 180.0;

// The depth sensor 2 m behind the stereo robot's start, looking along world +y. The simulated
// humanoid 1 m ahead of the depth sensor then stands where the stereo simulator puts its robot.
const Pose2D kWorldFromGround{0.05, -2.0, kPi / 2};

struct StereoTruthRow {
  double t = 0.0;
  Pose2D head;
  bool object_present = false;
  Eigen::Vector3d object = Eigen::Vector3d::Zero();
  bool object_moving = false;
};

std::vector<StereoTruthRow> ReadStereoTruth(const std::string& path) {
  std::vector<StereoTruthRow> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header.
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
    if (v.size() < 14) continue;  // later columns: occlusion and distractor counts.
    StereoTruthRow r;
    r.t = v[1];
    r.head = Pose2D{v[5], v[6], v[7]};
    r.object_present = v[9] != 0.0;
    r.object = Eigen::Vector3d(v[10], v[11], v[12]);
    r.object_moving = v[13] != 0.0;
    rows.push_back(r);
  }
  return rows;
}

std::unique_ptr<v1::PoseService::Stub> Connect(int port) {
  return v1::PoseService::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials()));
}

void SetDeadline(grpc::ClientContext* ctx, std::chrono::milliseconds d) {
  ctx->set_deadline(std::chrono::system_clock::now() + d);
}

Pose2D FromProto(const v1::Pose2D& p) { return Pose2D{p.x(), p.y(), p.theta()}; }

void ExpectPoseNear(const Pose2D& actual, const Pose2D& expected, double tol_m, double tol_rad,
                    const std::string& what) {
  EXPECT_NEAR(actual.x, expected.x, tol_m) << what;
  EXPECT_NEAR(actual.y, expected.y, tol_m) << what;
  EXPECT_LT(std::abs(AngleDiff(actual.theta, expected.theta)), tol_rad) << what;
}

StereoSimSequenceSpec SmallSpec(int frames) {
  StereoSimSequenceSpec spec;
  spec.frames = frames;
  spec.noise.supersample = 1;
  return spec;
}

// Rendering the 45 stereo pairs takes minutes under the sanitizers, and every test pays it in
// its own process: there the suite is skipped (the stereo estimator's own tests still run).
class StereoDaemonTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (testing::kSanitizerBuild) return;
    dir_ = new std::string(tu::MakeTempDir("stereo_daemon"));
    StereoSimSequenceSpec spec;  // rolling ball: kicked at 1.6 s.
    spec.frames = 45;
    ASSERT_TRUE(WriteStereoSimSequence(spec, *dir_ + "/stereo").ok());
    truth_ = new std::vector<StereoTruthRow>(ReadStereoTruth(*dir_ + "/stereo/ground_truth.csv"));
    ASSERT_EQ(truth_->size(), 45u);
    ASSERT_TRUE(tu::SimulateFrames(*dir_ + "/depth", 3));
    Result<std::string> text = ReadFile(*dir_ + "/depth/truth.json");
    ASSERT_TRUE(text.ok());
    Result<SimTruth> depth_truth = ParseSimTruthJson(*text, "truth.json");
    ASSERT_TRUE(depth_truth.ok()) << depth_truth.error().ToString();
    depth_truth_ = new SimTruth(std::move(*depth_truth));

    DaemonConfig config;
    config.grpc.listen = "127.0.0.1:0";
    config.source.path = *dir_ + "/depth";
    config.source.loop = true;
    config.source.fps = 5.0;
    config.templates = {tu::TemplatePath("standing")};
    config.stereo.source = *dir_ + "/stereo";
    config.stereo.loop = true;
    config.world_from_ground = {true, kWorldFromGround.x, kWorldFromGround.y,
                                kWorldFromGround.theta};
    Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
    ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
    daemon_ = daemon->release();
  }
  static void TearDownTestSuite() {
    delete daemon_;
    daemon_ = nullptr;
    if (dir_ != nullptr) fs::remove_all(*dir_);
    delete dir_;
    delete truth_;
    delete depth_truth_;
  }

  void SetUp() override {
    HPOSE_SKIP_IF_SANITIZED();
    ASSERT_NE(daemon_, nullptr);
    stub_ = Connect(daemon_->port());
  }

  const StereoTruthRow& TruthOf(const v1::PoseEstimate& e) const {
    return (*truth_)[(e.sequence() - 1) % truth_->size()];
  }

  // Reads up to `max` estimates of `estimators` (empty = all) until `enough` says so.
  std::vector<v1::PoseEstimate> Stream(const std::vector<v1::EstimatorKind>& estimators, int max,
                                       const std::function<bool(const v1::PoseEstimate&)>& enough) {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 180s);
    v1::StreamPosesRequest request;
    for (v1::EstimatorKind k : estimators) request.add_estimators(k);
    auto reader = stub_->StreamPoses(&ctx, request);
    std::vector<v1::PoseEstimate> got;
    v1::PoseEstimate e;
    while (static_cast<int>(got.size()) < max && reader->Read(&e)) {
      got.push_back(e);
      if (enough(e)) break;
    }
    ctx.TryCancel();
    while (reader->Read(&e)) {
    }
    reader->Finish();
    return got;
  }

  static std::string* dir_;
  static std::vector<StereoTruthRow>* truth_;
  static SimTruth* depth_truth_;
  static Daemon* daemon_;
  std::unique_ptr<v1::PoseService::Stub> stub_;
};

std::string* StereoDaemonTest::dir_ = nullptr;
std::vector<StereoTruthRow>* StereoDaemonTest::truth_ = nullptr;
SimTruth* StereoDaemonTest::depth_truth_ = nullptr;
Daemon* StereoDaemonTest::daemon_ = nullptr;

TEST_F(StereoDaemonTest, StreamCarriesBothEstimatorsEachMarked) {
  int depth = 0, stereo = 0;
  const auto got = Stream({}, 400, [&](const v1::PoseEstimate& e) {
    (e.estimator() == v1::ESTIMATOR_KIND_STEREO_MARKER ? stereo : depth)++;
    return depth >= 1 && stereo >= 3;
  });
  EXPECT_GE(depth, 1);
  EXPECT_GE(stereo, 3);
  for (const v1::PoseEstimate& e : got) {
    if (e.estimator() == v1::ESTIMATOR_KIND_STEREO_MARKER) {
      EXPECT_TRUE(e.has_stereo_marker());
      EXPECT_FALSE(e.has_depth_template());
      EXPECT_NE(e.source().find(".png"), std::string::npos) << e.source();
    } else {
      EXPECT_EQ(e.estimator(), v1::ESTIMATOR_KIND_DEPTH_TEMPLATE);
      EXPECT_TRUE(e.has_depth_template() || e.has_error());
      EXPECT_FALSE(e.has_stereo_marker());
    }
  }
}

TEST_F(StereoDaemonTest, StereoPosesMatchTheSimulatorTruth) {
  const auto got =
      Stream({v1::ESTIMATOR_KIND_STEREO_MARKER}, 12, [](const v1::PoseEstimate&) { return false; });
  ASSERT_EQ(got.size(), 12u);
  int found = 0;
  for (const v1::PoseEstimate& e : got) {
    ASSERT_EQ(e.estimator(), v1::ESTIMATOR_KIND_STEREO_MARKER);
    const v1::StereoMarkerResult& r = e.stereo_marker();
    const StereoTruthRow& truth = TruthOf(e);
    EXPECT_NEAR(e.source_time(), truth.t, 1e-6);
    if (!r.robot_found()) continue;
    ++found;
    EXPECT_EQ(r.status(), "ok");
    const std::string what = "sequence " + std::to_string(e.sequence());
    ExpectPoseNear(FromProto(r.robot_pose_world()), truth.head, kStereoTolM, kStereoTolRad, what);
    // The estimate-level world pose is the same pose, for side-by-side use.
    ASSERT_TRUE(e.has_robot_pose_world());
    EXPECT_DOUBLE_EQ(e.robot_pose_world().x(), r.robot_pose_world().x());
    EXPECT_NEAR(r.camera_height(), 0.45, 0.03) << what;  // the simulated head height.
    EXPECT_NEAR(r.camera_in_world().position().z(), r.camera_height(), 0.05) << what;
    EXPECT_GE(r.robot_mean_frames(), 1);
    EXPECT_LE(r.robot_mean_frames(), 8);
    ExpectPoseNear(FromProto(r.robot_pose_world_mean()), truth.head, kStereoTolM, kStereoTolRad,
                   what + " (mean)");
    if (truth.object_present && r.object_found()) {
      EXPECT_NEAR(r.object_position_world().x(), truth.object.x(), kStereoTolM) << what;
      EXPECT_NEAR(r.object_position_world().y(), truth.object.y(), kStereoTolM) << what;
    }
  }
  EXPECT_GE(found, 10);
}

TEST_F(StereoDaemonTest, BallMotionAndPredictedPathAreServed) {
  // The ball is kicked 1.6 s into the 3 s sequence; wait for a frame with a fitted path.
  const auto got = Stream({v1::ESTIMATOR_KIND_STEREO_MARKER}, 200,
                          [](const v1::PoseEstimate& e) { return e.stereo_marker().has_path(); });
  ASSERT_FALSE(got.empty());
  const v1::PoseEstimate& e = got.back();
  const v1::StereoMarkerResult& r = e.stereo_marker();
  ASSERT_TRUE(r.has_path()) << "no path fitted in " << got.size() << " estimates";
  EXPECT_TRUE(r.object_moving());
  EXPECT_TRUE(TruthOf(e).object_moving);
  EXPECT_GT(e.source_time(), r.motion_start_time());
  // Kicked at (-0.12, -0.45) m/s, slowing down at 0.12 m/s^2.
  EXPECT_NEAR(r.path().velocity().x(), -0.12, 0.1);
  EXPECT_NEAR(r.path().velocity().y(), -0.42, 0.12);
  EXPECT_TRUE(r.path().has_closest_approach());
  for (const v1::PoseEstimate& before : got) {
    if (!TruthOf(before).object_moving && TruthOf(before).t < 1.0) {
      EXPECT_FALSE(before.stereo_marker().object_moving()) << before.sequence();
    }
  }
}

TEST_F(StereoDaemonTest, DepthPosesAreAlsoReportedInTheWorldFrame) {
  grpc::ClientContext ctx;
  SetDeadline(&ctx, 180s);
  v1::GetLatestRequest request;
  request.set_estimator(v1::ESTIMATOR_KIND_DEPTH_TEMPLATE);
  request.set_after_sequence(1);
  v1::GetLatestResponse response;
  grpc::Status s = stub_->GetLatest(&ctx, request, &response);
  ASSERT_TRUE(s.ok()) << s.error_message();
  const v1::PoseEstimate& e = response.estimate();
  ASSERT_EQ(e.estimator(), v1::ESTIMATOR_KIND_DEPTH_TEMPLATE);
  ASSERT_TRUE(e.has_depth_template());
  const v1::DepthTemplateResult& r = e.depth_template();
  ASSERT_TRUE(r.humanoid_found());
  ASSERT_TRUE(r.has_world_from_ground());
  EXPECT_DOUBLE_EQ(r.world_from_ground().y(), kWorldFromGround.y);
  const v1::Candidate& c = r.best().best();
  ASSERT_TRUE(c.has_pose_world());
  // The world pose is the ground pose moved by world_from_ground...
  const Pose2D composed = GroundPoseToWorld(kWorldFromGround, FromProto(c.pose()));
  ExpectPoseNear(FromProto(c.pose_world()), composed, 1e-9, 1e-9, "composition");
  ASSERT_TRUE(e.has_robot_pose_world());
  EXPECT_DOUBLE_EQ(e.robot_pose_world().theta(), c.pose_world().theta());
  for (const v1::Candidate& other : r.candidates()) EXPECT_TRUE(other.has_pose_world());
  // ...and lands on the simulator's truth moved the same way.
  const SimFrameTruth* frame = nullptr;
  for (const SimFrameTruth& f : depth_truth_->frames) {
    if (e.source().find(f.depth_file) != std::string::npos) frame = &f;
  }
  ASSERT_NE(frame, nullptr) << e.source();
  const Pose2D expected = GroundPoseToWorld(kWorldFromGround, frame->humanoid_pose);
  EXPECT_NEAR(expected.x, 0.05, 1e-9);  // 1 m ahead of the sensor = the stereo robot's place.
  EXPECT_NEAR(expected.y, -1.0, 1e-9);
  ExpectPoseNear(FromProto(e.robot_pose_world()), expected, kDepthTolM, kDepthTolRad, e.source());
}

TEST_F(StereoDaemonTest, GetLatestChoosesTheEstimator) {
  for (v1::EstimatorKind kind : {v1::ESTIMATOR_KIND_UNSPECIFIED, v1::ESTIMATOR_KIND_STEREO_MARKER,
                                 v1::ESTIMATOR_KIND_DEPTH_TEMPLATE}) {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 180s);
    v1::GetLatestRequest request;
    request.set_estimator(kind);
    request.set_after_sequence(1);
    v1::GetLatestResponse response;
    grpc::Status s = stub_->GetLatest(&ctx, request, &response);
    ASSERT_TRUE(s.ok()) << s.error_message();
    // Unspecified = the depth source, as before the stereo source existed.
    EXPECT_EQ(response.estimate().estimator(),
              kind == v1::ESTIMATOR_KIND_UNSPECIFIED ? v1::ESTIMATOR_KIND_DEPTH_TEMPLATE : kind);
    EXPECT_GT(response.estimate().sequence(), 1u);
  }
}

TEST_F(StereoDaemonTest, EstimateStereoOnOnePair) {
  Result<StereoSequence> seq = StereoSequence::Open(*dir_ + "/stereo");
  ASSERT_TRUE(seq.ok());
  auto pair = seq->Load(5);
  ASSERT_TRUE(pair.ok());
  v1::EstimateStereoRequest request;
  ColorImageToProto(pair->first, request.mutable_left());
  ColorImageToProto(pair->second, request.mutable_right());
  request.set_source_time(2.5);
  v1::EstimateResponse response;
  {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 60s);
    grpc::Status s = stub_->EstimateStereo(&ctx, request, &response);
    ASSERT_TRUE(s.ok()) << s.error_message();
  }
  const v1::PoseEstimate& e = response.estimate();
  EXPECT_EQ(e.estimator(), v1::ESTIMATOR_KIND_STEREO_MARKER);
  EXPECT_EQ(e.source(), "request");
  EXPECT_DOUBLE_EQ(e.source_time(), 2.5);
  ASSERT_TRUE(e.stereo_marker().robot_found()) << e.stereo_marker().status_reason();
  ExpectPoseNear(FromProto(e.robot_pose_world()), (*truth_)[5].head, kStereoTolM, kStereoTolRad,
                 "pair 5");
  EXPECT_FALSE(e.stereo_marker().has_robot_pose_world_mean());  // one pair: no tracker.

  auto call = [&](const v1::EstimateStereoRequest& r, v1::EstimateResponse* out) {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 60s);
    return stub_->EstimateStereo(&ctx, r, out);
  };
  // Landmarks painted over: processed, but no pose, and the reason.
  v1::EstimateStereoRequest blank = request;
  blank.mutable_left()->mutable_data()->assign(blank.left().data().size(), '\x80');
  ASSERT_TRUE(call(blank, &response).ok());
  EXPECT_FALSE(response.estimate().stereo_marker().robot_found());
  EXPECT_FALSE(response.estimate().has_robot_pose_world());
  EXPECT_EQ(response.estimate().stereo_marker().status(), "missing_landmark");
  EXPECT_NE(response.estimate().stereo_marker().status_reason().find("left"), std::string::npos);

  // Images of different sizes.
  v1::EstimateStereoRequest sizes = request;
  ColorImageToProto(RgbImage(256, 120), sizes.mutable_right());
  grpc::Status s = call(sizes, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("right image is 256x120"), std::string::npos)
      << s.error_message();
  // Both smaller than the calibration's image size.
  ColorImageToProto(RgbImage(256, 120), sizes.mutable_left());
  s = call(sizes, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("calibration is for 512x240"), std::string::npos)
      << s.error_message();
  // A buffer that does not match its size, and a missing image.
  v1::EstimateStereoRequest truncated = request;
  truncated.mutable_right()->mutable_data()->resize(100);
  s = call(truncated, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("right.data"), std::string::npos) << s.error_message();
  v1::EstimateStereoRequest one = request;
  one.clear_right();
  s = call(one, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("right"), std::string::npos) << s.error_message();

  grpc::ClientContext ctx;
  v1::GetStatusResponse status;
  ASSERT_TRUE(stub_->GetStatus(&ctx, v1::GetStatusRequest(), &status).ok());
  EXPECT_GE(status.estimate_stereo_calls(), 2u);
}

TEST_F(StereoDaemonTest, StatusReportsBothSourcesAndTheWorldFrame) {
  Stream({v1::ESTIMATOR_KIND_STEREO_MARKER}, 2, [](const v1::PoseEstimate&) { return false; });
  grpc::ClientContext ctx;
  v1::GetStatusResponse st;
  ASSERT_TRUE(stub_->GetStatus(&ctx, v1::GetStatusRequest(), &st).ok());
  EXPECT_EQ(st.source().kind(), "png-dir");
  EXPECT_EQ(st.stereo_source().kind(), "stereo-dir");
  EXPECT_EQ(st.stereo_source().state(), v1::SOURCE_STATE_RUNNING);
  EXPECT_EQ(st.stereo_source().description(), *dir_ + "/stereo");
  EXPECT_GE(st.stereo_source().frames_in(), 2u);
  EXPECT_GE(st.stereo_source().frames_estimated(), 1u);
  EXPECT_GE(st.stereo_latency().samples(), 1u);
  EXPECT_TRUE(st.stereo_calibrated());
  // The pairs' size and the calibration's left camera.
  Result<StereoCalibration> cal = ReadStereoCalibration({*dir_ + "/stereo/calibration.yaml"});
  ASSERT_TRUE(cal.ok()) << cal.error().ToString();
  ASSERT_TRUE(st.stereo_source().has_camera());
  const v1::Intrinsics& k = st.stereo_source().camera();
  ASSERT_GT(cal->image_width, 0);
  EXPECT_EQ(k.width(), static_cast<unsigned>(cal->image_width));
  EXPECT_EQ(k.height(), static_cast<unsigned>(cal->image_height));
  EXPECT_DOUBLE_EQ(k.fx(), cal->left.camera_matrix(0, 0));
  EXPECT_DOUBLE_EQ(k.fy(), cal->left.camera_matrix(1, 1));
  EXPECT_DOUBLE_EQ(k.cx(), cal->left.camera_matrix(0, 2));
  EXPECT_DOUBLE_EQ(k.cy(), cal->left.camera_matrix(1, 2));
  // hpose query status says it in a line.
  std::string out;
  ASSERT_EQ(tu::RunCommand(tu::HposeProgram() + " query status --server 127.0.0.1:" +
                               std::to_string(daemon_->port()),
                           &out),
            0)
      << out;
  char line[160];
  std::snprintf(line, sizeof(line),
                "stereo camera: %ux%u pairs, left fx %.1f fy %.1f cx %.1f cy %.1f\n", k.width(),
                k.height(), k.fx(), k.fy(), k.cx(), k.cy());
  EXPECT_NE(out.find(line), std::string::npos) << out;
  ASSERT_TRUE(st.has_world_from_ground());
  EXPECT_DOUBLE_EQ(st.world_from_ground().x(), kWorldFromGround.x);
  EXPECT_DOUBLE_EQ(st.world_from_ground().theta(), kWorldFromGround.theta);
}

TEST(StereoOnlyDaemonTest, ServesTheStereoSourceAloneAndFinishes) {
  const std::string dir = tu::MakeTempDir("stereo_only");
  ASSERT_TRUE(WriteStereoSimSequence(SmallSpec(6), dir).ok());
  DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.templates = {tu::TemplatePath("standing")};
  config.stereo.source = dir;
  config.stereo.realtime = false;  // as fast as possible, no loop.
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  auto stub = Connect((*daemon)->port());
  v1::GetStatusResponse st;
  for (int i = 0; i < 600; ++i) {  // up to 60 s on a loaded machine.
    grpc::ClientContext ctx;
    ASSERT_TRUE(stub->GetStatus(&ctx, v1::GetStatusRequest(), &st).ok());
    if (st.stereo_source().state() == v1::SOURCE_STATE_FINISHED) break;
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(st.stereo_source().state(), v1::SOURCE_STATE_FINISHED);
  EXPECT_EQ(st.stereo_source().frames_in(), 6u);
  EXPECT_EQ(st.stereo_source().frames_dropped(), 0u);
  EXPECT_EQ(st.stereo_source().frames_estimated() + st.stereo_source().frames_failed(), 6u);
  EXPECT_EQ(st.source().state(), v1::SOURCE_STATE_NONE);
  EXPECT_FALSE(st.has_world_from_ground());
  {  // Unspecified = the stereo source when there is no depth source.
    grpc::ClientContext ctx;
    v1::GetLatestResponse latest;
    ASSERT_TRUE(stub->GetLatest(&ctx, v1::GetLatestRequest(), &latest).ok());
    EXPECT_EQ(latest.estimate().estimator(), v1::ESTIMATOR_KIND_STEREO_MARKER);
    EXPECT_EQ(latest.estimate().sequence(), 6u);
    EXPECT_TRUE(latest.estimate().stale());
    EXPECT_NE(latest.estimate().stale_reason().find("finished"), std::string::npos)
        << latest.estimate().stale_reason();
  }
  {
    grpc::ClientContext ctx;
    v1::GetLatestRequest request;
    request.set_estimator(v1::ESTIMATOR_KIND_DEPTH_TEMPLATE);
    v1::GetLatestResponse latest;
    EXPECT_EQ(stub->GetLatest(&ctx, request, &latest).error_code(),
              grpc::StatusCode::FAILED_PRECONDITION);
  }
  {  // The stereo sequence has ended: a stream of it ends at once.
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + 60s);
    auto reader = stub->StreamPoses(&ctx, v1::StreamPosesRequest());
    v1::PoseEstimate e;
    EXPECT_FALSE(reader->Read(&e));
    const grpc::Status s = reader->Finish();
    EXPECT_TRUE(s.ok()) << s.error_code() << ": " << s.error_message();
  }
  {
    grpc::ClientContext ctx;
    v1::StreamPosesRequest request;
    request.add_estimators(v1::ESTIMATOR_KIND_DEPTH_TEMPLATE);
    auto reader = stub->StreamPoses(&ctx, request);
    v1::PoseEstimate e;
    EXPECT_FALSE(reader->Read(&e));
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  }
  {  // Without world_from_ground, depth estimates carry no world-frame pose.
    const std::string frames = dir + "/depth";
    ASSERT_TRUE(tu::SimulateFrames(frames, 2));
    const v1::EstimateRequest request = tu::FrameRequest(frames);
    ASSERT_TRUE(request.has_depth());
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 120s);
    v1::EstimateResponse response;
    ASSERT_TRUE(stub->Estimate(&ctx, request, &response).ok());
    const v1::PoseEstimate& e = response.estimate();
    ASSERT_TRUE(e.depth_template().humanoid_found());
    EXPECT_FALSE(e.has_robot_pose_world());
    EXPECT_FALSE(e.depth_template().has_world_from_ground());
    EXPECT_FALSE(e.depth_template().best().best().has_pose_world());
  }
  (*daemon)->Shutdown();
  fs::remove_all(dir);
}

TEST(DaemonWithoutStereoTest, StereoCallsAreFailedPrecondition) {
  DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.templates = {tu::TemplatePath("standing")};
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  auto stub = Connect((*daemon)->port());
  {
    grpc::ClientContext ctx;
    v1::EstimateStereoRequest request;
    ColorImageToProto(RgbImage(8, 8), request.mutable_left());
    ColorImageToProto(RgbImage(8, 8), request.mutable_right());
    v1::EstimateResponse response;
    grpc::Status s = stub->EstimateStereo(&ctx, request, &response);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
    EXPECT_NE(s.error_message().find("stereo calibration"), std::string::npos) << s.error_message();
  }
  {
    grpc::ClientContext ctx;
    v1::GetLatestRequest request;
    request.set_estimator(v1::ESTIMATOR_KIND_STEREO_MARKER);
    v1::GetLatestResponse latest;
    grpc::Status s = stub->GetLatest(&ctx, request, &latest);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
    EXPECT_NE(s.error_message().find("stereo source"), std::string::npos) << s.error_message();
  }
  grpc::ClientContext ctx;
  v1::GetStatusResponse st;
  ASSERT_TRUE(stub->GetStatus(&ctx, v1::GetStatusRequest(), &st).ok());
  EXPECT_EQ(st.stereo_source().state(), v1::SOURCE_STATE_NONE);
  EXPECT_FALSE(st.stereo_calibrated());
}

// A calibration alone enables EstimateStereo without a stereo source.
TEST(DaemonWithoutStereoTest, CalibrationAloneEnablesEstimateStereo) {
  const std::string dir = tu::MakeTempDir("stereo_cal_only");
  ASSERT_TRUE(WriteStereoSimSequence(SmallSpec(1), dir).ok());
  DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.templates = {tu::TemplatePath("standing")};
  config.stereo.calibration = dir + "/calibration.yaml";
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  Result<RgbImage> left = ReadRgbImage(dir + "/left/000000.png");
  Result<RgbImage> right = ReadRgbImage(dir + "/right/000000.png");
  ASSERT_TRUE(left.ok() && right.ok());
  v1::EstimateStereoRequest request;
  ColorImageToProto(*left, request.mutable_left());
  ColorImageToProto(*right, request.mutable_right());
  auto stub = Connect((*daemon)->port());
  grpc::ClientContext ctx;
  v1::EstimateResponse response;
  grpc::Status s = stub->EstimateStereo(&ctx, request, &response);
  ASSERT_TRUE(s.ok()) << s.error_message();
  const std::vector<StereoTruthRow> truth = ReadStereoTruth(dir + "/ground_truth.csv");
  ASSERT_EQ(truth.size(), 1u);
  ASSERT_TRUE(response.estimate().stereo_marker().robot_found());
  ExpectPoseNear(FromProto(response.estimate().robot_pose_world()), truth[0].head, kStereoTolM,
                 kStereoTolRad, "pair 0");
  (*daemon)->Shutdown();
  fs::remove_all(dir);
}

TEST(StereoConfigErrorsTest, BadStereoInputFailsAtStartNamingTheProblem) {
  const std::string dir = tu::MakeTempDir("stereo_bad");
  ASSERT_TRUE(WriteStereoSimSequence(SmallSpec(2), dir + "/good").ok());
  StereoSimSequenceSpec small = SmallSpec(1);
  small.camera.width = 256;
  small.camera.height = 120;
  ASSERT_TRUE(WriteStereoSimSequence(small, dir + "/small").ok());
  DaemonConfig base;
  base.grpc.listen = "127.0.0.1:0";
  base.templates = {tu::TemplatePath("standing")};

  auto start_error = [&](const StereoConfig& stereo) {
    DaemonConfig config = base;
    config.stereo = stereo;
    Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
    return daemon.ok() ? std::string("started") : daemon.error().message;
  };
  StereoConfig c;
  c.source = dir + "/missing";
  EXPECT_NE(start_error(c).find(dir + "/missing"), std::string::npos) << start_error(c);

  // No calibration.yaml in the directory and none given.
  fs::copy(dir + "/good", dir + "/nocal", fs::copy_options::recursive);
  fs::remove(dir + "/nocal/calibration.yaml");
  c.source = dir + "/nocal";
  EXPECT_NE(start_error(c).find("calibration"), std::string::npos) << start_error(c);

  // A file that is not a stereo calibration: the error names it.
  std::ofstream(dir + "/not_a_calibration.yaml") << "%YAML:1.0\n---\nfx: 500\n";
  c.source = dir + "/good";
  c.calibration = dir + "/not_a_calibration.yaml";
  EXPECT_NE(start_error(c).find("not_a_calibration.yaml"), std::string::npos) << start_error(c);

  // The calibration of another camera (256x120) for 512x240 images.
  c.calibration = dir + "/small/calibration.yaml";
  EXPECT_NE(start_error(c).find("calibration is for 256x120"), std::string::npos) << start_error(c);

  // Left and right images of different sizes.
  fs::copy(dir + "/good", dir + "/sizes", fs::copy_options::recursive);
  ASSERT_TRUE(WriteRgbPng(RgbImage(256, 120), dir + "/sizes/right/000000.png").ok());
  c.source = dir + "/sizes";
  c.calibration.clear();
  EXPECT_NE(start_error(c).find("is 512x240 but"), std::string::npos) << start_error(c);

  // The good one starts.
  c.source = dir + "/good";
  EXPECT_EQ(start_error(c), "started");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace hpose::server
