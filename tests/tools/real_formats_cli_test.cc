// `hpose estimate` and `hpose replay` on the real Kinect frames of PCL's grabber sequences
// (../shared/data; skipped when absent): 16-bit TIFF, pclzf and single files, with times from
// the file names, and the note when Kinect v1 intrinsics are assumed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/tools/cli_test_util.h"

namespace hpose {
namespace {

using testing::CliRun;
using testing::RunHpose;
using testing::TempDir;

const std::string kGrabber = std::string(HPOSE_SHARED_DATA_DIR) + "/kinect/grabber_sequences/";
const std::string kNote = "note: no --intrinsics given; assuming Kinect v1 intrinsics";

class RealFormatsCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(kGrabber)) {
      GTEST_SKIP() << "PCL grabber sequences not found in " << kGrabber
                   << " (third-party data is optional)";
    }
  }
};

std::vector<nlohmann::json> JsonLines(const std::string& text) {
  std::vector<nlohmann::json> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(nlohmann::json::parse(line));
  return out;
}

TEST_F(RealFormatsCliTest, EstimateTakesTiffAndPclzf) {
  TempDir dir("real_formats_estimate");
  const std::string tiff = kGrabber + "tiff/frame_20121214T142255.814212_depth.tiff";
  CliRun run = RunHpose("estimate --depth '" + tiff + "' --json", dir);
  // Processed (a humanoid found or not), not refused as input.
  EXPECT_TRUE(run.exit_code == 0 || run.exit_code == 3) << run.exit_code << " " << run.err;
  EXPECT_NE(run.err.find(kNote), std::string::npos) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_NEAR(j.at("source_time").get<double>(), 1355494975.814212, 1e-5);
  EXPECT_TRUE(j.at("depth_template").at("floor").at("fitted").get<bool>());

  // The same frame with PCL's intrinsics given as a ROS camera_info YAML, and as the pclzf
  // with its .xml: no note, and the same floor.
  const std::string yaml = dir / "kinect.yaml";
  std::ofstream(yaml)
      << "image_width: 640\nimage_height: 480\n"
         "camera_matrix: {rows: 3, cols: 3, data: [525, 0, 320, 0, 525, 240, 0, 0, 1]}\n";
  run = RunHpose("estimate --depth '" + tiff + "' --intrinsics '" + yaml + "' --json", dir);
  EXPECT_TRUE(run.exit_code == 0 || run.exit_code == 3) << run.err;
  EXPECT_EQ(run.err.find(kNote), std::string::npos) << run.err;
  const nlohmann::json a = nlohmann::json::parse(run.out);
  run = RunHpose(
      "estimate --depth '" + kGrabber + "pclzf/frame_20121214T142255.814212_depth.pclzf' --json",
      dir);
  EXPECT_TRUE(run.exit_code == 0 || run.exit_code == 3) << run.err;
  EXPECT_EQ(run.err.find(kNote), std::string::npos) << run.err;
  const nlohmann::json b = nlohmann::json::parse(run.out);
  EXPECT_DOUBLE_EQ(a.at("depth_template").at("floor").at("height").get<double>(),
                   b.at("depth_template").at("floor").at("height").get<double>());
}

TEST_F(RealFormatsCliTest, ReplayDirectoriesAndSingleFilesWithFileNameTimes) {
  TempDir dir("real_formats_replay");
  for (const char* sub : {"tiff", "pclzf", "pcd"}) {
    const CliRun run = RunHpose("replay '" + kGrabber + sub + "' --no-progress", dir);
    ASSERT_EQ(run.exit_code, 0) << sub << ": " << run.err;
    const std::vector<nlohmann::json> lines = JsonLines(run.out);
    ASSERT_EQ(lines.size(), 3u) << sub;
    EXPECT_NEAR(lines[1].at("source_time").get<double>() - lines[0].at("source_time").get<double>(),
                0.254471, 1e-5)
        << sub;
  }
  const CliRun one =
      RunHpose("replay '" + kGrabber + "pcd/frame_20121214T142256.332395.pcd' --no-progress", dir);
  ASSERT_EQ(one.exit_code, 0) << one.err;
  const std::vector<nlohmann::json> lines = JsonLines(one.out);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NEAR(lines[0].at("source_time").get<double>(), 1355494976.332395, 1e-5);
}

}  // namespace
}  // namespace hpose
