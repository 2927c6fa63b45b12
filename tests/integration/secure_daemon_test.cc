// TLS, mutual TLS and bearer tokens: certificates are made by `openssl` in the test. Without a
// token a call is UNAUTHENTICATED, a read-only token cannot estimate (PERMISSION_DENIED), a
// plaintext client cannot talk to a TLS daemon, and a daemon refuses a non-loopback address
// without TLS unless told it is insecure on purpose.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "core/io/atomic_file.h"
#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/daemon.h"
#include "tests/integration/daemon_fixture.h"
#include "tests/integration/test_util.h"

namespace hpose::server {
namespace {

using namespace std::chrono_literals;
namespace tu = hpose::testing_util;

constexpr char kReadToken[] = "read-token-0123456789abcdef";
constexpr char kEstimateToken[] = "estimate-token-0123456789abcdef";

// A CA, a server certificate for 127.0.0.1 / localhost and a client certificate, all signed by
// the CA, written into `dir`. True on success.
bool MakeCertificates(const std::string& dir) {
  const std::string d = "'" + dir + "'";
  const std::string quiet = " > /dev/null 2>&1";
  const std::string ext = dir + "/server.ext";
  std::ofstream(ext) << "subjectAltName=IP:127.0.0.1,DNS:localhost\n";
  const std::string cmds[] = {
      "openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=hpose-test-ca -keyout " + d +
          "/ca.key -out " + d + "/ca.pem",
      "openssl req -newkey rsa:2048 -nodes -subj /CN=localhost -keyout " + d + "/server.key -out " +
          d + "/server.csr",
      "openssl x509 -req -in " + d + "/server.csr -CA " + d + "/ca.pem -CAkey " + d +
          "/ca.key -CAcreateserial -days 2 -extfile " + d + "/server.ext -out " + d + "/server.pem",
      "openssl req -newkey rsa:2048 -nodes -subj /CN=hpose-client -keyout " + d +
          "/client.key -out " + d + "/client.csr",
      "openssl x509 -req -in " + d + "/client.csr -CA " + d + "/ca.pem -CAkey " + d +
          "/ca.key -CAcreateserial -days 2 -out " + d + "/client.pem",
  };
  for (const std::string& c : cmds) {
    if (tu::RunCommand(c + quiet) != 0) return false;
  }
  return true;
}

std::string Slurp(const std::string& path) { return ReadFile(path).ok() ? *ReadFile(path) : ""; }

class SecureDaemonTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(tu::MakeTempDir("secure"));
    ASSERT_TRUE(MakeCertificates(*dir_)) << "openssl failed";
    ASSERT_TRUE(tu::SimulateFrames(*dir_ + "/frames", 2));
    std::ofstream(*dir_ + "/tokens") << "# test tokens\n"
                                     << kReadToken << " read\n"
                                     << kEstimateToken << " estimate\n";
  }
  static void TearDownTestSuite() {
    if (dir_ != nullptr) std::filesystem::remove_all(*dir_);
    delete dir_;
  }

  static DaemonConfig SecureConfig(bool mutual) {
    DaemonConfig config;
    config.grpc.listen = "127.0.0.1:0";
    config.templates = {tu::TemplatePath("standing")};
    config.security.tls_cert = *dir_ + "/server.pem";
    config.security.tls_key = *dir_ + "/server.key";
    if (mutual) config.security.tls_client_ca = *dir_ + "/ca.pem";
    config.security.tokens_file = *dir_ + "/tokens";
    return config;
  }

  static std::shared_ptr<grpc::ChannelCredentials> TlsCredentials(bool with_client_cert) {
    grpc::SslCredentialsOptions options;
    options.pem_root_certs = Slurp(*dir_ + "/ca.pem");
    if (with_client_cert) {
      options.pem_private_key = Slurp(*dir_ + "/client.key");
      options.pem_cert_chain = Slurp(*dir_ + "/client.pem");
    }
    return grpc::SslCredentials(options);
  }

  static std::unique_ptr<v1::PoseService::Stub> Connect(
      const Daemon& daemon, std::shared_ptr<grpc::ChannelCredentials> creds) {
    return v1::PoseService::NewStub(
        grpc::CreateChannel("localhost:" + std::to_string(daemon.port()), creds));
  }

  static void Prepare(grpc::ClientContext* ctx, const std::string& token) {
    ctx->set_deadline(std::chrono::system_clock::now() + 30s);
    if (!token.empty()) ctx->AddMetadata("authorization", "Bearer " + token);
  }

  static grpc::Status GetStatus(v1::PoseService::Stub* stub, const std::string& token) {
    grpc::ClientContext ctx;
    Prepare(&ctx, token);
    v1::GetStatusResponse response;
    return stub->GetStatus(&ctx, v1::GetStatusRequest(), &response);
  }

  static grpc::Status Estimate(v1::PoseService::Stub* stub, const std::string& token) {
    const v1::EstimateRequest request = tu::FrameRequest(*dir_ + "/frames");
    grpc::ClientContext ctx;
    Prepare(&ctx, token);
    v1::EstimateResponse response;
    return stub->Estimate(&ctx, request, &response);
  }

  static grpc::Status Stream(v1::PoseService::Stub* stub, const std::string& token) {
    grpc::ClientContext ctx;
    Prepare(&ctx, token);
    ctx.set_deadline(std::chrono::system_clock::now() + 5s);
    v1::StreamPosesRequest request;
    request.set_max_estimates(1);
    auto reader = stub->StreamPoses(&ctx, request);
    v1::PoseEstimate e;
    while (reader->Read(&e)) {
    }
    return reader->Finish();
  }

  static std::string* dir_;
};
std::string* SecureDaemonTest::dir_ = nullptr;

TEST_F(SecureDaemonTest, TokensAndRolesOnEveryCall) {
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(SecureConfig(/*mutual=*/false));
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  auto stub = Connect(**daemon, TlsCredentials(false));

  grpc::Status s = GetStatus(stub.get(), "");
  EXPECT_EQ(s.error_code(), grpc::StatusCode::UNAUTHENTICATED) << s.error_message();
  s = GetStatus(stub.get(), "not-a-known-token-0123456789");
  EXPECT_EQ(s.error_code(), grpc::StatusCode::UNAUTHENTICATED) << s.error_message();
  s = Estimate(stub.get(), "");
  EXPECT_EQ(s.error_code(), grpc::StatusCode::UNAUTHENTICATED) << s.error_message();
  // Streams are checked too (before anything is sent).
  s = Stream(stub.get(), "");
  EXPECT_EQ(s.error_code(), grpc::StatusCode::UNAUTHENTICATED) << s.error_message();

  // A read-only token reads but cannot estimate.
  s = GetStatus(stub.get(), kReadToken);
  EXPECT_TRUE(s.ok()) << s.error_message();
  s = Estimate(stub.get(), kReadToken);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::PERMISSION_DENIED) << s.error_message();
  // A token differing in its last character only is still unknown.
  std::string almost = kEstimateToken;
  almost.back() = 'x';
  s = Estimate(stub.get(), almost);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::UNAUTHENTICATED) << s.error_message();

  s = Estimate(stub.get(), kEstimateToken);
  EXPECT_TRUE(s.ok()) << s.error_message();
  s = GetStatus(stub.get(), kEstimateToken);
  EXPECT_TRUE(s.ok()) << s.error_message();
}

// `hpose query` takes the same options.
TEST_F(SecureDaemonTest, QueryCommandSpeaksTlsWithTokens) {
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(SecureConfig(/*mutual=*/true));
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  std::ofstream(*dir_ + "/my_token") << kReadToken << "\n";
  const std::string base = tu::HposeProgram() + " query --timeout 20 --server localhost:" +
                           std::to_string((*daemon)->port()) + " --tls-ca '" + *dir_ +
                           "/ca.pem' --tls-cert '" + *dir_ + "/client.pem' --tls-key '" + *dir_ +
                           "/client.key'";
  std::string out;
  EXPECT_EQ(tu::RunCommand(base + " --token-file '" + *dir_ + "/my_token' status 2>&1", &out), 0)
      << out;
  out.clear();
  EXPECT_NE(tu::RunCommand(base + " status 2>&1", &out), 0);
  EXPECT_NE(out.find("bearer token"), std::string::npos) << out;
  out.clear();
  EXPECT_NE(tu::RunCommand(base + " --token-file '" + *dir_ + "/my_token' estimate '" + *dir_ +
                               "/frames/depth_000.png' 2>&1",
                           &out),
            0);
  EXPECT_NE(out.find("read-only"), std::string::npos) << out;
}

TEST_F(SecureDaemonTest, PlaintextClientCannotTalkToATlsDaemon) {
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(SecureConfig(/*mutual=*/false));
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  auto plain = Connect(**daemon, grpc::InsecureChannelCredentials());
  const grpc::Status s = GetStatus(plain.get(), kReadToken);
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.error_code(), grpc::StatusCode::UNAVAILABLE) << s.error_message();
}

// `hpose query` without --tls-ca cannot connect to a TLS daemon: after a second it says what it
// waits for, and at its deadline what to check, with the unavailable exit status.
TEST_F(SecureDaemonTest, PlaintextQuerySaysWhatItWaitsForAndWhatToCheck) {
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(SecureConfig(/*mutual=*/false));
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  const std::string server = "127.0.0.1:" + std::to_string((*daemon)->port());
  std::string out;
  EXPECT_EQ(
      tu::RunCommand(
          tu::HposeProgram() + " query --timeout 1.5 --server " + server + " status 2>&1", &out),
      5)
      << out;
  EXPECT_NE(out.find("waiting for hposed at " + server + " (up to 1.5 s"), std::string::npos)
      << out;
  EXPECT_NE(out.find("cannot reach hposed at " + server + " within 1.5 s: is it running there?"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("needs --tls-ca"), std::string::npos) << out;
}

TEST_F(SecureDaemonTest, MutualTlsNeedsAClientCertificate) {
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(SecureConfig(/*mutual=*/true));
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  auto without = Connect(**daemon, TlsCredentials(false));
  EXPECT_FALSE(GetStatus(without.get(), kReadToken).ok());
  auto with = Connect(**daemon, TlsCredentials(true));
  const grpc::Status s = GetStatus(with.get(), kReadToken);
  EXPECT_TRUE(s.ok()) << s.error_message();
}

TEST_F(SecureDaemonTest, NonLoopbackWithoutTlsIsRefused) {
  DaemonConfig config;
  config.grpc.listen = "0.0.0.0:0";
  config.templates = {tu::TemplatePath("standing")};
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
  ASSERT_FALSE(daemon.ok());
  EXPECT_NE(daemon.error().message.find("without TLS"), std::string::npos)
      << daemon.error().message;
  EXPECT_NE(daemon.error().message.find("--insecure"), std::string::npos);
  // Said on purpose, it starts; with TLS, it starts.
  config.security.insecure = true;
  daemon = Daemon::Start(config);
  EXPECT_TRUE(daemon.ok()) << daemon.error().ToString();
  DaemonConfig tls = SecureConfig(false);
  tls.grpc.listen = "0.0.0.0:0";
  daemon = Daemon::Start(tls);
  EXPECT_TRUE(daemon.ok()) << daemon.error().ToString();
}

TEST_F(SecureDaemonTest, BadTokenFilesAreRefusedAtStart) {
  DaemonConfig config = SecureConfig(false);
  config.security.tokens_file = *dir_ + "/bad_tokens";
  std::ofstream(config.security.tokens_file) << "short read\n";
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
  ASSERT_FALSE(daemon.ok());
  EXPECT_NE(daemon.error().message.find("bad_tokens:1"), std::string::npos)
      << daemon.error().message;
  std::ofstream(config.security.tokens_file) << "long-enough-token-0123456789 admin\n";
  daemon = Daemon::Start(config);
  ASSERT_FALSE(daemon.ok());
  EXPECT_NE(daemon.error().message.find("unknown role 'admin'"), std::string::npos)
      << daemon.error().message;
}

}  // namespace
}  // namespace hpose::server
