// End to end: a simulated recording that the depth sensor and the stereo head see at once, the
// depth sensor's placement calibrated from it with `hpose calibrate world-from-ground
// --recording`, then hposed running both estimators on it (loopback) and `hpose query stream
// --compare` showing how far apart the two estimators put the same robot point.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>

#include "core/common/pose2d.h"
#include "server/daemon.h"
#include "tests/integration/test_util.h"
#include "tests/sanitizer_build.h"

namespace hpose::server {
namespace {

namespace fs = std::filesystem;
namespace tu = hpose::testing_util;

// Where the simulated depth sensor stands in the landmarks' frame (`--depth-sensor`).
const Pose2D kTruePlacement{-1.1, -2.1, kPi / 4};

// The value after `key` in `text` (e.g. "median " -> 11.6), NaN when absent.
double NumberAfter(const std::string& text, const std::string& key) {
  const size_t at = text.find(key);
  if (at == std::string::npos) return std::nan("");
  return std::strtod(text.c_str() + at + key.size(), nullptr);
}

TEST(WorldFrameCompareTest, CalibratedPlacementMakesBothEstimatorsAgreeInTheDaemon) {
  HPOSE_SKIP_IF_SANITIZED();  // renders a 90-pair stereo recording, like the stereo daemon suite.
  const std::string dir = tu::MakeTempDir("world_compare");
  ASSERT_FALSE(dir.empty());
  const std::string rec = dir + "/rec";
  // The robot walks 0.72 m towards the landmarks in 9 s (10 stereo pairs/s, a depth frame
  // every 3rd pair); the depth sensor watches it from behind and to the side, 1.4-1.9 m away.
  std::string out;
  ASSERT_EQ(tu::RunCommand(tu::HposeProgram() + " simulate stereo --out '" + rec +
                               "' --scenario walking --frames 90 --fps 10 --speed 0.08 "
                               "--robot-y -1.35 --depth-sensor -1.1,-2.1,45 2>/dev/null",
                           &out),
            0)
      << out;

  // The placement from the recording alone.
  out.clear();
  ASSERT_EQ(tu::RunCommand(tu::HposeProgram() + " calibrate world-from-ground --recording '" + rec +
                               "' 2>/dev/null",
                           &out),
            0)
      << out;
  const Pose2D fitted{NumberAfter(out, "world_from_ground: x "), NumberAfter(out, "m, y "),
                      NumberAfter(out, "m, yaw ")};
  ASSERT_TRUE(std::isfinite(fitted.x + fitted.y + fitted.theta)) << out;
  EXPECT_LT(std::hypot(fitted.x - kTruePlacement.x, fitted.y - kTruePlacement.y), 0.02) << out;
  EXPECT_LT(std::abs(AngleDiff(fitted.theta, kTruePlacement.theta)), DegToRad(1.0)) << out;
  EXPECT_GE(NumberAfter(out, "pairs used "), 25) << out;

  // hposed with both estimators and the fitted placement, at the recorded rate.
  DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.source.path = rec + "/depth";
  config.templates = {tu::TemplatePath("standing"), tu::TemplatePath("right_arm_raised")};
  config.stereo.source = rec + "/stereo";
  // Both loop (they start over together); the client may connect a little after the start.
  config.source.loop = true;
  config.stereo.loop = true;
  config.world_from_ground = {true, fitted.x, fitted.y, fitted.theta};
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  out.clear();
  const int code = tu::RunCommand("timeout 60 " + tu::HposeProgram() +
                                      " query stream --compare --count 100 --server 127.0.0.1:" +
                                      std::to_string((*daemon)->port()),
                                  &out);
  daemon->reset();
  EXPECT_EQ(code, 0) << out;
  // Every diff line compares poses of one instant; the summary takes their median.
  int lines = 0;
  std::istringstream text(out);
  for (std::string line; std::getline(text, line);) {
    if (line.find(" diff ") == std::string::npos) continue;
    ++lines;
    EXPECT_NE(line.find("(same instant)"), std::string::npos) << line;
    EXPECT_LT(NumberAfter(line, " diff "), 80.0) << line;
  }
  const double pairs = NumberAfter(out, "compare: ");
  const double median_mm = NumberAfter(out, "position difference median ");
  EXPECT_GE(pairs, 10) << out;
  EXPECT_EQ(pairs, lines) << out;
  EXPECT_LE(median_mm, 30.0) << out;
  std::printf("calibrated placement: %.4f m, %.4f m, %.2f deg; query stream --compare: %s\n",
              fitted.x, fitted.y, RadToDeg(fitted.theta),
              out.substr(out.find("compare: ")).c_str());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace hpose::server
