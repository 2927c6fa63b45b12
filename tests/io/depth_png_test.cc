#include "core/io/depth_png.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <gtest/gtest.h>

#include "tests/io/temp_dir.h"

namespace hpose {
namespace {

DepthImage Gradient(int w, int h) {
  DepthImage depth(w, h);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u)
      depth.at(u, v) = static_cast<std::uint16_t>(400 + 37 * u + 1009 * v);
  }
  depth.at(0, 0) = 0;              // no reading.
  depth.at(w - 1, h - 1) = 65535;  // full 16-bit range.
  return depth;
}

std::string EncodePng(const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  EXPECT_TRUE(cv::imencode(".png", image, bytes));
  return std::string(bytes.begin(), bytes.end());
}

TEST(DepthPngTest, RoundTripsExactly) {
  TempDir dir;
  const DepthImage depth = Gradient(64, 48);
  const std::string path = dir.File("depth.png");
  ASSERT_TRUE(WriteDepthPng(depth, path).ok());
  const Result<DepthImage> back = ReadDepthPng(path);
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(back->width, 64);
  EXPECT_EQ(back->height, 48);
  EXPECT_EQ(back->mm, depth.mm);
}

TEST(DepthPngTest, ReadsA16BitPngWrittenByAnotherTool) {
  TempDir dir;
  cv::Mat image(3, 5, CV_16UC1, cv::Scalar(0));
  image.at<std::uint16_t>(2, 4) = 1234;  // row 2, column 4.
  const std::string path = dir.Write("tum.png", EncodePng(image));
  const Result<DepthImage> depth = ReadDepthPng(path);
  ASSERT_TRUE(depth.ok()) << depth.error().ToString();
  EXPECT_EQ(depth->width, 5);
  EXPECT_EQ(depth->height, 3);
  EXPECT_EQ(depth->at(4, 2), 1234);
  EXPECT_EQ(depth->at(0, 0), 0);
}

TEST(DepthPngTest, MissingFileIsNotFound) {
  TempDir dir;
  const Result<DepthImage> depth = ReadDepthPng(dir.File("nope.png"));
  ASSERT_FALSE(depth.ok());
  EXPECT_EQ(depth.error().code, ErrorCode::kNotFound);
  EXPECT_NE(depth.error().message.find("nope.png"), std::string::npos);
}

TEST(DepthPngTest, GarbageAndEmptyFilesAreDataLoss) {
  TempDir dir;
  for (const std::string& bytes : {std::string("this is not an image at all"), std::string()}) {
    const Result<DepthImage> depth = ReadDepthPng(dir.Write("bad.png", bytes));
    ASSERT_FALSE(depth.ok());
    EXPECT_EQ(depth.error().code, ErrorCode::kDataLoss);
    EXPECT_NE(depth.error().message.find("bad.png"), std::string::npos);
  }
}

TEST(DepthPngTest, TruncatedPngIsDataLoss) {
  TempDir dir;
  const std::string path = dir.File("full.png");
  ASSERT_TRUE(WriteDepthPng(Gradient(64, 48), path).ok());
  const std::string bytes = Slurp(path);
  for (const size_t keep : {size_t{8}, size_t{40}, bytes.size() / 2, bytes.size() - 20}) {
    const Result<DepthImage> depth = ReadDepthPng(dir.Write("cut.png", bytes.substr(0, keep)));
    ASSERT_FALSE(depth.ok()) << "kept " << keep << " of " << bytes.size();
    EXPECT_EQ(depth.error().code, ErrorCode::kDataLoss) << depth.error().ToString();
  }
}

TEST(DepthPngTest, EightBitAndColourPngsAreInvalidArgument) {
  TempDir dir;
  Result<DepthImage> depth =
      ReadDepthPng(dir.Write("grey8.png", EncodePng(cv::Mat(4, 4, CV_8UC1, cv::Scalar(7)))));
  ASSERT_FALSE(depth.ok());
  EXPECT_EQ(depth.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(depth.error().message.find("16-bit"), std::string::npos) << depth.error().message;
  depth =
      ReadDepthPng(dir.Write("rgb.png", EncodePng(cv::Mat(4, 4, CV_8UC3, cv::Scalar(1, 2, 3)))));
  ASSERT_FALSE(depth.ok());
  EXPECT_EQ(depth.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(depth.error().message.find("channel"), std::string::npos) << depth.error().message;
  depth =
      ReadDepthPng(dir.Write("rgb16.png", EncodePng(cv::Mat(4, 4, CV_16UC3, cv::Scalar(1, 2, 3)))));
  ASSERT_FALSE(depth.ok());
  EXPECT_EQ(depth.error().code, ErrorCode::kInvalidArgument);
}

TEST(DepthPngTest, WriteRejectsInconsistentImages) {
  TempDir dir;
  DepthImage depth(4, 4);
  depth.mm.resize(3);
  const Status status = WriteDepthPng(depth, dir.File("x.png"));
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().code, ErrorCode::kInvalidArgument);
  EXPECT_FALSE(WriteDepthPng(DepthImage(), dir.File("y.png")).ok());
}

}  // namespace
}  // namespace hpose
