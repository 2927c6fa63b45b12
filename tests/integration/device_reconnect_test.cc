// A live OpenNI2 device that disappears: the daemon keeps answering, marks the last estimate
// stale with the reason, retries with back-off and resumes when the device is back; OpenNI2's
// drivers stay loaded meanwhile unless they only look for devices when loaded. The device is
// our simulated-depth OpenNI2 driver, told to unplug itself after a few frames or while a file
// exists.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <thread>

#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/daemon.h"
#include "server/openni2_source.h"
#include "tests/integration/test_util.h"

namespace hpose::server {
namespace {

using namespace std::chrono_literals;
namespace tu = hpose::testing_util;

// Calls `done` every 50 ms until it returns true (then true) or `limit` has passed.
bool WaitFor(const std::function<bool()>& done, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(50ms);
  }
  return done();
}

int CountLines(const std::string& path) {
  std::ifstream in(path);
  int n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

// hposed's config for the simulated device (openni2://, with the camera's own intrinsics:
// OpenNI2 would only give a field of view) and its retries.
DaemonConfig DeviceConfig(const std::string& intrinsics, double frame_timeout_s,
                          double initial_backoff_s, double max_backoff_s) {
  DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.source.path = "openni2://";
  config.source.intrinsics = intrinsics;
  config.source.frame_timeout_s = frame_timeout_s;
  config.source.reconnect_initial_backoff_s = initial_backoff_s;
  config.source.reconnect_max_backoff_s = max_backoff_s;
  config.templates = {tu::TemplatePath("standing")};
  return config;
}

std::unique_ptr<v1::PoseService::Stub> Connect(const Daemon& daemon) {
  return v1::PoseService::NewStub(grpc::CreateChannel("127.0.0.1:" + std::to_string(daemon.port()),
                                                      grpc::InsecureChannelCredentials()));
}

v1::GetStatusResponse ReadStatus(v1::PoseService::Stub& stub) {
  grpc::ClientContext ctx;
  v1::GetStatusResponse st;
  EXPECT_TRUE(stub.GetStatus(&ctx, v1::GetStatusRequest(), &st).ok());
  return st;
}

// The simulated device unplugged while a file exists, and a log of the driver's loads.
class Replug {
 public:
  explicit Replug(const std::string& dir) : dir_(dir) {
    setenv("HPOSE_SIM_DEPTH_DIR", (dir + "/frames").c_str(), 1);
    setenv("HPOSE_SIM_DEPTH_FPS", "30", 1);
    setenv("HPOSE_SIM_DEPTH_UNPLUGGED_FILE", (dir + "/unplugged").c_str(), 1);
    setenv("HPOSE_SIM_DEPTH_LOAD_LOG", (dir + "/loads").c_str(), 1);
  }
  ~Replug() {
    for (const char* name :
         {"HPOSE_SIM_DEPTH_DIR", "HPOSE_SIM_DEPTH_FPS", "HPOSE_SIM_DEPTH_UNPLUGGED_FILE",
          "HPOSE_SIM_DEPTH_LOAD_LOG", "HPOSE_SIM_DEPTH_NO_HOTPLUG"}) {
      unsetenv(name);
    }
    std::filesystem::remove_all(dir_);
  }
  void Unplug() const { std::ofstream(dir_ + "/unplugged") << "away\n"; }
  void PlugBack() const { std::filesystem::remove(dir_ + "/unplugged"); }
  int DriverLoads() const { return CountLines(dir_ + "/loads"); }

 private:
  std::string dir_;
};

// A device that comes back is reported by its driver (one that watches the bus, as PS1080's
// does): the source finds it again without OpenNI2 loading its drivers anew at every attempt
// (each load loses about 9 KB inside them).
TEST(DeviceReconnectTest, DeviceBackIsFoundByTheDriversStillLoaded) {
  const std::string dir = tu::MakeTempDir("replug");
  ASSERT_TRUE(tu::SimulateFrames(dir + "/frames", 2));
  Replug device(dir);
  Openni2SourceOptions options;
  options.device.frame_timeout_s = 5.0;  // the loss must come from the driver, not a timeout.
  options.device.driver_reload_interval_s = 600.0;
  Openni2Source source("openni2://", options);
  ASSERT_TRUE(source.Open().ok());
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(source.Next().ok());
  const auto unplugged = std::chrono::steady_clock::now();
  device.Unplug();
  Result<Frame> lost = source.Next();
  for (int i = 0; i < 30 && lost.ok(); ++i) lost = source.Next();
  ASSERT_FALSE(lost.ok());
  // Said by the driver at once, not found by waiting out the frame timeout.
  EXPECT_LT(std::chrono::steady_clock::now() - unplugged, 2500ms);
  EXPECT_EQ(lost.error().code, ErrorCode::kUnavailable);
  EXPECT_NE(lost.error().message.find("disconnected"), std::string::npos) << lost.error().message;
  source.Close();
  // Away: every attempt fails, saying so.
  for (int i = 0; i < 5; ++i) {
    const Status away = source.Open();
    ASSERT_FALSE(away.ok());
    EXPECT_EQ(away.error().code, ErrorCode::kUnavailable);
    EXPECT_NE(away.error().message.find("no OpenNI2 device found"), std::string::npos)
        << away.error().message;
    std::this_thread::sleep_for(50ms);
  }
  device.PlugBack();
  ASSERT_TRUE(WaitFor([&] { return source.Open().ok(); }, 10s));
  Result<Frame> back = source.Next();
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(back->epoch, 1u);  // a reconnection: the device's clock started over.
  source.Close();
  EXPECT_EQ(device.DriverLoads(), 1) << "OpenNI2 loaded its drivers once, for every attempt";
}

// A driver that looks for devices only when it loads (as libfreenect's does) never reports the
// device back; the daemon's source reloads the drivers every source.driver_reload_interval_s
// while it retries, and finds it. Without the driver's word the loss shows as frames that stop
// for source.frame_timeout_s.
TEST(DeviceReconnectTest, DriversThatLookOnlyWhenLoadedAreReloaded) {
  const std::string dir = tu::MakeTempDir("reload");
  ASSERT_TRUE(tu::SimulateFrames(dir + "/frames", 2));
  Replug device(dir);
  setenv("HPOSE_SIM_DEPTH_NO_HOTPLUG", "1", 1);

  DaemonConfig config = DeviceConfig(dir + "/frames/intrinsics.json", 0.7, 0.1, 0.2);
  config.source.driver_reload_interval_s = 1.0;
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  auto stub = Connect(**daemon);
  auto status = [&] { return ReadStatus(*stub).source(); };
  ASSERT_TRUE(WaitFor([&] { return status().frames_in() >= 3; }, 60s));
  device.Unplug();
  v1::SourceStatus away;
  ASSERT_TRUE(WaitFor(
      [&] {
        away = status();
        return away.state() == v1::SOURCE_STATE_RECONNECTING;
      },
      30s));
  EXPECT_NE(away.state_reason().find("no frame for 700 ms"), std::string::npos)
      << away.state_reason();
  std::this_thread::sleep_for(1500ms);  // attempts fail meanwhile, the drivers reloaded once.
  EXPECT_EQ(status().state(), v1::SOURCE_STATE_RECONNECTING);
  device.PlugBack();
  ASSERT_TRUE(WaitFor(
      [&] {
        const v1::SourceStatus s = status();
        return s.state() == v1::SOURCE_STATE_RUNNING && s.reconnects() >= 1;
      },
      30s));
  (*daemon)->Shutdown();
  EXPECT_GE(device.DriverLoads(), 2);
}

TEST(DeviceReconnectTest, LostDeviceIsRetriedWhileTheDaemonServes) {
  const std::string dir = tu::MakeTempDir("reconnect");
  ASSERT_TRUE(tu::SimulateFrames(dir, 2));
  setenv("HPOSE_SIM_DEPTH_DIR", dir.c_str(), 1);
  setenv("HPOSE_SIM_DEPTH_FPS", "10", 1);
  setenv("HPOSE_SIM_DEPTH_DISCONNECT_AFTER", "8", 1);  // unplugged after 8 frames ...
  setenv("HPOSE_SIM_DEPTH_OFFLINE_MS", "2500", 1);     // ... for 2.5 s, then back.

  Result<std::unique_ptr<Daemon>> daemon =
      Daemon::Start(DeviceConfig(dir + "/intrinsics.json", 1.0, 0.2, 0.8));
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  auto stub = Connect(**daemon);
  auto status = [&] { return ReadStatus(*stub); };
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
