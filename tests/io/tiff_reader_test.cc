// libtiff reader against OpenCV's TIFF codec as the reference: the same pixels on real Kinect
// frames (../shared/data, skipped when absent), on every layout OpenCV writes, compressed or
// not, and on tiled files; bounded and clear failures on hostile files.
#include "core/io/tiff_reader.h"

#include <gtest/gtest.h>
#include <tiffio.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "core/io/depth_frame_io.h"
#include "core/io/image_header.h"
#include "tests/io/cv_reference.h"
#include "tests/io/temp_dir.h"

namespace hpose {
namespace {

const std::string kGrabberTiffs =
    std::string(HPOSE_SHARED_DATA_DIR) + "/kinect/grabber_sequences/tiff/";

void ExpectReadsLikeOpenCv(const std::string& path, const std::string& what) {
  const cv::Mat reference = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(reference.empty()) << what << ": OpenCV cannot read " << path;
  const Result<DecodedImage> ours = ReadTiff(path);
  ASSERT_TRUE(ours.ok()) << what << ": " << ours.error().ToString();
  ExpectSameImage(*ours, FromMat(reference), what);
}

// A tiled TIFF written with libtiff (OpenCV writes strips only); the tiles overhang the image.
void WriteTiledTiff(const std::string& path, const DecodedImage& image, std::uint32_t tile) {
  TIFF* tiff = TIFFOpen(path.c_str(), "w");
  ASSERT_NE(tiff, nullptr);
  TIFFSetField(tiff, TIFFTAG_IMAGEWIDTH, image.width);
  TIFFSetField(tiff, TIFFTAG_IMAGELENGTH, image.height);
  TIFFSetField(tiff, TIFFTAG_SAMPLESPERPIXEL, image.channels);
  TIFFSetField(tiff, TIFFTAG_BITSPERSAMPLE, image.bits_per_sample);
  TIFFSetField(tiff, TIFFTAG_PHOTOMETRIC,
               image.channels >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK);
  TIFFSetField(tiff, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(tiff, TIFFTAG_COMPRESSION, COMPRESSION_ADOBE_DEFLATE);
  TIFFSetField(tiff, TIFFTAG_TILEWIDTH, tile);
  TIFFSetField(tiff, TIFFTAG_TILELENGTH, tile);
  const size_t pixel = static_cast<size_t>(image.channels) * image.bits_per_sample / 8;
  std::vector<std::uint8_t> buffer(tile * tile * pixel);
  for (std::uint32_t y = 0; y < static_cast<std::uint32_t>(image.height); y += tile) {
    for (std::uint32_t x = 0; x < static_cast<std::uint32_t>(image.width); x += tile) {
      std::fill(buffer.begin(), buffer.end(), 0);
      for (std::uint32_t r = 0; r < tile && y + r < static_cast<std::uint32_t>(image.height); ++r) {
        const std::uint32_t columns = std::min<std::uint32_t>(tile, image.width - x);
        std::memcpy(buffer.data() + r * tile * pixel,
                    image.bytes.data() + (y + r) * image.RowBytes() + x * pixel, columns * pixel);
      }
      ASSERT_GE(TIFFWriteTile(tiff, buffer.data(), x, y, 0, 0), 0);
    }
  }
  TIFFClose(tiff);
}

TEST(TiffReaderTest, AgreesWithOpenCvOnRealKinectFrames) {
  if (!std::filesystem::is_directory(kGrabberTiffs)) {
    GTEST_SKIP() << "Kinect frames not found in " << kGrabberTiffs << " (third-party data)";
  }
  int frames = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kGrabberTiffs)) {
    ExpectReadsLikeOpenCv(entry.path().string(), entry.path().filename().string());
    ++frames;
  }
  EXPECT_GE(frames, 2);
}

TEST(TiffReaderTest, AgreesWithOpenCvOnEveryLayoutItWrites) {
  TempDir dir;
  unsigned seed = 1;
  for (int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    for (int compression : {1 /* none */, 5 /* LZW */, 32946 /* deflate */}) {
      const std::string what =
          "type " + std::to_string(type) + ", compression " + std::to_string(compression);
      const std::string path = dir.File("cv.tiff");
      ASSERT_TRUE(cv::imwrite(path, RandomMat(37, 53, type, seed++),
                              {cv::IMWRITE_TIFF_COMPRESSION, compression}))
          << what;
      ExpectReadsLikeOpenCv(path, what);
    }
  }
}

TEST(TiffReaderTest, ReadsTiledFilesLikeOpenCv) {
  TempDir dir;
  for (int type : {CV_16UC1, CV_8UC3}) {
    const DecodedImage image = FromMat(RandomMat(70, 45, type, 3));
    const std::string path = dir.File("tiled.tiff");
    WriteTiledTiff(path, image, 32);
    ExpectReadsLikeOpenCv(path, "tiled, type " + std::to_string(type));
    const Result<DecodedImage> ours = ReadTiff(path);
    ASSERT_TRUE(ours.ok()) << ours.error().ToString();
    ExpectSameImage(*ours, image, "tiled against its source");
  }
}

TEST(TiffReaderTest, DepthFramesAreSixteenBitGreyOnly) {
  TempDir dir;
  const cv::Mat depth = RandomMat(12, 16, CV_16UC1, 4);
  const std::string grey16 = dir.File("depth.tiff");
  ASSERT_TRUE(cv::imwrite(grey16, depth));
  Result<DepthFrameFile> frame = ReadDepthFrame(grey16);
  ASSERT_TRUE(frame.ok()) << frame.error().ToString();
  EXPECT_EQ(frame->depth.at(5, 7), depth.at<std::uint16_t>(7, 5));

  const std::string rgb = dir.File("rgb.tiff");
  ASSERT_TRUE(cv::imwrite(rgb, RandomMat(12, 16, CV_8UC3, 5)));
  frame = ReadDepthFrame(rgb);
  ASSERT_FALSE(frame.ok());
  EXPECT_EQ(frame.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(frame.error().message.find("3 channel(s) of 8-bit"), std::string::npos)
      << frame.error().message;

  const std::string real = dir.File("float.tiff");
  ASSERT_TRUE(cv::imwrite(real, cv::Mat(4, 4, CV_32FC1, cv::Scalar(1.5))));
  const Result<DecodedImage> refused = ReadTiff(real);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(refused.error().message.find("32-bit float"), std::string::npos)
      << refused.error().message;
}

TEST(TiffReaderTest, OversizedCorruptAndTruncatedFilesFailClearly) {
  TempDir dir;
  const std::string path = dir.File("ok.tiff");
  ASSERT_TRUE(
      cv::imwrite(path, RandomMat(300, 40, CV_16UC1, 6), {cv::IMWRITE_TIFF_COMPRESSION, 1}));
  const Result<DecodedImage> big = ReadTiff(path, /*max_side=*/256);
  ASSERT_FALSE(big.ok());
  EXPECT_EQ(big.error().code, ErrorCode::kOutOfRange);
  EXPECT_NE(big.error().message.find("40x300 px"), std::string::npos) << big.error().message;

  // Writers that put the directory after the pixels (beyond the head CheckImageSize reads
  // first) are measured too.
  const std::string wide = dir.File("wide.tiff");
  ASSERT_TRUE(cv::imwrite(wide, cv::Mat(20, 9000, CV_16UC1, cv::Scalar(7)),
                          {cv::IMWRITE_TIFF_COMPRESSION, 1}));
  ASSERT_GT(std::filesystem::file_size(wide), 256u * 1024u);
  const Result<ImageSize> wide_size = ReadImageSize(wide);
  ASSERT_TRUE(wide_size.ok()) << wide_size.error().ToString();
  EXPECT_EQ(wide_size->width, 9000);
  EXPECT_EQ(wide_size->height, 20);
  EXPECT_EQ(ReadTiff(wide).error().code, ErrorCode::kOutOfRange);

  const std::string bytes = Slurp(path);
  for (const std::string& bad : {bytes.substr(0, bytes.size() / 2), bytes.substr(0, 6),
                                 std::string("II*\0junk", 8), std::string("not a tiff at all")}) {
    const Result<DecodedImage> read = ReadTiff(dir.Write("bad.tiff", bad));
    ASSERT_FALSE(read.ok()) << bad.size() << " bytes";
    EXPECT_EQ(read.error().code, ErrorCode::kDataLoss) << read.error().ToString();
    EXPECT_NE(read.error().message.find("bad.tiff"), std::string::npos) << read.error().message;
  }
  EXPECT_EQ(ReadTiff(dir.File("missing.tiff")).error().code, ErrorCode::kNotFound);
}

}  // namespace
}  // namespace hpose
