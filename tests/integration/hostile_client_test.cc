// A hostile client on loopback: crafted Estimate requests that used to abort the daemon (values
// that turn non-finite inside the pipeline) get INVALID_ARGUMENT, and the daemon keeps serving
// ordinary requests afterwards.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>

#include "core/depth/depth_to_cloud.h"
#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/daemon.h"
#include "server/proto_convert.h"
#include "tests/integration/test_util.h"

namespace hpose::server {
namespace {

using namespace std::chrono_literals;
namespace tu = hpose::testing_util;

class HostileClientTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(tu::MakeTempDir("hostile"));
    ASSERT_TRUE(tu::SimulateFrames(*dir_ + "/frames", 2));
    DaemonConfig config;
    config.grpc.listen = "127.0.0.1:0";
    config.templates = {tu::TemplatePath("standing")};
    Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
    ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
    daemon_ = daemon->release();
  }
  static void TearDownTestSuite() {
    delete daemon_;
    daemon_ = nullptr;
    if (dir_ != nullptr) std::filesystem::remove_all(*dir_);
    delete dir_;
  }

  void SetUp() override {
    ASSERT_NE(daemon_, nullptr);
    stub_ = v1::PoseService::NewStub(grpc::CreateChannel(
        "127.0.0.1:" + std::to_string(daemon_->port()), grpc::InsecureChannelCredentials()));
  }

  static v1::EstimateRequest FrameRequest() {
    v1::EstimateRequest request;
    Result<DepthImage> depth = ReadDepthPng(*dir_ + "/frames/depth_000.png");
    Result<Intrinsics> k = ReadIntrinsicsJson(*dir_ + "/frames/intrinsics.json");
    EXPECT_TRUE(depth.ok() && k.ok());
    if (depth.ok() && k.ok()) DepthToProto(*depth, *k, request.mutable_depth());
    return request;
  }

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

  static std::string* dir_;
  static Daemon* daemon_;
  std::unique_ptr<v1::PoseService::Stub> stub_;
};

std::string* HostileClientTest::dir_ = nullptr;
Daemon* HostileClientTest::daemon_ = nullptr;

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

}  // namespace
}  // namespace hpose::server
