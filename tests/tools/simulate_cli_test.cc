// End-to-end tests of `hpose simulate`: the files it writes parse and match the flags.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "core/common/pose2d.h"
#include "core/depth/floor_estimate.h"
#include "core/io/atomic_file.h"
#include "core/io/cloud_io.h"
#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "core/sim/humanoid_model.h"
#include "core/sim/sim_truth.h"
#include "tests/tools/cli_test_util.h"

namespace hpose {
namespace {

using testing::CliRun;
using testing::RunHpose;
using testing::TempDir;

SimTruth ReadTruth(const std::string& path) {
  const Result<std::string> text = ReadFile(path);
  EXPECT_TRUE(text.ok()) << path;
  if (!text.ok()) return {};
  const Result<SimTruth> truth = ParseSimTruthJson(*text, path);
  EXPECT_TRUE(truth.ok()) << truth.error().ToString();
  return truth.ok() ? *truth : SimTruth{};
}

TEST(SimulateCliTest, WritesFilesThatParseAndMatchTheFlags) {
  TempDir dir("simulate_cli_files");
  const std::string out = dir / "scene";
  const CliRun run =
      RunHpose("simulate --out '" + out +
                   "' --x 1.5 --y 0.2 --theta-deg 120 --pose right_arm_raised --sensor-height 0.5 "
                   "--pitch-deg 8 --roll-deg 2 --clutter 3 --seed 9 --width 320 --height 240",
               dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;

  const Result<DepthImage> depth = ReadDepthPng(out + "/depth.png");
  ASSERT_TRUE(depth.ok()) << depth.error().ToString();
  EXPECT_EQ(depth->width, 320);
  EXPECT_EQ(depth->height, 240);
  size_t valid = 0;
  for (const std::uint16_t mm : depth->mm) {
    if (mm == 0) continue;
    ++valid;
    EXPECT_GE(mm, 800);
    EXPECT_LE(mm, 4000);
  }
  EXPECT_GT(valid, 10000u);

  const Result<Intrinsics> k = ReadIntrinsicsJson(out + "/intrinsics.json");
  ASSERT_TRUE(k.ok()) << k.error().ToString();
  const Intrinsics expected_k = Intrinsics::KinectV1(320, 240);
  EXPECT_EQ(k->width, 320);
  EXPECT_DOUBLE_EQ(k->fx, expected_k.fx);
  EXPECT_DOUBLE_EQ(k->cy, expected_k.cy);

  const SimTruth truth = ReadTruth(out + "/truth.json");
  EXPECT_DOUBLE_EQ(truth.humanoid_pose.x, 1.5);
  EXPECT_DOUBLE_EQ(truth.humanoid_pose.y, 0.2);
  EXPECT_NEAR(truth.humanoid_pose.theta, DegToRad(120.0), 1e-12);
  EXPECT_EQ(truth.humanoid_preset, "right_arm_raised");
  EXPECT_DOUBLE_EQ(truth.sensor_height_m, 0.5);
  EXPECT_NEAR(truth.sensor_pitch_rad, DegToRad(8.0), 1e-12);
  EXPECT_NEAR(truth.sensor_roll_rad, DegToRad(2.0), 1e-12);
  EXPECT_EQ(truth.intrinsics.height, 240);
  EXPECT_TRUE(truth.noise_enabled);
  EXPECT_EQ(truth.seed, 9u);
  EXPECT_EQ(truth.clutter.size(), 3u);
  ASSERT_EQ(truth.frames.size(), 1u);
  EXPECT_EQ(truth.frames[0].depth_file, "depth.png");
  EXPECT_EQ(truth.frames[0].cloud_file, "cloud.pcd");
  const auto model = HumanoidModel::FromPreset("right_arm_raised");
  ASSERT_TRUE(model.ok());
  EXPECT_NEAR(truth.humanoid_height_m, model->Height(), 1e-9);

  // The cloud is the depth image back-projected, organised; in the ground frame the humanoid
  // stands where the truth says.
  const Result<PointCloud> cloud = ReadCloud(out + "/cloud.pcd");
  ASSERT_TRUE(cloud.ok()) << cloud.error().ToString();
  EXPECT_EQ(cloud->width, 320);
  EXPECT_EQ(cloud->height, 240);
  const FloorEstimate floor = FloorEstimate::FromHeightPitchRoll(
      truth.sensor_height_m, truth.sensor_pitch_rad, truth.sensor_roll_rad);
  size_t finite = 0;
  size_t on_humanoid = 0;
  double top = 0.0;
  for (const Eigen::Vector3f& p : cloud->points) {
    if (!p.allFinite()) continue;
    ++finite;
    const Eigen::Vector3d g = floor.ground_from_sensor * p.cast<double>();
    if (g.z() > 0.05 && std::hypot(g.x() - 1.5, g.y() - 0.2) < 0.3) {
      ++on_humanoid;
      top = std::max(top, g.z());
    }
  }
  EXPECT_EQ(finite, valid);
  EXPECT_GT(on_humanoid, 1000u);
  EXPECT_NEAR(top, model->Height(), 0.06);
}

TEST(SimulateCliTest, FramesFollowTheTurnAndWalk) {
  TempDir dir("simulate_cli_frames");
  const std::string out = dir / "walk";
  const CliRun run = RunHpose("simulate --out '" + out +
                                  "' --frames 3 --turn-deg 30 --step-m 0.1 --no-noise "
                                  "--no-cloud --width 160 --height 120",
                              dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const SimTruth truth = ReadTruth(out + "/truth.json");
  ASSERT_EQ(truth.frames.size(), 3u);
  EXPECT_FALSE(truth.noise_enabled);
  double x = 1.0;
  double y = 0.0;
  for (int i = 0; i < 3; ++i) {
    const SimFrameTruth& f = truth.frames[i];
    EXPECT_EQ(f.index, i);
    const double theta = DegToRad(30.0 * i);
    EXPECT_NEAR(f.humanoid_pose.theta, theta, 1e-12) << i;
    EXPECT_NEAR(f.humanoid_pose.x, x, 1e-12) << i;
    EXPECT_NEAR(f.humanoid_pose.y, y, 1e-12) << i;
    x += 0.1 * std::cos(theta);
    y += 0.1 * std::sin(theta);
    EXPECT_TRUE(ReadDepthPng(out + "/" + f.depth_file).ok()) << f.depth_file;
    EXPECT_TRUE(f.cloud_file.empty());
  }
  EXPECT_EQ(truth.frames[2].depth_file, "depth_002.png");
  EXPECT_FALSE(std::filesystem::exists(out + "/cloud_000.pcd"));
}

TEST(SimulateCliTest, SeedReproducesTheFrame) {
  TempDir dir("simulate_cli_seed");
  const std::string common = " --clutter 4 --width 160 --height 120 --no-cloud";
  ASSERT_EQ(RunHpose("simulate --out '" + (dir / "a") + "' --seed 5" + common, dir).exit_code, 0);
  ASSERT_EQ(RunHpose("simulate --out '" + (dir / "b") + "' --seed 5" + common, dir).exit_code, 0);
  ASSERT_EQ(RunHpose("simulate --out '" + (dir / "c") + "' --seed 6" + common, dir).exit_code, 0);
  const Result<DepthImage> a = ReadDepthPng(dir / "a/depth.png");
  const Result<DepthImage> b = ReadDepthPng(dir / "b/depth.png");
  const Result<DepthImage> c = ReadDepthPng(dir / "c/depth.png");
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  EXPECT_EQ(a->mm, b->mm);
  EXPECT_NE(a->mm, c->mm);
}

// --noise-correlation: neighbouring readings of the same surfaces differ less than with every
// pixel's noise its own (same seed, same scene), and truth.json says which noise was drawn.
TEST(SimulateCliTest, NoiseCorrelationMakesNeighbouringReadingsAlike) {
  TempDir dir("simulate_cli_correlated");
  const std::string common =
      " --seed 5 --x 3 --sensor-height 1.3 --pitch-deg 5 --width 320 --height 240 --no-cloud";
  ASSERT_EQ(RunHpose("simulate --out '" + (dir / "own") + "'" + common, dir).exit_code, 0);
  const CliRun run = RunHpose("simulate --out '" + (dir / "shared") +
                                  "' --noise-correlation 0.9 --noise-correlation-px 3" + common,
                              dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Result<DepthImage> own = ReadDepthPng(dir / "own/depth.png");
  const Result<DepthImage> shared = ReadDepthPng(dir / "shared/depth.png");
  ASSERT_TRUE(own.ok() && shared.ok());
  // Mean absolute difference of horizontal neighbours on the floor and the robot (both read,
  // less than 5 cm apart: no depth edge between them).
  const auto neighbour_step = [](const DepthImage& d) {
    double sum = 0.0;
    int n = 0;
    for (int v = 0; v < d.height; ++v) {
      for (int u = 0; u + 1 < d.width; ++u) {
        const int a = d.at(u, v), b = d.at(u + 1, v);
        if (a == 0 || b == 0 || std::abs(a - b) >= 50) continue;
        sum += std::abs(a - b);
        ++n;
      }
    }
    return n > 0 ? sum / n : 0.0;
  };
  const double own_step = neighbour_step(*own), shared_step = neighbour_step(*shared);
  EXPECT_GT(own_step, 0.0);
  EXPECT_LT(shared_step, 0.75 * own_step) << own_step << " mm vs " << shared_step << " mm";
  const SimTruth truth = ReadTruth(dir / "shared/truth.json");
  EXPECT_NEAR(truth.noise_correlated_share, 0.9, 1e-12);
  EXPECT_EQ(truth.noise_correlation_radius_px, 3);
  EXPECT_EQ(ReadTruth(dir / "own/truth.json").noise_correlated_share, 0.0);
}

TEST(SimulateCliTest, BadFlagsExitWithUsageStatus) {
  TempDir dir("simulate_cli_bad");
  const std::string out = dir / "never";
  for (const std::string bad :
       {"--sensor-height -1", "--pose dancing", "--frames 0", "--no-such-flag", "--x abc",
        "--pitch-deg 90", "--pitch-deg 85.5", "--clutter -2", "--width 5", "--second-at 1,2",
        "--x nan", "--noise-correlation 1.5", "--noise-correlation-px 0", "--theta-deg 1e300",
        "--second-at 30,0,0", "--second-at 1e300,0,90", "--second-at 2,0,1e9"}) {
    const CliRun run = RunHpose("simulate --out '" + out + "' " + bad, dir);
    EXPECT_EQ(run.exit_code, 2) << bad << ": " << run.err;
    EXPECT_FALSE(run.err.empty()) << bad;
    EXPECT_FALSE(std::filesystem::exists(out)) << bad;
  }
  const CliRun no_out = RunHpose("simulate --x 1", dir);
  EXPECT_EQ(no_out.exit_code, 2);
  EXPECT_NE(no_out.err.find("--out"), std::string::npos);
  const CliRun dancing = RunHpose("simulate --out '" + out + "' --pose dancing", dir);
  EXPECT_NE(dancing.err.find("dancing"), std::string::npos);
  const CliRun help = RunHpose("simulate --help", dir);
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("--sensor-height"), std::string::npos);
}

}  // namespace
}  // namespace hpose
