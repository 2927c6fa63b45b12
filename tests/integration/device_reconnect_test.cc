// A live OpenNI2 device that disappears: the daemon keeps answering, marks the last estimate
// stale with the reason, retries with back-off and resumes when the device is back. The device
// is our simulated-depth OpenNI2 driver, told to unplug itself after a few frames.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/daemon.h"
#include "tests/integration/test_util.h"

namespace hpose::server {
namespace {

using namespace std::chrono_literals;
namespace tu = hpose::testing_util;

TEST(DeviceReconnectTest, LostDeviceIsRetriedWhileTheDaemonServes) {
  const std::string dir = tu::MakeTempDir("reconnect");
  ASSERT_TRUE(tu::SimulateFrames(dir, 2));
  setenv("HPOSE_SIM_DEPTH_DIR", dir.c_str(), 1);
  setenv("HPOSE_SIM_DEPTH_FPS", "10", 1);
  setenv("HPOSE_SIM_DEPTH_DISCONNECT_AFTER", "8", 1);  // unplugged after 8 frames ...
  setenv("HPOSE_SIM_DEPTH_OFFLINE_MS", "2500", 1);     // ... for 2.5 s, then back.

  DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.source.path = "openni2://";
  // The camera's own intrinsics (OpenNI2 would only give a field of view).
  config.source.intrinsics = dir + "/intrinsics.json";
  config.source.frame_timeout_s = 1.0;
  config.source.reconnect_initial_backoff_s = 0.2;
  config.source.reconnect_max_backoff_s = 0.8;
  config.templates = {tu::TemplatePath("standing")};
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  auto stub = v1::PoseService::NewStub(grpc::CreateChannel(
      "127.0.0.1:" + std::to_string((*daemon)->port()), grpc::InsecureChannelCredentials()));

  auto status = [&] {
    grpc::ClientContext ctx;
    v1::GetStatusResponse st;
    EXPECT_TRUE(stub->GetStatus(&ctx, v1::GetStatusRequest(), &st).ok());
    return st;
  };
  // 1. Running, then lost: the status says why.
  bool saw_reconnecting = false;
  std::string reason;
  for (int i = 0; i < 400 && !saw_reconnecting; ++i) {
    const v1::GetStatusResponse st = status();
    if (st.source().state() == v1::SOURCE_STATE_RECONNECTING) {
      saw_reconnecting = true;
      reason = st.source().state_reason();
    }
    std::this_thread::sleep_for(50ms);
  }
  ASSERT_TRUE(saw_reconnecting);
  EXPECT_FALSE(reason.empty());
  // 2. Meanwhile the daemon answers, and the last estimate (if any) is stale.
  {
    grpc::ClientContext ctx;
    v1::GetLatestResponse latest;
    grpc::Status s = stub->GetLatest(&ctx, v1::GetLatestRequest(), &latest);
    if (s.ok()) {
      EXPECT_TRUE(latest.estimate().stale());
      EXPECT_FALSE(latest.estimate().stale_reason().empty());
    } else {
      EXPECT_EQ(s.error_code(), grpc::StatusCode::UNAVAILABLE);  // nothing estimated yet.
    }
  }
  // 3. The device comes back and frames flow again.
  bool resumed = false;
  for (int i = 0; i < 600 && !resumed; ++i) {
    const v1::GetStatusResponse st = status();
    resumed = st.source().state() == v1::SOURCE_STATE_RUNNING && st.source().reconnects() >= 1;
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_TRUE(resumed);
  // 4. Estimates after the reconnection carry a new source epoch: the device's clock restarted.
  {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + 60s);
    v1::GetLatestRequest request;
    request.set_after_sequence(8);  // the device was unplugged after 8 frames.
    v1::GetLatestResponse latest;
    grpc::Status s = stub->GetLatest(&ctx, request, &latest);
    ASSERT_TRUE(s.ok()) << s.error_message();
    EXPECT_GE(latest.estimate().source_epoch(), 1u);
    EXPECT_FALSE(latest.estimate().has_error()) << latest.estimate().error().message();
  }
  (*daemon)->Shutdown();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hpose::server
