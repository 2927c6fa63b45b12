// Per-client StreamPoses limits: a client that opens more streams than
// grpc.max_pose_streams_per_client gets RESOURCE_EXHAUSTED for the extra ones while another
// client is still served, and a client gets its place back when one of its streams ends. A client
// is its bearer token when the daemon checks tokens, else its network address.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/daemon.h"
#include "tests/integration/test_util.h"

namespace hpose::server {
namespace {

using namespace std::chrono_literals;
namespace tu = hpose::testing_util;

constexpr char kTokenA[] = "client-a-token-0123456789";
constexpr char kTokenB[] = "client-b-token-0123456789";
constexpr int kLimit = 2;

// One StreamPoses call kept open by the client.
struct OpenStream {
  std::unique_ptr<grpc::ClientContext> ctx = std::make_unique<grpc::ClientContext>();
  std::unique_ptr<grpc::ClientReader<v1::PoseEstimate>> reader;
  bool got_estimate = false;  // the first message arrived: the daemon serves this stream.
};

OpenStream Open(v1::PoseService::Stub* stub, const std::string& token) {
  OpenStream s;
  s.ctx->set_deadline(std::chrono::system_clock::now() + 60s);
  if (!token.empty()) s.ctx->AddMetadata("authorization", std::string("Bearer ") + token);
  s.reader = stub->StreamPoses(s.ctx.get(), v1::StreamPosesRequest());
  v1::PoseEstimate first;
  s.got_estimate = s.reader->Read(&first);
  return s;
}

// Open() once the client has a free place: the daemon notices a cancelled stream within its
// wait period (100 ms) and only then gives its place back. Not got_estimate after 5 s.
OpenStream OpenWhenFree(v1::PoseService::Stub* stub, const std::string& token) {
  for (int attempt = 0;; ++attempt) {
    OpenStream s = Open(stub, token);
    if (s.got_estimate || attempt == 50) return s;
    const grpc::Status status = s.reader->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
    std::this_thread::sleep_for(100ms);
  }
}

// Ends a stream from the client side and waits for its status.
grpc::Status Close(OpenStream* s) {
  s->ctx->TryCancel();
  return s->reader->Finish();
}

class StreamLimitTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(tu::MakeTempDir("stream_limit"));
    ASSERT_TRUE(tu::SimulateFrames(*dir_ + "/frames", 2));
    std::ofstream(*dir_ + "/tokens") << kTokenA << " read\n" << kTokenB << " read\n";
  }
  static void TearDownTestSuite() {
    if (dir_ != nullptr) std::filesystem::remove_all(*dir_);
    delete dir_;
  }

  static DaemonConfig Config(const std::string& listen, bool tokens) {
    DaemonConfig config;
    config.grpc.listen = listen;
    config.grpc.max_pose_streams_per_client = kLimit;
    config.templates = {tu::TemplatePath("standing")};
    config.source.path = *dir_ + "/frames";
    config.source.loop = true;
    config.source.fps = 10.0;
    if (tokens) config.security.tokens_file = *dir_ + "/tokens";
    config.security.insecure = true;  // the address test listens on every address.
    return config;
  }

  // `first` opens kLimit streams, then one more, which must be refused while `second` is
  // still served; after `first` ends a stream, it may open one again.
  static void ExpectLimitPerClient(v1::PoseService::Stub* first, const std::string& first_token,
                                   v1::PoseService::Stub* second, const std::string& second_token) {
    std::vector<OpenStream> held;
    for (int i = 0; i < kLimit; ++i) {
      held.push_back(OpenWhenFree(first, first_token));
      ASSERT_TRUE(held.back().got_estimate) << "stream " << i << " within the limit";
    }
    OpenStream extra = Open(first, first_token);
    EXPECT_FALSE(extra.got_estimate);
    const grpc::Status refused = extra.reader->Finish();
    EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED)
        << refused.error_message();
    EXPECT_NE(refused.error_message().find("max_pose_streams_per_client"), std::string::npos)
        << refused.error_message();

    OpenStream other = Open(second, second_token);
    EXPECT_TRUE(other.got_estimate) << "another client is served while the first is at its limit";
    Close(&other);

    Close(&held.front());
    OpenStream again = OpenWhenFree(first, first_token);
    EXPECT_TRUE(again.got_estimate) << "a client gets its place back when one of its streams ends";
    Close(&again);
    for (size_t i = 1; i < held.size(); ++i) Close(&held[i]);
  }

  static std::string* dir_;
};
std::string* StreamLimitTest::dir_ = nullptr;

TEST_F(StreamLimitTest, ClientIsItsTokenWhenTokensAreChecked) {
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(Config("127.0.0.1:0", true));
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  // Both clients share one channel (and address): only the token tells them apart.
  auto stub = v1::PoseService::NewStub(grpc::CreateChannel(
      "127.0.0.1:" + std::to_string((*daemon)->port()), grpc::InsecureChannelCredentials()));
  ExpectLimitPerClient(stub.get(), kTokenA, stub.get(), kTokenB);
  (*daemon)->Shutdown();
}

TEST_F(StreamLimitTest, ClientIsItsAddressWithoutTokens) {
  // Two addresses of this machine: 127.0.0.1 and ::1 (the daemon listens on both).
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(Config("[::]:0", false));
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  const std::string port = std::to_string((*daemon)->port());
  auto v4 = v1::PoseService::NewStub(
      grpc::CreateChannel("ipv4:127.0.0.1:" + port, grpc::InsecureChannelCredentials()));
  auto v6 = v1::PoseService::NewStub(
      grpc::CreateChannel("ipv6:[::1]:" + port, grpc::InsecureChannelCredentials()));
  {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + 5s);
    v1::GetStatusResponse st;
    if (!v6->GetStatus(&ctx, v1::GetStatusRequest(), &st).ok()) {
      (*daemon)->Shutdown();
      GTEST_SKIP() << "no IPv6 loopback (::1) on this machine";
    }
  }
  // Streams from two channels of one address count together.
  auto v4_again = v1::PoseService::NewStub(
      grpc::CreateChannel("ipv4:127.0.0.1:" + port, grpc::InsecureChannelCredentials()));
  OpenStream one = Open(v4.get(), "");
  ASSERT_TRUE(one.got_estimate);
  OpenStream two = Open(v4_again.get(), "");
  ASSERT_TRUE(two.got_estimate);
  OpenStream three = Open(v4.get(), "");
  EXPECT_FALSE(three.got_estimate);
  EXPECT_EQ(three.reader->Finish().error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  Close(&one);
  Close(&two);
  ExpectLimitPerClient(v4.get(), "", v6.get(), "");
  (*daemon)->Shutdown();
}

}  // namespace
}  // namespace hpose::server
