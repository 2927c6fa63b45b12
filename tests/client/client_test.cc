// hpose::client against daemons started in-process on loopback: every call, streaming stopped
// by the callback, answers equal to the raw gRPC API's, errors with their codes, TLS and bearer
// tokens, and the PCD reader against the core's.
#include "hpose/client.h"

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "core/io/cloud_io.h"
#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/daemon.h"
#include "server/proto_convert.h"
#include "tests/integration/daemon_fixture.h"
#include "tests/integration/test_util.h"
#include "tests/sanitizer_build.h"

namespace hpose {
namespace {

using namespace std::chrono_literals;
namespace tu = hpose::testing_util;
namespace hc = hpose::client;

constexpr int kInvalidArgument = 3;
constexpr int kNotFound = 5;
constexpr int kUnavailable = 14;
constexpr int kUnauthenticated = 16;
constexpr char kToken[] = "client-test-token-0123456789abcdef";

// The simulated frame `index` as the client's depth image.
hc::DepthImage ClientDepth(const std::string& frames, int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "/depth_%03d.png", index);
  Result<DepthImage> depth = ReadDepthPng(frames + name);
  Result<Intrinsics> k = ReadIntrinsicsJson(frames + "/intrinsics.json");
  EXPECT_TRUE(depth.ok() && k.ok());
  hc::DepthImage out;
  if (!depth.ok() || !k.ok()) return out;
  out.width = depth->width;
  out.height = depth->height;
  out.depth_mm = depth->mm;
  out.fx = k->fx;
  out.fy = k->fy;
  out.cx = k->cx;
  out.cy = k->cy;
  return out;
}

class ClientTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // With clouds (cloud_000.pcd ...) for the cloud calls and the PCD reader.
    suite_ = tu::SuiteDaemon::Start({"client", 3, true}, tu::LoopTheFrames);
  }
  static void TearDownTestSuite() { suite_.reset(); }

  void SetUp() override {
    ASSERT_NE(suite_, nullptr);
    hc::ConnectOptions options;
    options.address = suite_->daemon().address();
    options.call_timeout_s = 120.0;
    const hc::Status s = hc::Client::Connect(options, &client_);
    ASSERT_TRUE(s.ok()) << s.message;
  }

  // The newest estimate, waiting for the first one (UNAVAILABLE until then).
  hc::PoseEstimate WaitLatest() {
    hc::PoseEstimate e;
    hc::Status s;
    for (int i = 0; i < 600; ++i) {
      s = client_->Latest(&e);
      if (s.code != kUnavailable) break;
      std::this_thread::sleep_for(100ms);
    }
    EXPECT_TRUE(s.ok()) << s.message;
    return e;
  }

  static inline std::unique_ptr<tu::SuiteDaemon> suite_;
  std::unique_ptr<hc::Client> client_;
};

TEST_F(ClientTest, ListTemplatesAndStatus) {
  std::vector<std::string> names;
  ASSERT_TRUE(client_->ListTemplates(&names).ok());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"right_arm_raised", "standing"}));
  WaitLatest();
  hc::DaemonStatus status;
  const hc::Status s = client_->GetStatus(&status);
  ASSERT_TRUE(s.ok()) << s.message;
  EXPECT_EQ(status.templates, 2u);
  EXPECT_EQ(status.source_state, "running");
  EXPECT_NE(status.source.find("frames"), std::string::npos) << status.source;
  EXPECT_GE(status.frames_in, status.frames_estimated);
  EXPECT_GT(status.frames_estimated, 0u);
  EXPECT_FALSE(status.version.empty());
  // The frames' size and camera: the recording's intrinsics.json.
  const hc::DepthImage frame = ClientDepth(suite_->dir() + "/frames", 0);
  EXPECT_EQ(status.frame_width, frame.width);
  EXPECT_EQ(status.frame_height, frame.height);
  EXPECT_EQ(status.fx, frame.fx);
  EXPECT_EQ(status.fy, frame.fy);
  EXPECT_EQ(status.cx, frame.cx);
  EXPECT_EQ(status.cy, frame.cy);
  EXPECT_FALSE(status.point_clouds);
}

TEST_F(ClientTest, LatestIsTheHumanoid) {
  const hc::PoseEstimate e = WaitLatest();
  EXPECT_EQ(e.estimator, hc::Estimator::kDepthTemplate);
  EXPECT_TRUE(e.error_code.empty()) << e.error_message;
  ASSERT_TRUE(e.has_match);
  EXPECT_TRUE(e.humanoid_found);
  EXPECT_NEAR(e.pose.x_m, 1.0, 0.1);  // simulated 1 m ahead.
  EXPECT_NEAR(e.pose.y_m, 0.0, 0.1);
  EXPECT_GT(e.score, 50.0);
  EXPECT_GT(e.floor_height_m, 0.2);
  EXPECT_GE(e.clusters, 1);
  EXPECT_GT(e.estimate_time_s, 0.0);
  EXPECT_GT(e.sequence, 0u);
}

TEST_F(ClientTest, StreamStopsWhenTheCallbackSaysSo) {
  std::vector<hc::PoseEstimate> seen;
  hc::StreamOptions options;
  options.estimator = hc::Estimator::kDepthTemplate;
  const hc::Status s = client_->Stream(
      [&](const hc::PoseEstimate& e) {
        seen.push_back(e);
        return seen.size() < 4;
      },
      options);
  ASSERT_TRUE(s.ok()) << s.message;
  ASSERT_EQ(seen.size(), 4u);
  for (size_t i = 1; i < seen.size(); ++i) EXPECT_GT(seen[i].sequence, seen[i - 1].sequence);
  for (const hc::PoseEstimate& e : seen) {
    EXPECT_EQ(e.estimator, hc::Estimator::kDepthTemplate);
    EXPECT_NEAR(e.pose.x_m, 1.0, 0.1);
  }
  // The connection stays usable after a cancelled stream.
  std::vector<std::string> names;
  EXPECT_TRUE(client_->ListTemplates(&names).ok());
}

TEST_F(ClientTest, StreamEndsAfterMaxEstimates) {
  int calls = 0;
  hc::StreamOptions options;
  options.max_estimates = 2;
  const hc::Status s = client_->Stream(
      [&](const hc::PoseEstimate&) {
        ++calls;
        return true;
      },
      options);
  ASSERT_TRUE(s.ok()) << s.message;
  EXPECT_EQ(calls, 2);
}

TEST_F(ClientTest, StreamEndsAtItsDeadline) {
  // Once the daemon publishes, a window of several of its frame periods holds estimates even on
  // a loaded machine (an estimate takes a fraction of a second under the sanitizers).
  WaitLatest();
  int calls = 0;
  hc::StreamOptions options;
  options.timeout_s = hpose::testing::kSanitizerBuild ? 8.0 : 2.0;
  const hc::Status s = client_->Stream(
      [&](const hc::PoseEstimate&) {
        ++calls;
        return true;
      },
      options);
  EXPECT_EQ(s.code, 4);  // DEADLINE_EXCEEDED
  EXPECT_GT(calls, 0);   // the source publishes at 10 Hz.
}

// The client's depth Estimate gives what the raw API gives for the same frame.
TEST_F(ClientTest, EstimateDepthAgreesWithTheRawApi) {
  const hc::DepthImage depth = ClientDepth(suite_->dir() + "/frames", 1);
  hc::PoseEstimate e;
  const hc::Status s = client_->Estimate(depth, &e);
  ASSERT_TRUE(s.ok()) << s.message;

  const v1::EstimateRequest request = tu::FrameRequest(suite_->dir() + "/frames", 1);
  ASSERT_TRUE(request.has_depth());
  auto stub = v1::PoseService::NewStub(
      grpc::CreateChannel(suite_->daemon().address(), grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + 120s);
  v1::EstimateResponse response;
  ASSERT_TRUE(stub->Estimate(&ctx, request, &response).ok());
  const v1::Candidate& c = response.estimate().depth_template().best().best();

  EXPECT_EQ(e.source, "request");
  ASSERT_TRUE(e.humanoid_found);
  EXPECT_EQ(e.template_name, c.template_name());
  EXPECT_DOUBLE_EQ(e.pose.x_m, c.pose().x());
  EXPECT_DOUBLE_EQ(e.pose.y_m, c.pose().y());
  EXPECT_DOUBLE_EQ(e.pose.theta_rad, c.pose().theta());
  EXPECT_DOUBLE_EQ(e.score, c.score());
  EXPECT_EQ(e.has_runner_up, c.has_runner_up());
  EXPECT_DOUBLE_EQ(e.runner_up_margin, c.runner_up_margin());
  const v1::Detection& d = response.estimate().depth_template().best();
  EXPECT_DOUBLE_EQ(e.template_margin, d.template_margin());
  EXPECT_EQ(static_cast<int>(e.template_margin_kind), static_cast<int>(d.template_margin_kind()));
  EXPECT_NEAR(e.pose.theta_rad, 20.0 * M_PI / 180.0, 5.0 * M_PI / 180.0);  // frame 1: turned 20.
}

TEST_F(ClientTest, EstimateCloudWithATemplateSubset) {
  hc::PointCloud cloud;
  hc::Status s = hc::ReadPcd(suite_->dir() + "/frames/cloud_000.pcd", &cloud);
  ASSERT_TRUE(s.ok()) << s.message;
  hc::PoseEstimate e;
  s = client_->Estimate(cloud, &e, {"standing"});
  ASSERT_TRUE(s.ok()) << s.message;
  EXPECT_TRUE(e.humanoid_found);
  EXPECT_EQ(e.template_name, "standing");
  EXPECT_NEAR(e.pose.x_m, 1.0, 0.1);
  EXPECT_NEAR(e.pose.y_m, 0.0, 0.1);
}

TEST_F(ClientTest, ErrorsCarryTheirCodes) {
  hc::PoseEstimate e;
  hc::DepthImage depth = ClientDepth(suite_->dir() + "/frames", 0);
  hc::Status s = client_->Estimate(depth, &e, {"sitting"});
  EXPECT_EQ(s.code, kNotFound);
  EXPECT_NE(s.message.find("sitting"), std::string::npos) << s.message;

  depth.depth_mm.resize(10);  // caught before sending.
  s = client_->Estimate(depth, &e);
  EXPECT_EQ(s.code, kInvalidArgument);
  EXPECT_NE(s.message.find("10 values"), std::string::npos) << s.message;

  hc::PointCloud cloud;
  cloud.xyz = {1.0f, 2.0f};
  s = client_->Estimate(cloud, &e);
  EXPECT_EQ(s.code, kInvalidArgument);
  EXPECT_NE(s.message.find("multiple of 3"), std::string::npos) << s.message;
}

// The example program (client/examples) against the same daemon.
TEST_F(ClientTest, ExampleProgramAnswers) {
  WaitLatest();
  const std::string example = std::string(HPOSE_BINARY_DIR) +
                              "/client/hpose_client_example --server " + suite_->daemon().address();
  std::string out;
  ASSERT_EQ(tu::RunCommand(example + " status", &out), 0) << out;
  EXPECT_NE(out.find("(running)"), std::string::npos) << out;
  EXPECT_NE(out.find("templates 2"), std::string::npos) << out;
  out.clear();
  ASSERT_EQ(tu::RunCommand(example + " stream 2", &out), 0) << out;
  // Two lines, each with the humanoid within 5 cm of 1 m ahead (printed in metres).
  const std::regex near_1m(R"(x (0\.9[5-9]|1\.0[0-5])\d* m)");
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 2) << out;
  EXPECT_EQ(
      std::distance(std::sregex_iterator(out.begin(), out.end(), near_1m), std::sregex_iterator()),
      2)
      << out;
  out.clear();
  ASSERT_EQ(tu::RunCommand(example + " estimate " + suite_->dir() + "/frames/cloud_000.pcd", &out),
            0)
      << out;
  EXPECT_TRUE(std::regex_search(out, near_1m)) << out;
  EXPECT_EQ(out.find("below threshold"), std::string::npos) << out;
  EXPECT_EQ(tu::RunCommand(example + " estimate 2>/dev/null"), 2);  // usage: missing FILE.
}

TEST(ClientConnectTest, UnreachableDaemonIsUnavailable) {
  // A port that was free a moment ago: nothing listens there.
  Result<std::unique_ptr<server::Daemon>> probe = [] {
    server::DaemonConfig config;
    config.grpc.listen = "127.0.0.1:0";
    config.templates = {tu::TemplatePath("standing")};
    return server::Daemon::Start(config);
  }();
  ASSERT_TRUE(probe.ok()) << probe.error().ToString();
  const std::string address = (*probe)->address();
  probe->reset();
  hc::ConnectOptions options;
  options.address = address;
  options.connect_timeout_s = 1.0;
  std::unique_ptr<hc::Client> client;
  const hc::Status s = hc::Client::Connect(options, &client);
  EXPECT_EQ(s.code, kUnavailable);
  EXPECT_NE(s.message.find(address), std::string::npos) << s.message;
  EXPECT_EQ(client, nullptr);
}

TEST(ClientConnectTest, BadOptionsAreInvalidArgument) {
  std::unique_ptr<hc::Client> client;
  hc::ConnectOptions options;
  options.tls_cert_file = "client.pem";
  EXPECT_EQ(hc::Client::Connect(options, &client).code, kInvalidArgument);
  options = hc::ConnectOptions();
  options.tls_ca_file = "/nonexistent/ca.pem";
  hc::Status s = hc::Client::Connect(options, &client);
  EXPECT_EQ(s.code, kInvalidArgument);
  EXPECT_NE(s.message.find("/nonexistent/ca.pem"), std::string::npos) << s.message;
  options = hc::ConnectOptions();
  options.token = "a";
  options.token_file = "b";
  EXPECT_EQ(hc::Client::Connect(options, &client).code, kInvalidArgument);
}

// Mutual TLS and a bearer token, with self-signed certificates made by openssl.
TEST(ClientSecureTest, TlsAndTokens) {
  const std::string dir = tu::MakeTempDir("client_tls");
  const std::string d = "'" + dir + "'";
  for (const std::string& who : {"server", "client"}) {
    ASSERT_EQ(tu::RunCommand("openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=" +
                             std::string(who == "server" ? "localhost" : "hpose-client") +
                             " -addext subjectAltName=IP:127.0.0.1,DNS:localhost -keyout " + d +
                             "/" + who + ".key -out " + d + "/" + who + ".pem > /dev/null 2>&1"),
              0)
        << "openssl failed";
  }
  std::ofstream(dir + "/tokens") << kToken << " read\n";
  std::ofstream(dir + "/token") << kToken << "\n";
  server::DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.templates = {tu::TemplatePath("standing")};
  config.security.tls_cert = dir + "/server.pem";
  config.security.tls_key = dir + "/server.key";
  config.security.tls_client_ca = dir + "/client.pem";
  config.security.tokens_file = dir + "/tokens";
  Result<std::unique_ptr<server::Daemon>> daemon = server::Daemon::Start(config);
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();

  hc::ConnectOptions options;
  options.address = "localhost:" + std::to_string((*daemon)->port());
  options.tls_ca_file = dir + "/server.pem";
  options.tls_cert_file = dir + "/client.pem";
  options.tls_key_file = dir + "/client.key";
  options.connect_timeout_s = 20.0;
  std::unique_ptr<hc::Client> client;
  hc::Status s = hc::Client::Connect(options, &client);
  ASSERT_TRUE(s.ok()) << s.message;
  hc::DaemonStatus status;
  EXPECT_EQ(client->GetStatus(&status).code, kUnauthenticated);  // no token.

  for (const bool from_file : {false, true}) {
    (from_file ? options.token_file : options.token) = from_file ? dir + "/token" : kToken;
    if (from_file) options.token.clear();
    s = hc::Client::Connect(options, &client);
    ASSERT_TRUE(s.ok()) << s.message;
    s = client->GetStatus(&status);
    EXPECT_TRUE(s.ok()) << (from_file ? "token_file: " : "token: ") << s.message;
    EXPECT_EQ(status.templates, 1u);
  }
  std::filesystem::remove_all(dir);
}

// ReadPcd gives the finite points the core's reader gives, for binary and ASCII files.
TEST_F(ClientTest, ReadPcdAgreesWithTheCoreReader) {
  const std::string binary = suite_->dir() + "/frames/cloud_002.pcd";
  Result<PointCloud> reference = ReadCloud(binary);
  ASSERT_TRUE(reference.ok());
  std::vector<float> expected;
  for (const auto& p : reference->points) {
    if (p.allFinite()) expected.insert(expected.end(), {p.x(), p.y(), p.z()});
  }
  hc::PointCloud cloud;
  hc::Status s = hc::ReadPcd(binary, &cloud);
  ASSERT_TRUE(s.ok()) << s.message;
  ASSERT_GT(expected.size(), 3000u);
  EXPECT_EQ(cloud.xyz, expected);

  const std::string ascii = suite_->dir() + "/ascii.pcd";
  std::ofstream(ascii) << "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\n"
                          "TYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n"
                          "0.5 -1.25 2 0\nnan nan nan 0\n1e-3 3 4.5 7\n";
  s = hc::ReadPcd(ascii, &cloud);
  ASSERT_TRUE(s.ok()) << s.message;
  EXPECT_EQ(cloud.xyz, (std::vector<float>{0.5f, -1.25f, 2.0f, 1e-3f, 3.0f, 4.5f}));

  std::ofstream(ascii)
      << "VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nPOINTS 1\nDATA ascii\n1 2\n";
  s = hc::ReadPcd(ascii, &cloud);
  EXPECT_EQ(s.code, kInvalidArgument);
  EXPECT_NE(s.message.find("lack x, y or z"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find(ascii), std::string::npos) << s.message;
  EXPECT_EQ(hc::ReadPcd(suite_->dir() + "/missing.pcd", &cloud).code, kNotFound);
}

}  // namespace
}  // namespace hpose
