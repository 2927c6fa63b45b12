// What the in-process daemon tests share: a daemon on loopback over simulated frames in a
// temporary directory, kept for a whole test suite, and Estimate requests made from such frames.
#ifndef HPOSE_TESTS_INTEGRATION_DAEMON_FIXTURE_H_
#define HPOSE_TESTS_INTEGRATION_DAEMON_FIXTURE_H_

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <system_error>
#include <utility>

#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "hpose/v1/pose_service.pb.h"
#include "server/daemon.h"
#include "server/proto_convert.h"
#include "tests/integration/test_util.h"

namespace hpose::testing_util {

// Frame `index` of a directory `hpose simulate` wrote (depth_NNN.png and intrinsics.json) as an
// Estimate request; an empty request, after a test failure naming the file, if it cannot be read.
inline v1::EstimateRequest FrameRequest(const std::string& frames, int index = 0) {
  char name[32];
  std::snprintf(name, sizeof(name), "/depth_%03d.png", index);
  v1::EstimateRequest request;
  Result<DepthImage> depth = ReadDepthPng(frames + name);
  Result<Intrinsics> k = ReadIntrinsicsJson(frames + "/intrinsics.json");
  if (!depth.ok() || !k.ok()) {
    ADD_FAILURE() << (depth.ok() ? k.error().ToString() : depth.error().ToString());
    return request;
  }
  server::DepthToProto(*depth, *k, request.mutable_depth());
  return request;
}

// Settings (SuiteDaemon::Configure) for a daemon that estimates its simulated frames over and
// over at 10 frames/s, with both shipped templates.
inline void LoopTheFrames(const std::string& dir, server::DaemonConfig* config) {
  config->source.path = dir + "/frames";
  config->source.loop = true;
  config->source.fps = 10.0;
  config->templates = {TemplatePath("standing"), TemplatePath("right_arm_raised")};
}

// A daemon listening on 127.0.0.1 (a free port) over simulated frames in a temporary directory;
// the directory goes when the daemon does.
class SuiteDaemon {
 public:
  struct Options {
    std::string tag;      // names the temporary directory.
    int frames = 2;       // simulated 320x240 frames in dir()/frames.
    bool clouds = false;  // with cloud_NNN.pcd beside the depth images.
  };
  // Completes the daemon's settings; `dir` is the temporary directory.
  using Configure = std::function<void(const std::string& dir, server::DaemonConfig*)>;

  // The frames, then the daemon; nullptr, after a test failure saying why, if either fails.
  static std::unique_ptr<SuiteDaemon> Start(const Options& options, const Configure& configure) {
    std::unique_ptr<SuiteDaemon> suite(new SuiteDaemon(MakeTempDir(options.tag)));
    if (suite->dir_.empty()) {
      ADD_FAILURE() << "cannot make a temporary directory";
      return nullptr;
    }
    if (!SimulateFrames(suite->frames(), options.frames, "", options.clouds)) {
      ADD_FAILURE() << "hpose simulate failed";
      return nullptr;
    }
    server::DaemonConfig config;
    config.grpc.listen = "127.0.0.1:0";
    configure(suite->dir_, &config);
    Result<std::unique_ptr<server::Daemon>> daemon = server::Daemon::Start(config);
    if (!daemon.ok()) {
      ADD_FAILURE() << daemon.error().ToString();
      return nullptr;
    }
    suite->daemon_ = std::move(*daemon);
    return suite;
  }

  ~SuiteDaemon() {
    daemon_.reset();  // stops it before its frames go.
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }
  SuiteDaemon(const SuiteDaemon&) = delete;
  SuiteDaemon& operator=(const SuiteDaemon&) = delete;

  const std::string& dir() const { return dir_; }
  std::string frames() const { return dir_ + "/frames"; }
  server::Daemon& daemon() const { return *daemon_; }

 private:
  explicit SuiteDaemon(std::string dir) : dir_(std::move(dir)) {}

  std::string dir_;
  std::unique_ptr<server::Daemon> daemon_;
};

}  // namespace hpose::testing_util

#endif  // HPOSE_TESTS_INTEGRATION_DAEMON_FIXTURE_H_
