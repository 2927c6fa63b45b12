// Real-data depth formats (16-bit TIFF and PCL's pclzf from PCL's Kinect grabber sequences in
// ../shared/data, skipped when absent), times in frame file names, and ROS camera_info YAML.
#include "core/io/depth_frame_io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/io/depth_png.h"
#include "core/io/frame_file_time.h"
#include "core/io/intrinsics_file.h"
#include "tests/io/temp_dir.h"

namespace hpose {
namespace {

const std::string kGrabber = std::string(HPOSE_SHARED_DATA_DIR) + "/kinect/grabber_sequences/";
const std::string kFrame = "frame_20121214T142255.814212";

bool HaveGrabberData() {
  return std::filesystem::exists(kGrabber + "tiff/" + kFrame + "_depth.tiff");
}

#define SKIP_WITHOUT_GRABBER_DATA()                                 \
  if (!HaveGrabberData())                                           \
  GTEST_SKIP() << "PCL grabber sequences not found in " << kGrabber \
               << " (third-party data is optional)"

TEST(DepthFrameIoTest, TiffAndPclzfOfOneFrameAgreeAndMatchTheCloud) {
  SKIP_WITHOUT_GRABBER_DATA();
  Result<DepthFrameFile> tiff = ReadDepthFrame(kGrabber + "tiff/" + kFrame + "_depth.tiff");
  ASSERT_TRUE(tiff.ok()) << tiff.error().ToString();
  EXPECT_EQ(tiff->depth.width, 640);
  EXPECT_EQ(tiff->depth.height, 480);
  EXPECT_FALSE(tiff->has_intrinsics);

  Result<DepthFrameFile> lzf = ReadDepthFrame(kGrabber + "pclzf/" + kFrame + "_depth.pclzf");
  ASSERT_TRUE(lzf.ok()) << lzf.error().ToString();
  ASSERT_TRUE(lzf->has_intrinsics);
  EXPECT_DOUBLE_EQ(lzf->intrinsics.fx, 525.0);
  EXPECT_DOUBLE_EQ(lzf->intrinsics.cx, 320.0);
  EXPECT_DOUBLE_EQ(lzf->intrinsics.cy, 240.0);
  ASSERT_EQ(lzf->depth.width, 640);
  ASSERT_EQ(lzf->depth.height, 480);

  // The grabber saved the same frame in both formats: the same millimetres, pixel by pixel.
  size_t valid = 0, equal = 0;
  for (size_t i = 0; i < tiff->depth.mm.size(); ++i) {
    if (tiff->depth.mm[i] != 0) ++valid;
    if (tiff->depth.mm[i] == lzf->depth.mm[i]) ++equal;
  }
  EXPECT_GT(valid, tiff->depth.mm.size() / 2);
  EXPECT_EQ(equal, tiff->depth.mm.size());

  std::vector<std::uint16_t> sorted;
  for (std::uint16_t v : tiff->depth.mm) {
    if (v != 0) sorted.push_back(v);
  }
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median_mm = sorted[sorted.size() / 2];
  EXPECT_GT(median_mm, 500.0);  // a room seen by a Kinect: metres, not metres * 1000 or raw.
  EXPECT_LT(median_mm, 8000.0);
}

TEST(DepthFrameIoTest, ColourTiffIsRefusedWithAClearMessage) {
  SKIP_WITHOUT_GRABBER_DATA();
  Result<DepthFrameFile> rgb = ReadDepthFrame(kGrabber + "tiff/" + kFrame + "_rgb.tiff");
  ASSERT_FALSE(rgb.ok());
  EXPECT_EQ(rgb.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(rgb.error().message.find("_rgb.tiff"), std::string::npos);
  EXPECT_NE(rgb.error().message.find("16-bit"), std::string::npos) << rgb.error().message;
}

TEST(DepthFrameIoTest, PngStillReadsAndUnknownOrMissingFilesFail) {
  TempDir dir;
  DepthImage d(4, 3);
  d.at(1, 2) = 1234;
  const std::string png = dir.path() + "/f.png";
  ASSERT_TRUE(WriteDepthPng(d, png).ok());
  Result<DepthFrameFile> read = ReadDepthFrame(png);
  ASSERT_TRUE(read.ok());
  EXPECT_EQ(read->depth.at(1, 2), 1234);
  EXPECT_EQ(ReadDepthFrame(dir.path() + "/missing.tiff").error().code, ErrorCode::kNotFound);
  EXPECT_EQ(ReadDepthFrame(dir.path() + "/a.jpg").error().code, ErrorCode::kInvalidArgument);
  // A pclzf without its .xml names the .xml it looked for.
  std::ofstream(dir.path() + "/x_depth.pclzf") << "PCLZF";
  Result<DepthFrameFile> lzf = ReadDepthFrame(dir.path() + "/x_depth.pclzf");
  ASSERT_FALSE(lzf.ok());
  EXPECT_NE(lzf.error().message.find("x.xml"), std::string::npos) << lzf.error().message;
}

TEST(FrameFileTimeTest, ReadsGrabberAndSecondsNamesAndIgnoresCounters) {
  // 2012-12-14 14:22:55 UTC = 1355494975 s.
  std::optional<double> t = TimeFromFrameFileName("/data/frame_20121214T142255.814212.pcd");
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(*t, 1355494975.814212, 1e-6);
  std::optional<double> u = TimeFromFrameFileName("frame_20121214T142256.068683_depth.tiff");
  ASSERT_TRUE(u.has_value());
  EXPECT_NEAR(*u - *t, 0.254471, 1e-6);
  EXPECT_NEAR(TimeFromFrameFileName("1305031102.175304.png").value_or(-1), 1305031102.175304, 1e-6);
  EXPECT_NEAR(TimeFromFrameFileName("dir/0001.250_depth.tiff").value_or(-1), 1.25, 1e-9);
  EXPECT_FALSE(TimeFromFrameFileName("depth_000.png").has_value());
  // No clock's seconds: 400 digits (read as infinity) or beyond 1e11 s.
  EXPECT_FALSE(TimeFromFrameFileName(std::string(400, '9') + ".5.png").has_value());
  EXPECT_FALSE(TimeFromFrameFileName("200000000000.5.png").has_value());
  EXPECT_FALSE(TimeFromFrameFileName("12.png").has_value());
  EXPECT_FALSE(TimeFromFrameFileName("frame_20121314T142255.pcd").has_value());  // month 13.
}

TEST(IntrinsicsFileTest, RosCameraInfoYamlAndJson) {
  TempDir dir;
  const std::string calib = dir.path() + "/depth.yaml";
  std::ofstream(calib) << "image_width: 640\nimage_height: 480\ncamera_name: depth\n"
                          "camera_matrix:\n  rows: 3\n  cols: 3\n"
                          "  data: [570.3, 0, 314.5, 0, 570.1, 235.5, 0, 0, 1]\n"
                          "distortion_model: plumb_bob\n";
  Result<Intrinsics> k = ReadIntrinsicsFile(calib);
  ASSERT_TRUE(k.ok()) << k.error().ToString();
  EXPECT_EQ(k->width, 640);
  EXPECT_EQ(k->height, 480);
  EXPECT_DOUBLE_EQ(k->fx, 570.3);
  EXPECT_DOUBLE_EQ(k->fy, 570.1);
  EXPECT_DOUBLE_EQ(k->cx, 314.5);
  EXPECT_DOUBLE_EQ(k->cy, 235.5);

  const std::string msg = dir.path() + "/info.yml";  // a sensor_msgs/CameraInfo as YAML.
  std::ofstream(msg) << "height: 240\nwidth: 320\nK: [285, 0, 158, 0, 285, 121, 0, 0, 1]\n";
  Result<Intrinsics> m = ReadIntrinsicsFile(msg);
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  EXPECT_DOUBLE_EQ(m->cx, 158.0);

  const std::string bad = dir.path() + "/bad.yaml";
  std::ofstream(bad) << "image_width: 640\nimage_height: 480\ncamera_matrix: {data: [1, 2]}\n";
  Result<Intrinsics> b = ReadIntrinsicsFile(bad);
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message.find("camera_matrix"), std::string::npos) << b.error().message;
}

}  // namespace
}  // namespace hpose
