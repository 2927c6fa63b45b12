// A hostile client on loopback: crafted Estimate requests that used to abort the daemon (values
// that turn non-finite inside the pipeline) get INVALID_ARGUMENT, and the daemon keeps serving
// ordinary requests afterwards.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/depth/depth_to_cloud.h"
#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/daemon.h"
#include "server/proto_convert.h"
#include "tests/integration/daemon_fixture.h"
#include "tests/integration/hposed_process.h"
#include "tests/integration/test_util.h"
#include "tests/sanitizer_build.h"

namespace hpose::server {
namespace {

using namespace std::chrono_literals;
namespace tu = hpose::testing_util;

class HostileClientTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    suite_ = tu::SuiteDaemon::Start({"hostile", 2}, [](const std::string&, DaemonConfig* config) {
      config->templates = {tu::TemplatePath("standing")};
    });
  }
  static void TearDownTestSuite() { suite_.reset(); }

  void SetUp() override {
    ASSERT_NE(suite_, nullptr);
    stub_ = v1::PoseService::NewStub(
        grpc::CreateChannel("127.0.0.1:" + std::to_string(suite_->daemon().port()),
                            grpc::InsecureChannelCredentials()));
  }

  static v1::EstimateRequest FrameRequest() { return tu::FrameRequest(suite_->dir() + "/frames"); }

  static v1::EstimateRequest CloudRequest() {
    const v1::EstimateRequest depth_request = FrameRequest();
    Intrinsics k;
    Result<DepthImage> depth = DepthFromProto(depth_request.depth(), &k);
    EXPECT_TRUE(depth.ok());
    v1::EstimateRequest request;
    if (depth.ok()) CloudToProto(*DepthToCloud(*depth, k), request.mutable_cloud());
    return request;
  }

  grpc::Status Estimate(const v1::EstimateRequest& request) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + 60s);
    v1::EstimateResponse response;
    return stub_->Estimate(&ctx, request, &response);
  }

  // The daemon is alive and a normal request still finds the humanoid.
  void ExpectStillServing() {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + 60s);
    v1::EstimateResponse response;
    const grpc::Status s = stub_->Estimate(&ctx, FrameRequest(), &response);
    ASSERT_TRUE(s.ok()) << s.error_message();
    EXPECT_TRUE(response.estimate().depth_template().humanoid_found());
  }

  static inline std::unique_ptr<tu::SuiteDaemon> suite_;
  std::unique_ptr<v1::PoseService::Stub> stub_;
};

TEST_F(HostileClientTest, ExtremeIntrinsicsAreInvalidArgument) {
  for (const double f : {1e-34, 1e-30, 1e-40, 1e30}) {
    v1::EstimateRequest request = FrameRequest();
    request.mutable_depth()->mutable_intrinsics()->set_fx(f);
    grpc::Status s = Estimate(request);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << f << ": " << s.error_message();
    EXPECT_NE(s.error_message().find("fx"), std::string::npos) << s.error_message();
    request = FrameRequest();
    request.mutable_depth()->mutable_intrinsics()->set_cy(-1e15);
    s = Estimate(request);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << s.error_message();
  }
  ExpectStillServing();
}

TEST_F(HostileClientTest, CoordinatesThatOverflowAreInvalidArgument) {
  for (const float v : {1e38f, -3e38f, std::numeric_limits<float>::infinity(), 5000.0f}) {
    v1::EstimateRequest request = CloudRequest();
    auto* xyz = request.mutable_cloud()->mutable_xyz();
    ASSERT_GT(xyz->size(), 3000);
    // Many huge points in one voxel used to sum to infinity inside the floor fit.
    for (int i = 0; i < xyz->size(); i += 150) xyz->Set(i, v);
    const grpc::Status s = Estimate(request);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << v << ": " << s.error_message();
    EXPECT_NE(s.error_message().find("point"), std::string::npos) << s.error_message();
  }
  ExpectStillServing();
}

TEST_F(HostileClientTest, DegenerateCloudsDoNotStopTheDaemon) {
  // All points in one spot; all on the optical axis; all nearly in the optical centre's plane.
  for (int kind = 0; kind < 3; ++kind) {
    v1::EstimateRequest request;
    for (int i = 0; i < 3000; ++i) {
      const float t = static_cast<float>(i) / 3000.0f;
      const float p[3][3] = {{0.1f, 0.2f, 1.0f}, {0.0f, 0.0f, 0.5f + t}, {t - 0.5f, 0.3f, 1e-30f}};
      for (int a = 0; a < 3; ++a) request.mutable_cloud()->add_xyz(p[kind][a]);
    }
    const grpc::Status s = Estimate(request);
    EXPECT_TRUE(s.ok() || s.error_code() == grpc::StatusCode::INVALID_ARGUMENT ||
                s.error_code() == grpc::StatusCode::FAILED_PRECONDITION)
        << kind << ": " << s.error_code() << " " << s.error_message();
  }
  ExpectStillServing();
}

// 40 clients on their own connections send a ~15 MB cloud each at the same moment. Every answer
// is OK or RESOURCE_EXHAUSTED (admission control, or gRPC's memory quota refusing the stream),
// except that gRPC may drop a connection whose request it cannot buffer (UNAVAILABLE, "Broken
// pipe": seen once for one client in a fresh-clone CI run); hposed keeps serving, and its peak
// resident memory stays within 1 GB (docs/RELIABILITY.md).
TEST(DaemonFloodTest, FortyConcurrentLargeRequestsStayBounded) {
  const std::string dir = tu::MakeTempDir("flood");
  ASSERT_TRUE(tu::SimulateFrames(dir + "/frames", 2));
  tu::HposedProcess hposed({"--listen", "127.0.0.1:0", "--template", tu::TemplatePath("standing")});
  ASSERT_FALSE(hposed.address().empty()) << "hposed did not start";
  const long base_kb = hposed.StatusKb("VmRSS");

  // The frame's cloud, tiled with small offsets to ~15 MB (1.25 million points).
  Result<DepthImage> depth = ReadDepthPng(dir + "/frames/depth_000.png");
  Result<Intrinsics> k = ReadIntrinsicsJson(dir + "/frames/intrinsics.json");
  ASSERT_TRUE(depth.ok() && k.ok());
  const PointCloud frame = *DepthToCloud(*depth, *k);
  v1::EstimateRequest request;
  auto* xyz = request.mutable_cloud()->mutable_xyz();
  constexpr int kPoints = 1'250'000;
  xyz->Reserve(3 * kPoints);
  for (int i = 0; i < kPoints; ++i) {
    const Eigen::Vector3f& p = frame.points[i % frame.size()];
    const float jitter = 0.001f * static_cast<float>((i / frame.size()) % 7);
    xyz->Add(p.x() + jitter);
    xyz->Add(p.y());
    xyz->Add(p.z());
  }
  ASSERT_GT(request.ByteSizeLong(), 14u << 20);
  ASSERT_LT(request.ByteSizeLong(), 16u << 20);

  constexpr int kClients = 40;
  std::vector<grpc::StatusCode> codes(kClients, grpc::StatusCode::UNKNOWN);
  std::vector<std::string> messages(kClients);
  std::atomic<int> ready{0};
  std::vector<std::thread> clients;
  for (int c = 0; c < kClients; ++c) {
    clients.emplace_back([&, c] {
      grpc::ChannelArguments args;
      args.SetInt("grpc.channel_id", c);  // one connection per client.
      args.SetMaxSendMessageSize(32 << 20);
      auto stub = v1::PoseService::NewStub(
          grpc::CreateCustomChannel(hposed.address(), grpc::InsecureChannelCredentials(), args));
      ++ready;
      while (ready.load() < kClients) std::this_thread::yield();
      grpc::ClientContext ctx;
      ctx.set_deadline(std::chrono::system_clock::now() + 300s);
      v1::EstimateResponse response;
      const grpc::Status s = stub->Estimate(&ctx, request, &response);
      codes[c] = s.error_code();
      messages[c] = s.error_message();
    });
  }
  for (std::thread& t : clients) t.join();
  int ok = 0, exhausted = 0, dropped = 0;
  for (int c = 0; c < kClients; ++c) {
    EXPECT_TRUE(codes[c] == grpc::StatusCode::OK ||
                codes[c] == grpc::StatusCode::RESOURCE_EXHAUSTED ||
                codes[c] == grpc::StatusCode::UNAVAILABLE)
        << "client " << c << ": " << codes[c] << " " << messages[c];
    ok += codes[c] == grpc::StatusCode::OK ? 1 : 0;
    exhausted += codes[c] == grpc::StatusCode::RESOURCE_EXHAUSTED ? 1 : 0;
    dropped += codes[c] == grpc::StatusCode::UNAVAILABLE ? 1 : 0;
  }
  // A dropped connection is gRPC's last resort, not the daemon's way of refusing: the exception.
  EXPECT_LE(dropped, kClients / 4);
  std::map<std::string, int> reasons;  // for the log: who refused, and why.
  for (int c = 0; c < kClients; ++c) ++reasons[messages[c]];
  for (const auto& [reason, n] : reasons) std::printf("  %2d x '%s'\n", n, reason.c_str());
  const long peak_kb = hposed.StatusKb("VmHWM");
  std::printf(
      "flood: %d OK, %d RESOURCE_EXHAUSTED, %d UNAVAILABLE; hposed RSS %ld kB before, peak %ld "
      "kB\n",
      ok, exhausted, dropped, base_kb, peak_kb);
  ASSERT_TRUE(hposed.alive());
  EXPECT_GT(peak_kb, 0);
  // 1 GB in the Release build (the documented figure); AddressSanitizer adds its quarantine of
  // freed blocks (256 MB by default), red zones and shadow memory on top.
  EXPECT_LE(peak_kb, (hpose::testing::kSanitizerBuild ? 2048L : 1024L) * 1024L);

  // Still serving: an ordinary frame is estimated. Right after the flood gRPC's memory quota
  // may still refuse a call (RESOURCE_EXHAUSTED, as a client is told to retry): a few tries.
  auto stub = v1::PoseService::NewStub(
      grpc::CreateChannel(hposed.address(), grpc::InsecureChannelCredentials()));
  v1::EstimateRequest normal;
  DepthToProto(*depth, *k, normal.mutable_depth());
  grpc::Status s;
  for (int attempt = 0; attempt < 10; ++attempt) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + 60s);
    v1::EstimateResponse response;
    s = stub->Estimate(&ctx, normal, &response);
    if (s.error_code() != grpc::StatusCode::RESOURCE_EXHAUSTED) break;
    std::this_thread::sleep_for(1s);
  }
  EXPECT_TRUE(s.ok()) << s.error_code() << " " << s.error_message();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hpose::server
