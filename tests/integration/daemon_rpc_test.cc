// Starts the daemon in-process on a free loopback port and checks every RPC, streaming with
// cancellation, and that bad requests get the right status while the daemon keeps serving.
#include <google/protobuf/util/json_util.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>

#include "core/depth/depth_to_cloud.h"
#include "core/io/intrinsics_json.h"
#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/daemon.h"
#include "server/proto_convert.h"
#include "tests/integration/daemon_fixture.h"
#include "tests/integration/test_util.h"

namespace hpose::server {
namespace {

using namespace std::chrono_literals;
namespace tu = hpose::testing_util;

constexpr int kMaxReceiveBytes = 1 << 20;

std::unique_ptr<v1::PoseService::Stub> Connect(int port) {
  return v1::PoseService::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials()));
}

void SetDeadline(grpc::ClientContext* ctx, std::chrono::milliseconds d) {
  ctx->set_deadline(std::chrono::system_clock::now() + d);
}

class DaemonRpcTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    suite_ = tu::SuiteDaemon::Start({"rpc", 3}, [](const std::string& dir, DaemonConfig* config) {
      tu::LoopTheFrames(dir, config);
      config->grpc.max_receive_message_bytes = kMaxReceiveBytes;
    });
  }
  static void TearDownTestSuite() { suite_.reset(); }

  void SetUp() override {
    ASSERT_NE(suite_, nullptr);
    stub_ = Connect(suite_->daemon().port());
  }

  // A request holding the first simulated frame.
  v1::EstimateRequest FrameRequest() const { return tu::FrameRequest(suite_->dir() + "/frames"); }

  grpc::Status Estimate(const v1::EstimateRequest& request, v1::EstimateResponse* response) {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 120s);
    return stub_->Estimate(&ctx, request, response);
  }

  void ExpectStillServing() {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 10s);
    v1::GetStatusResponse status;
    ASSERT_TRUE(stub_->GetStatus(&ctx, v1::GetStatusRequest(), &status).ok());
    EXPECT_EQ(status.templates(), 2u);
  }

  static inline std::unique_ptr<tu::SuiteDaemon> suite_;
  std::unique_ptr<v1::PoseService::Stub> stub_;
};

TEST_F(DaemonRpcTest, EstimateDepthFindsTheHumanoid) {
  v1::EstimateResponse response;
  grpc::Status s = Estimate(FrameRequest(), &response);
  ASSERT_TRUE(s.ok()) << s.error_message();
  const v1::PoseEstimate& e = response.estimate();
  EXPECT_EQ(e.estimator(), v1::ESTIMATOR_KIND_DEPTH_TEMPLATE);
  EXPECT_EQ(e.source(), "request");
  EXPECT_FALSE(e.stale());
  ASSERT_TRUE(e.has_depth_template());
  const v1::DepthTemplateResult& r = e.depth_template();
  ASSERT_TRUE(r.humanoid_found());
  const v1::Candidate& c = r.best().best();
  EXPECT_NEAR(c.pose().x(), 1.0, 0.1);  // simulated 1 m ahead, theta 0.
  EXPECT_NEAR(c.pose().y(), 0.0, 0.1);
  // The 3D form agrees with (x, y, theta): z = 0, rotation about +z by theta.
  EXPECT_DOUBLE_EQ(c.pose_3d().position().x(), c.pose().x());
  EXPECT_DOUBLE_EQ(c.pose_3d().position().z(), 0.0);
  EXPECT_NEAR(c.pose_3d().orientation().z(), std::sin(c.pose().theta() / 2), 1e-9);
  EXPECT_NEAR(c.pose_3d().orientation().w(), std::cos(c.pose().theta() / 2), 1e-9);
  EXPECT_GT(c.score(), 0.0);
  EXPECT_FALSE(r.best().second_template().empty());  // two templates were matched.
  EXPECT_GE(r.candidates_size(), 2);
  EXPECT_GT(r.floor().height(), 0.2);
  EXPECT_GT(e.timings().total(), 0.0);
}

TEST_F(DaemonRpcTest, EstimateCloudAndTemplateSubset) {
  v1::EstimateRequest depth_request = FrameRequest();
  Intrinsics k;
  Result<DepthImage> depth = DepthFromProto(depth_request.depth(), &k);
  ASSERT_TRUE(depth.ok());
  Result<PointCloud> cloud = DepthToCloud(*depth, k);
  ASSERT_TRUE(cloud.ok());
  v1::EstimateRequest request;
  CloudToProto(*cloud, request.mutable_cloud());
  request.add_templates("standing");
  v1::EstimateResponse response;
  grpc::Status s = Estimate(request, &response);
  ASSERT_TRUE(s.ok()) << s.error_message();
  const v1::DepthTemplateResult& r = response.estimate().depth_template();
  ASSERT_GT(r.candidates_size(), 0);
  for (const v1::Candidate& c : r.candidates()) EXPECT_EQ(c.template_name(), "standing");
}

// `hpose query estimate` of a cloud with no finite point says so, naming the file, rather than
// sending an empty cloud for the daemon to call empty; the daemon is not asked and serves on.
TEST_F(DaemonRpcTest, QueryOfACloudWithoutFinitePointsNamesTheFile) {
  const std::string pcd = suite_->dir() + "/nan.pcd";
  std::ofstream(pcd) << "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
                        "COUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\n"
                        "DATA ascii\nnan nan nan\nnan 1 inf\n";
  std::string out;
  const int code = tu::RunCommand(
      tu::HposeProgram() + " query estimate '" + pcd +
          "' --timeout 20 --server 127.0.0.1:" + std::to_string(suite_->daemon().port()) + " 2>&1",
      &out);
  EXPECT_EQ(code, 1) << out;
  EXPECT_NE(out.find("nan.pcd: the cloud has no finite points (all 2 are NaN or infinite)"),
            std::string::npos)
      << out;
  ExpectStillServing();
}

// `hpose query estimate` of a frame: its line gives the template margin in the points the
// estimate's --json form names (score, fit, or at least so many score points).
TEST_F(DaemonRpcTest, QueryLineGivesTheTemplateMarginInItsPoints) {
  const std::string query = tu::HposeProgram() + " query estimate '" + suite_->dir() +
                            "/frames/depth_000.png' --timeout 60 --server 127.0.0.1:" +
                            std::to_string(suite_->daemon().port());
  std::string json, text;
  ASSERT_EQ(tu::RunCommand(query + " --json 2>&1", &json), 0) << json;
  ASSERT_EQ(tu::RunCommand(query + " 2>&1", &text), 0) << text;
  v1::PoseEstimate e;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(json, &e).ok()) << json;
  const v1::Detection& d = e.depth_template().best();
  ASSERT_FALSE(d.second_template().empty()) << json;  // the daemon holds two templates.
  char expected[64];
  std::snprintf(expected, sizeof(expected), "  margin %s%.1f %s",
                d.template_margin_kind() == v1::TEMPLATE_MARGIN_SCORE_AT_LEAST ? ">=" : "",
                d.template_margin(),
                d.template_margin_kind() == v1::TEMPLATE_MARGIN_FIT ? "fit" : "score");
  EXPECT_NE(text.find(expected), std::string::npos) << expected << "\n" << text;
  // The runner-up's score against the best's, signed (above it where the fit chose the best).
  const v1::Candidate& c = d.best();
  ASSERT_TRUE(c.has_runner_up()) << json;
  std::snprintf(expected, sizeof(expected), " deg (%+.1f)", 0.0 - c.runner_up_margin());
  EXPECT_NE(text.find(expected), std::string::npos) << expected << "\n" << text;
  EXPECT_EQ(text.find("(--"), std::string::npos) << text;
  // In view whole: the line says nothing of it.
  ASSERT_TRUE(c.refined()) << json;
  EXPECT_GE(c.fit().in_view(), 0.9) << json;
  EXPECT_EQ(text.find("in view"), std::string::npos) << text;
}

// A robot whose head and raised arm the image's top cuts: its line says how much of its template
// was in view, as the estimate's --json form gives it.
TEST_F(DaemonRpcTest, QueryLineSaysHowMuchOfACutTemplateWasInView) {
  const std::string dir = suite_->dir() + "/cut";
  std::string out;
  ASSERT_EQ(tu::RunCommand(tu::HposeProgram() + " simulate --out '" + dir +
                               "' --pose right_arm_raised --x 1.0 --theta-deg 150 --pitch-deg 15 "
                               "--seed 11 --no-cloud 2>&1",
                           &out),
            0)
      << out;
  const std::string query =
      tu::HposeProgram() + " query estimate '" + dir +
      "/depth.png' --timeout 60 --server 127.0.0.1:" + std::to_string(suite_->daemon().port());
  std::string json, text;
  ASSERT_EQ(tu::RunCommand(query + " --json 2>&1", &json), 0) << json;
  ASSERT_EQ(tu::RunCommand(query + " 2>&1", &text), 0) << text;
  v1::PoseEstimate e;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(json, &e).ok()) << json;
  ASSERT_TRUE(e.depth_template().humanoid_found()) << json;
  const v1::Candidate& c = e.depth_template().best().best();
  ASSERT_TRUE(c.refined()) << json;
  EXPECT_GT(c.fit().in_view(), 0.3) << json;
  EXPECT_LT(c.fit().in_view(), 0.9) << json;
  char expected[32];
  std::snprintf(expected, sizeof(expected), "  in view %.0f%%", 100.0 * c.fit().in_view());
  EXPECT_NE(text.find(expected), std::string::npos) << expected << "\n" << text;
  ExpectStillServing();
}

// Deadlines the clock cannot hold are usage errors, not a deadline already past.
TEST_F(DaemonRpcTest, QueryTimeoutsBeyondADayAreUsageErrors) {
  const std::string server = " --server 127.0.0.1:" + std::to_string(suite_->daemon().port());
  std::string out;
  int code =
      tu::RunCommand(tu::HposeProgram() + " query status --timeout 1e300" + server + " 2>&1", &out);
  EXPECT_EQ(code, 2) << out;
  EXPECT_NE(out.find("--timeout must be at most 86400 seconds"), std::string::npos) << out;
  out.clear();
  code = tu::RunCommand(
      tu::HposeProgram() + " query stream --compare --count 1 --max-dt 1e300" + server + " 2>&1",
      &out);
  EXPECT_EQ(code, 2) << out;
  EXPECT_NE(out.find("--max-dt must be at most 60 seconds"), std::string::npos) << out;
  out.clear();
  EXPECT_EQ(tu::RunCommand(tu::HposeProgram() + " query status --timeout 30" + server, &out), 0)
      << out;
}

TEST_F(DaemonRpcTest, UnknownTemplateIsNotFound) {
  v1::EstimateRequest request = FrameRequest();
  request.add_templates("sitting");
  v1::EstimateResponse response;
  grpc::Status s = Estimate(request, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_NE(s.error_message().find("sitting"), std::string::npos) << s.error_message();
  EXPECT_EQ(s.error_message().find("did you mean"), std::string::npos) << s.error_message();
  // A slip gets the name meant.
  request = FrameRequest();
  request.add_templates("standng");
  s = Estimate(request, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_NE(s.error_message().find("unknown template 'standng' (loaded: "), std::string::npos)
      << s.error_message();
  EXPECT_NE(s.error_message().find("; did you mean 'standing'?)"), std::string::npos)
      << s.error_message();
  ExpectStillServing();
}

TEST_F(DaemonRpcTest, WrongSizesAreInvalidArgument) {
  v1::EstimateRequest request = FrameRequest();
  request.mutable_depth()->mutable_data()->resize(100);
  v1::EstimateResponse response;
  grpc::Status s = Estimate(request, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("bytes"), std::string::npos) << s.error_message();

  request = FrameRequest();
  request.mutable_depth()->mutable_intrinsics()->set_width(640);
  s = Estimate(request, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("does not match"), std::string::npos) << s.error_message();

  v1::EstimateRequest cloud;
  cloud.mutable_cloud()->add_xyz(1.0f);
  cloud.mutable_cloud()->add_xyz(2.0f);
  s = Estimate(cloud, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("multiple of 3"), std::string::npos) << s.error_message();

  s = Estimate(v1::EstimateRequest(), &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  ExpectStillServing();
}

TEST_F(DaemonRpcTest, NanIntrinsicsAreInvalidArgument) {
  v1::EstimateRequest request = FrameRequest();
  request.mutable_depth()->mutable_intrinsics()->set_fy(std::nan(""));
  v1::EstimateResponse response;
  grpc::Status s = Estimate(request, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("fy"), std::string::npos) << s.error_message();
  request = FrameRequest();
  request.mutable_depth()->mutable_intrinsics()->set_fx(-3.0);
  s = Estimate(request, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  ExpectStillServing();
}

TEST_F(DaemonRpcTest, OversizedMessageIsResourceExhausted) {
  v1::EstimateRequest request;
  v1::DepthImage* depth = request.mutable_depth();
  depth->set_width(1024);
  depth->set_height(1024);
  depth->mutable_data()->assign(1024 * 1024 * 2, '\0');  // 2 MiB > the 1 MiB limit.
  v1::EstimateResponse response;
  grpc::Status s = Estimate(request, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << s.error_message();
  ExpectStillServing();
}

TEST_F(DaemonRpcTest, ExpiredDeadlineIsHonoured) {
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() - 1s);
  v1::EstimateResponse response;
  grpc::Status s = stub_->Estimate(&ctx, FrameRequest(), &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  ExpectStillServing();
}

TEST_F(DaemonRpcTest, GetLatestWaitsForANewerEstimate) {
  v1::GetLatestResponse first, second;
  {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 120s);
    v1::GetLatestRequest request;
    request.set_after_sequence(1);  // waits until the source's second frame is estimated.
    grpc::Status s = stub_->GetLatest(&ctx, request, &first);
    ASSERT_TRUE(s.ok()) << s.error_message();
  }
  EXPECT_GT(first.estimate().sequence(), 1u);
  EXPECT_TRUE(first.estimate().has_depth_template());
  EXPECT_NE(first.estimate().source().find("depth_"), std::string::npos);
  {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 120s);
    v1::GetLatestRequest request;
    request.set_after_sequence(first.estimate().sequence());
    ASSERT_TRUE(stub_->GetLatest(&ctx, request, &second).ok());
  }
  EXPECT_GT(second.estimate().sequence(), first.estimate().sequence());
  {  // A sequence far in the future cannot arrive before a short deadline.
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 300ms);
    v1::GetLatestRequest request;
    request.set_after_sequence(1000000);
    v1::GetLatestResponse never;
    EXPECT_EQ(stub_->GetLatest(&ctx, request, &never).error_code(),
              grpc::StatusCode::DEADLINE_EXCEEDED);
  }
}

TEST_F(DaemonRpcTest, StreamDeliversUntilCancelled) {
  grpc::ClientContext ctx;
  std::unique_ptr<grpc::ClientReader<v1::PoseEstimate>> reader =
      stub_->StreamPoses(&ctx, v1::StreamPosesRequest());
  v1::PoseEstimate e;
  std::uint64_t last = 0;
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(reader->Read(&e));
    EXPECT_GT(e.sequence(), last);
    last = e.sequence();
  }
  ctx.TryCancel();
  while (reader->Read(&e)) {
  }
  EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::CANCELLED);
  ExpectStillServing();

  grpc::ClientContext bounded;
  v1::StreamPosesRequest request;
  request.set_max_estimates(1);
  auto reader2 = stub_->StreamPoses(&bounded, request);
  int n = 0;
  while (reader2->Read(&e)) ++n;
  EXPECT_TRUE(reader2->Finish().ok());
  EXPECT_EQ(n, 1);
}

TEST_F(DaemonRpcTest, ListTemplatesAndStatus) {
  grpc::ClientContext ctx;
  v1::ListTemplatesResponse list;
  ASSERT_TRUE(stub_->ListTemplates(&ctx, v1::ListTemplatesRequest(), &list).ok());
  ASSERT_EQ(list.templates_size(), 2);
  EXPECT_EQ(list.templates(0).name(), "standing");
  EXPECT_EQ(list.templates(1).name(), "right_arm_raised");
  EXPECT_GT(list.templates(0).voxels(), 100);
  EXPECT_NEAR(list.templates(0).resolution(), 0.016, 1e-9);
  // The shipped Nao's templates are searched on their own voxels.
  for (const v1::TemplateInfo& t : list.templates()) {
    EXPECT_NEAR(t.search_resolution(), 0.016, 1e-9) << t.name();
  }

  {  // Make sure at least one frame went through.
    grpc::ClientContext wait;
    SetDeadline(&wait, 120s);
    v1::GetLatestRequest request;
    request.set_after_sequence(1);
    v1::GetLatestResponse latest;
    ASSERT_TRUE(stub_->GetLatest(&wait, request, &latest).ok());
  }
  grpc::ClientContext sctx;
  v1::GetStatusResponse st;
  ASSERT_TRUE(stub_->GetStatus(&sctx, v1::GetStatusRequest(), &st).ok());
  EXPECT_EQ(st.source().state(), v1::SOURCE_STATE_RUNNING);
  EXPECT_EQ(st.source().kind(), "png-dir");
  EXPECT_GE(st.source().frames_in(), 2u);
  EXPECT_GE(st.source().frames_estimated(), 1u);
  EXPECT_GT(st.uptime(), 0.0);
  EXPECT_EQ(st.floor_mode(), "fit");
  EXPECT_GT(st.floor().height(), 0.2);
  EXPECT_GE(st.latency().samples(), 1u);
  EXPECT_GE(st.latency().p99(), st.latency().median());
  // The frames' size and camera: the recording's intrinsics.json.
  Result<Intrinsics> k = ReadIntrinsicsJson(suite_->dir() + "/frames/intrinsics.json");
  ASSERT_TRUE(k.ok()) << k.error().message;
  ASSERT_TRUE(st.source().has_camera());
  EXPECT_FALSE(st.source().point_clouds());
  const v1::Intrinsics& camera = st.source().camera();
  EXPECT_EQ(camera.width(), static_cast<std::uint32_t>(k->width));
  EXPECT_EQ(camera.height(), static_cast<std::uint32_t>(k->height));
  EXPECT_EQ(camera.fx(), k->fx);
  EXPECT_EQ(camera.fy(), k->fy);
  EXPECT_EQ(camera.cx(), k->cx);
  EXPECT_EQ(camera.cy(), k->cy);
  // hpose query status says it in a line.
  std::string out;
  ASSERT_EQ(tu::RunCommand(tu::HposeProgram() + " query status --server 127.0.0.1:" +
                               std::to_string(suite_->daemon().port()),
                           &out),
            0)
      << out;
  char line[160];
  std::snprintf(line, sizeof(line), "camera: %dx%d depth frames, fx %.1f fy %.1f cx %.1f cy %.1f\n",
                k->width, k->height, k->fx, k->fy, k->cx, k->cy);
  EXPECT_NE(out.find(line), std::string::npos) << line << "not in:\n" << out;
}

TEST(DaemonWithoutSourceTest, GetLatestIsFailedPreconditionAndBadListenFails) {
  DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.templates = {tu::TemplatePath("standing")};
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  auto stub = Connect((*daemon)->port());
  grpc::ClientContext ctx;
  v1::GetLatestResponse latest;
  grpc::Status s = stub->GetLatest(&ctx, v1::GetLatestRequest(), &latest);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::FAILED_PRECONDITION);

  // The same port again cannot be bound: a clear error, not a crash.
  DaemonConfig clash = config;
  clash.grpc.listen = "127.0.0.1:" + std::to_string((*daemon)->port());
  Result<std::unique_ptr<Daemon>> second = Daemon::Start(clash);
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.error().code, ErrorCode::kUnavailable);

  DaemonConfig missing = config;
  missing.templates = {"/nonexistent/dir/standing.bt"};
  Result<std::unique_ptr<Daemon>> third = Daemon::Start(missing);
  ASSERT_FALSE(third.ok());
  EXPECT_NE(third.error().message.find("standing.bt"), std::string::npos);
}

// A daemon on loopback replaying the recording in `dir` once (no loop) with the standing
// template.
DaemonConfig RecordingOnceConfig(const std::string& dir) {
  DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.source.path = dir;
  config.templates = {tu::TemplatePath("standing")};
  return config;
}

TEST(DaemonFinishedRecordingTest, LastEstimateIsStaleWithTheReason) {
  const std::string dir = tu::MakeTempDir("finished");
  ASSERT_TRUE(tu::SimulateFrames(dir, 2));
  DaemonConfig config = RecordingOnceConfig(dir);
  config.source.realtime = false;  // as fast as possible: finishes quickly.
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  auto stub = Connect((*daemon)->port());
  v1::GetStatusResponse st;
  for (int i = 0; i < 600; ++i) {  // up to 60 s on a loaded machine.
    grpc::ClientContext ctx;
    ASSERT_TRUE(stub->GetStatus(&ctx, v1::GetStatusRequest(), &st).ok());
    if (st.source().state() == v1::SOURCE_STATE_FINISHED &&
        st.source().frames_estimated() + st.source().frames_failed() == 2) {
      break;
    }
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(st.source().state(), v1::SOURCE_STATE_FINISHED);
  EXPECT_EQ(st.source().frames_in(), 2u);
  EXPECT_EQ(st.source().frames_dropped(), 0u);  // fast replay waits instead of dropping.
  grpc::ClientContext ctx;
  v1::GetLatestResponse latest;
  ASSERT_TRUE(stub->GetLatest(&ctx, v1::GetLatestRequest(), &latest).ok());
  EXPECT_TRUE(latest.estimate().stale());
  EXPECT_NE(latest.estimate().stale_reason().find("finished"), std::string::npos)
      << latest.estimate().stale_reason();
  // Said once: "source finished: DIR: end of recording", not "source finished: source ...".
  EXPECT_EQ(latest.estimate().stale_reason().find("finished: source finished"), std::string::npos)
      << latest.estimate().stale_reason();
  (*daemon)->Shutdown();
  std::filesystem::remove_all(dir);
}

// A recording played to its end (no loop) ends the streams on it: a stream open while it plays
// gets its estimates up to the last frame, then ends OK; one opened afterwards ends at once, and
// so does `hpose query stream --count N`. GetLatest waiting for a sequence after the last says
// none will come instead of waiting for its deadline.
TEST(DaemonFinishedRecordingTest, StreamsEndWithTheRecording) {
  const std::string dir = tu::MakeTempDir("stream_end");
  ASSERT_TRUE(tu::SimulateFrames(dir, 6));
  DaemonConfig config = RecordingOnceConfig(dir);
  config.source.fps = 2.0;  // 3 s of frames at the recorded rate: the stream opens first.
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  auto stub = Connect((*daemon)->port());
  std::uint64_t last_sequence = 0;
  int received = 0;
  {
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 120s);
    auto reader = stub->StreamPoses(&ctx, v1::StreamPosesRequest());
    v1::PoseEstimate e;
    while (reader->Read(&e)) {
      EXPECT_GT(e.sequence(), last_sequence);
      last_sequence = e.sequence();
      ++received;
    }
    const grpc::Status s = reader->Finish();
    EXPECT_TRUE(s.ok()) << s.error_code() << ": " << s.error_message();
  }
  v1::GetStatusResponse st;
  {
    grpc::ClientContext ctx;
    ASSERT_TRUE(stub->GetStatus(&ctx, v1::GetStatusRequest(), &st).ok());
  }
  EXPECT_EQ(st.source().state(), v1::SOURCE_STATE_FINISHED);
  EXPECT_EQ(st.source().frames_in(), 6u);
  EXPECT_GE(received, 1);
  grpc::ClientContext latest_ctx;
  v1::GetLatestResponse latest;
  ASSERT_TRUE(stub->GetLatest(&latest_ctx, v1::GetLatestRequest(), &latest).ok());
  EXPECT_EQ(last_sequence, latest.estimate().sequence());  // the stream saw the last estimate.
  EXPECT_EQ(
      st.source().frames_estimated() + st.source().frames_failed() + st.source().frames_dropped(),
      6u);
  {  // Opened after the end: ends at once, nothing sent.
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 60s);
    v1::StreamPosesRequest request;
    request.set_max_estimates(5);
    auto reader = stub->StreamPoses(&ctx, request);
    v1::PoseEstimate e;
    EXPECT_FALSE(reader->Read(&e));
    const grpc::Status s = reader->Finish();
    EXPECT_TRUE(s.ok()) << s.error_code() << ": " << s.error_message();
  }
  {  // Waiting for a sequence after the last one: none will come.
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 60s);
    v1::GetLatestRequest request;
    request.set_after_sequence(latest.estimate().sequence());
    v1::GetLatestResponse response;
    const grpc::Status s = stub->GetLatest(&ctx, request, &response);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::OUT_OF_RANGE) << s.error_message();
    EXPECT_NE(s.error_message().find("will come: the source finished"), std::string::npos)
        << s.error_message();
  }
  {  // One before the last: answered with the last at once.
    grpc::ClientContext ctx;
    SetDeadline(&ctx, 60s);
    v1::GetLatestRequest request;
    request.set_after_sequence(latest.estimate().sequence() - 1);
    v1::GetLatestResponse response;
    ASSERT_TRUE(stub->GetLatest(&ctx, request, &response).ok());
    EXPECT_EQ(response.estimate().sequence(), latest.estimate().sequence());
  }
  {  // The command line: exits 0 and says why the stream ended.
    std::string out;
    const int code =
        tu::RunCommand("timeout 60 " + tu::HposeProgram() + " query --server 127.0.0.1:" +
                           std::to_string((*daemon)->port()) + " stream --count 5 2>&1",
                       &out);
    EXPECT_EQ(code, 0) << out;
    EXPECT_NE(out.find("the stream ended after 0 estimate(s): the daemon's source has ended"),
              std::string::npos)
        << out;
  }
  (*daemon)->Shutdown();
  std::filesystem::remove_all(dir);
}

// A daemon whose templates are taller than search.max_height_voxels of their voxels searches on
// coarser ones: ListTemplates says which edge, next to each template's own, and `hpose query
// templates` prints it.
TEST(DaemonSearchEdgeTest, ListTemplatesReportsTheCoarserSearchEdge) {
  DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.templates = {tu::TemplatePath("standing"), tu::TemplatePath("right_arm_raised")};
  config.estimator.max_height_voxels = 20;  // the Nao is 36-41 voxels of 16 mm high.
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  const double edge = (*daemon)->search_resolution_m();
  EXPECT_GT(edge, 0.016 * 36 / 20 - 1e-9);
  EXPECT_LT(edge, 0.040);

  std::unique_ptr<v1::PoseService::Stub> stub = Connect((*daemon)->port());
  grpc::ClientContext ctx;
  SetDeadline(&ctx, 60s);
  v1::ListTemplatesResponse list;
  ASSERT_TRUE(stub->ListTemplates(&ctx, v1::ListTemplatesRequest(), &list).ok());
  ASSERT_EQ(list.templates_size(), 2);
  for (const v1::TemplateInfo& t : list.templates()) {
    EXPECT_NEAR(t.resolution(), 0.016, 1e-9) << t.name();
    EXPECT_DOUBLE_EQ(t.search_resolution(), edge) << t.name();
  }

  std::string out;
  const int code = tu::RunCommand(
      tu::HposeProgram() +
          " query templates --timeout 20 --server 127.0.0.1:" + std::to_string((*daemon)->port()),
      &out);
  EXPECT_EQ(code, 0) << out;
  char expected[64];
  std::snprintf(expected, sizeof(expected), "searched on %.0f mm voxels", edge * 1e3);
  EXPECT_NE(out.find("voxels of 16 mm"), std::string::npos) << out;
  EXPECT_NE(out.find(expected), std::string::npos) << out;
}

}  // namespace
}  // namespace hpose::server
