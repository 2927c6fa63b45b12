// libpng reader and writer against OpenCV's PNG codec as the reference: the same pixels both
// ways, on simulated depth frames, real Kinect frames (../shared/data, skipped when absent)
// and every kind of PNG OpenCV writes; bounded and clear failures on hostile files.
#include "core/io/png_codec.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "core/io/depth_png.h"
#include "core/sim/frame_simulator.h"
#include "tests/io/cv_reference.h"
#include "tests/io/temp_dir.h"

namespace hpose {
namespace {

const std::string kGrabberTiffs =
    std::string(HPOSE_SHARED_DATA_DIR) + "/kinect/grabber_sequences/tiff/";

std::string CvEncode(const cv::Mat& mat, const std::vector<int>& params = {}) {
  std::vector<unsigned char> bytes;
  EXPECT_TRUE(cv::imencode(".png", mat, bytes, params));
  return std::string(bytes.begin(), bytes.end());
}

// Both directions for one image: OpenCV's file read by ReadPng, and EncodePng's file read by
// OpenCV, give OpenCV's pixels.
void ExpectAgreesWithOpenCv(const TempDir& dir, const cv::Mat& mat, const std::string& what) {
  const DecodedImage reference = FromMat(mat);
  const Result<DecodedImage> ours = ReadPng(dir.Write("cv.png", CvEncode(mat)));
  ASSERT_TRUE(ours.ok()) << what << ": " << ours.error().ToString();
  ExpectSameImage(*ours, reference, what + " written by OpenCV");

  for (int level : {0, 1, 9}) {
    const Result<std::string> encoded = EncodePng(reference, level);
    ASSERT_TRUE(encoded.ok()) << what << ": " << encoded.error().ToString();
    const cv::Mat back = cv::imread(dir.Write("ours.png", *encoded), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(back.empty()) << what << ": OpenCV cannot read our PNG";
    ExpectSameImage(FromMat(back), reference,
                    what + " written by EncodePng, level " + std::to_string(level));
  }
}

TEST(PngCodecTest, AgreesWithOpenCvOnEveryLayoutItWrites) {
  TempDir dir;
  unsigned seed = 1;
  for (int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    for (const cv::Size size : {cv::Size(1, 1), cv::Size(7, 3), cv::Size(640, 480)}) {
      ExpectAgreesWithOpenCv(dir, RandomMat(size.height, size.width, type, seed++),
                             "type " + std::to_string(type) + ", " + std::to_string(size.width) +
                                 "x" + std::to_string(size.height));
    }
  }
}

TEST(PngCodecTest, AgreesWithOpenCvOnSimulatedDepthFrames) {
  TempDir dir;
  for (int i = 0; i < 3; ++i) {
    FrameSpec spec;
    spec.clutter = 3;
    spec.seed = 11 + i;
    spec.humanoid_pose = Pose2D{1.0 + i, 0.2 * i, 0.7 * i};
    const Result<SimulatedFrame> frame = SimulateFrame(spec);
    ASSERT_TRUE(frame.ok()) << frame.error().ToString();
    const DepthImage& depth = frame->depth;
    const cv::Mat mat(depth.height, depth.width, CV_16UC1,
                      const_cast<std::uint16_t*>(depth.mm.data()));
    ExpectAgreesWithOpenCv(dir, mat, "simulated frame " + std::to_string(i));
    // The depth wrappers too: written by ours, read by OpenCV and by ours.
    const std::string path = dir.File("depth.png");
    ASSERT_TRUE(WriteDepthPng(depth, path).ok());
    const cv::Mat cv_back = cv::imread(path, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(cv_back.type(), CV_16UC1);
    EXPECT_EQ(cv::countNonZero(cv_back != mat), 0);
    const Result<DepthImage> back = ReadDepthPng(path);
    ASSERT_TRUE(back.ok()) << back.error().ToString();
    EXPECT_EQ(back->mm, depth.mm);
  }
}

TEST(PngCodecTest, AgreesWithOpenCvOnRealKinectFrames) {
  if (!std::filesystem::is_directory(kGrabberTiffs)) {
    GTEST_SKIP() << "Kinect frames not found in " << kGrabberTiffs << " (third-party data)";
  }
  TempDir dir;
  int frames = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kGrabberTiffs)) {
    const cv::Mat mat = cv::imread(entry.path().string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(mat.empty()) << entry.path();
    ExpectAgreesWithOpenCv(dir, mat, entry.path().filename().string());
    ++frames;
  }
  EXPECT_GE(frames, 2);
}

TEST(PngCodecTest, ExpandsOneBitGreyLikeOpenCv) {
  TempDir dir;
  cv::Mat mat = RandomMat(9, 13, CV_8UC1, 5) > 128;  // 0 or 255.
  const std::string path = dir.Write("bilevel.png", CvEncode(mat, {cv::IMWRITE_PNG_BILEVEL, 1}));
  const Result<DecodedImage> ours = ReadPng(path);
  ASSERT_TRUE(ours.ok()) << ours.error().ToString();
  ExpectSameImage(*ours, FromMat(cv::imread(path, cv::IMREAD_UNCHANGED)), "1-bit grey");
  ExpectSameImage(*ours, FromMat(mat), "1-bit grey against its source");
}

TEST(PngCodecTest, RefusesOversizedImagesBeforeDecoding) {
  TempDir dir;
  const std::string wide = dir.Write("wide.png", CvEncode(cv::Mat(2, 300, CV_8UC1, cv::Scalar(1))));
  const Result<DecodedImage> refused = ReadPng(wide, /*max_side=*/256);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ErrorCode::kOutOfRange);
  EXPECT_NE(refused.error().message.find("300x2 px"), std::string::npos) << refused.error().message;
  EXPECT_TRUE(ReadPng(wide, 300).ok());
}

TEST(PngCodecTest, CorruptAndTruncatedFilesAreDataLoss) {
  TempDir dir;
  const std::string good = CvEncode(RandomMat(40, 50, CV_16UC1, 9));
  const size_t idat = good.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  std::string flipped = good;
  flipped[idat + 30] = static_cast<char>(flipped[idat + 30] ^ 0x55);  // CRC no longer matches.
  std::vector<std::string> bad = {flipped, good.substr(0, idat + 10),
                                  good.substr(0, good.size() - 20), good.substr(0, 8),
                                  std::string("\x89PNG\r\n\x1a\n", 8) + "junk"};
  for (size_t i = 0; i < bad.size(); ++i) {
    const Result<DecodedImage> read = ReadPng(dir.Write("bad.png", bad[i]));
    ASSERT_FALSE(read.ok()) << "case " << i;
    EXPECT_EQ(read.error().code, ErrorCode::kDataLoss)
        << "case " << i << ": " << read.error().ToString();
    EXPECT_NE(read.error().message.find("bad.png"), std::string::npos) << read.error().message;
  }
}

TEST(PngCodecTest, EncodeRefusesInconsistentImages) {
  DecodedImage image;
  image.width = 4;
  image.height = 4;
  image.channels = 1;
  image.bits_per_sample = 16;
  image.bytes.resize(31);  // one byte short.
  EXPECT_EQ(EncodePng(image).error().code, ErrorCode::kInvalidArgument);
  image.bytes.resize(32);
  EXPECT_TRUE(EncodePng(image).ok());
  EXPECT_EQ(EncodePng(image, 10).error().code, ErrorCode::kInvalidArgument);
  image.bits_per_sample = 12;
  EXPECT_EQ(EncodePng(image).error().code, ErrorCode::kInvalidArgument);
  image.bits_per_sample = 8;
  image.channels = 5;
  EXPECT_EQ(EncodePng(image).error().code, ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace hpose
