// libjpeg decoder and encoder against OpenCV's JPEG codec as the reference (the same pixels
// from the same file), ReadRgbImage against the OpenCV reading it replaced, and clear failures
// on damaged, oversized and foreign files.
#include "core/io/jpeg_codec.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/io/image_header.h"
#include "core/stereo/rgb_image_io.h"
#include "tests/io/cv_reference.h"
#include "tests/io/temp_dir.h"

namespace hpose {
namespace {

std::string CvEncode(const std::string& ext, const cv::Mat& mat,
                     const std::vector<int>& params = {}) {
  std::vector<unsigned char> bytes;
  EXPECT_TRUE(cv::imencode(ext, mat, bytes, params));
  return std::string(bytes.begin(), bytes.end());
}

// A camera-like picture: smooth gradients, edges and noise (random pixels alone would test only
// the entropy coder's worst case).
cv::Mat Picture(int rows, int cols, int type, unsigned seed) {
  cv::Mat mat(rows, cols, type);
  cv::RNG rng(seed);
  const int channels = CV_MAT_CN(type);
  const double top = CV_MAT_DEPTH(type) == CV_16U ? 65535.0 : 255.0;
  for (int v = 0; v < rows; ++v) {
    for (int u = 0; u < cols; ++u) {
      for (int c = 0; c < channels; ++c) {
        double level = 0.5 + 0.4 * std::sin(0.05 * (u + 3 * c) + 0.03 * v);
        if ((u / 16 + v / 16 + c) % 3 == 0) level = 0.15;  // blocks with sharp edges.
        level += rng.gaussian(0.03);
        const double value = std::clamp(level, 0.0, 1.0) * top;
        if (CV_MAT_DEPTH(type) == CV_16U) {
          mat.ptr<std::uint16_t>(v)[u * channels + c] = static_cast<std::uint16_t>(value);
        } else {
          mat.ptr<std::uint8_t>(v)[u * channels + c] = static_cast<std::uint8_t>(value);
        }
      }
    }
  }
  return mat;
}

TEST(JpegCodecTest, DecodesWhatOpenCvDecodesToTheBit) {
  TempDir dir;
  unsigned seed = 1;
  for (int type : {CV_8UC1, CV_8UC3}) {
    for (const cv::Size size : {cv::Size(1, 1), cv::Size(13, 7), cv::Size(640, 480)}) {
      for (int quality : {30, 75, 95}) {
        const std::string what = "type " + std::to_string(type) + ", " +
                                 std::to_string(size.width) + "x" + std::to_string(size.height) +
                                 ", quality " + std::to_string(quality);
        const std::string file = CvEncode(".jpg", Picture(size.height, size.width, type, seed++),
                                          {cv::IMWRITE_JPEG_QUALITY, quality});
        const cv::Mat reference = cv::imdecode(std::vector<unsigned char>(file.begin(), file.end()),
                                               cv::IMREAD_UNCHANGED);
        ASSERT_FALSE(reference.empty()) << what;
        const Result<DecodedImage> ours = ReadJpeg(dir.Write("cv.jpg", file));
        ASSERT_TRUE(ours.ok()) << what << ": " << ours.error().ToString();
        ExpectSameImage(*ours, FromMat(reference), what);
      }
    }
  }
}

TEST(JpegCodecTest, EncodedImagesAreReadByOpenCvAndCloseToTheOriginal) {
  for (int channels : {1, 3}) {
    const cv::Mat original = Picture(120, 160, channels == 1 ? CV_8UC1 : CV_8UC3, 7);
    const DecodedImage source = FromMat(original);
    for (int quality : {50, 95}) {
      const std::string what =
          std::to_string(channels) + " channel(s), quality " + std::to_string(quality);
      const Result<std::string> encoded = EncodeJpeg(source, quality);
      ASSERT_TRUE(encoded.ok()) << what << ": " << encoded.error().ToString();
      const cv::Mat theirs = cv::imdecode(
          std::vector<unsigned char>(encoded->begin(), encoded->end()), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(theirs.empty()) << what << ": OpenCV cannot read our JPEG";
      const Result<DecodedImage> ours = DecodeJpeg(*encoded, "encoded");
      ASSERT_TRUE(ours.ok()) << what << ": " << ours.error().ToString();
      ExpectSameImage(*ours, FromMat(theirs), what);
      // Lossy (the sharp colour edges lose most to the halved chroma), as lossy as OpenCV's
      // encoder at the same quality.
      const auto mean_error = [&](const DecodedImage& decoded) {
        double sum = 0.0;
        for (size_t i = 0; i < source.bytes.size(); ++i) {
          sum += std::abs(static_cast<int>(source.bytes[i]) - static_cast<int>(decoded.bytes[i]));
        }
        return sum / static_cast<double>(source.bytes.size());
      };
      const std::string cv_file = CvEncode(".jpg", original, {cv::IMWRITE_JPEG_QUALITY, quality});
      const Result<DecodedImage> cv_decoded = DecodeJpeg(cv_file, "OpenCV's");
      ASSERT_TRUE(cv_decoded.ok()) << what;
      EXPECT_GT(mean_error(*ours), 0.0) << what;
      EXPECT_LE(mean_error(*ours), 1.05 * mean_error(*cv_decoded) + 0.05) << what;
    }
  }
  // A higher quality costs bytes.
  const DecodedImage source = FromMat(Picture(120, 160, CV_8UC3, 8));
  EXPECT_LT(EncodeJpeg(source, 30)->size(), EncodeJpeg(source, 95)->size());
}

TEST(JpegCodecTest, DamagedForeignAndOversizedFilesFailNamingTheProblem) {
  TempDir dir;
  const std::string good =
      CvEncode(".jpg", Picture(64, 64, CV_8UC3, 3), {cv::IMWRITE_JPEG_QUALITY, 90});
  const auto expect = [&](const Result<DecodedImage>& r, ErrorCode code, const std::string& text,
                          const std::string& what) {
    ASSERT_FALSE(r.ok()) << what;
    EXPECT_EQ(r.error().code, code) << what << ": " << r.error().ToString();
    EXPECT_NE(r.error().message.find(text), std::string::npos)
        << what << ": " << r.error().ToString();
  };
  expect(ReadJpeg(dir.File("missing.jpg")), ErrorCode::kNotFound, "missing.jpg", "missing");
  expect(ReadJpeg(dir.Write("empty.jpg", "")), ErrorCode::kDataLoss, "empty.jpg", "empty");
  expect(ReadJpeg(dir.Write("text.jpg", "not an image at all")), ErrorCode::kDataLoss,
         "not a decodable JPEG", "text");
  expect(ReadJpeg(dir.Write("cut.jpg", good.substr(0, good.size() / 2))), ErrorCode::kDataLoss,
         "corrupt or truncated", "cut in half");
  // Stray bytes before the end marker (some cameras write them): libjpeg warns, the pixels are
  // whole, and they are read as OpenCV reads them.
  std::string stray = good;
  stray.insert(stray.size() - 2, std::string("\x01\x02\x03", 3));
  const Result<DecodedImage> with_stray = ReadJpeg(dir.Write("stray.jpg", stray));
  ASSERT_TRUE(with_stray.ok()) << with_stray.error().ToString();
  const cv::Mat stray_reference =
      cv::imdecode(std::vector<unsigned char>(stray.begin(), stray.end()), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(stray_reference.empty());
  ExpectSameImage(*with_stray, FromMat(stray_reference), "stray bytes before the end marker");
  // A marker in the middle of the entropy-coded data: libjpeg stops the segment there.
  std::string marker = good;
  marker.insert(good.size() / 2, std::string("\xFF\xD3", 2));
  expect(ReadJpeg(dir.Write("marker.jpg", marker)), ErrorCode::kDataLoss, "corrupt or truncated",
         "a marker in the data");
  // Flipped bits of the entropy-coded data often decode to other pixels without a warning; then
  // the image keeps its size.
  std::string flipped = good;
  for (size_t i = good.size() / 3; i < good.size() - 2; i += 97) flipped[i] ^= 0x5A;
  const Result<DecodedImage> damaged = ReadJpeg(dir.Write("flipped.jpg", flipped));
  if (damaged.ok()) {
    EXPECT_EQ(damaged->width, 64);
    EXPECT_EQ(damaged->height, 64);
    EXPECT_EQ(damaged->bytes.size(), 64u * 64u * 3u);
  } else {
    EXPECT_EQ(damaged.error().code, ErrorCode::kDataLoss) << damaged.error().ToString();
  }
  // Wider than hpose decodes: refused after the header, before the pixels are allocated.
  DecodedImage wide;
  wide.width = 9000;
  wide.height = 2;
  wide.channels = 1;
  wide.bits_per_sample = 8;
  wide.bytes.assign(wide.RowBytes() * wide.height, 128);
  const Result<std::string> wide_file = EncodeJpeg(wide, 80);
  ASSERT_TRUE(wide_file.ok());
  expect(DecodeJpeg(*wide_file, "wide"), ErrorCode::kOutOfRange, "9000x2 px", "9000 px wide");
  expect(ReadJpeg(dir.Write("wide.jpg", *wide_file)), ErrorCode::kOutOfRange, "9000x2 px",
         "9000 px wide, from a file");
  // What the encoder takes.
  DecodedImage two = FromMat(Picture(8, 8, CV_8UC3, 4));
  EXPECT_EQ(EncodeJpeg(two, 0).error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(EncodeJpeg(two, 101).error().code, ErrorCode::kInvalidArgument);
  two.channels = 2;
  EXPECT_EQ(EncodeJpeg(two, 90).error().code, ErrorCode::kInvalidArgument);
  DecodedImage deep = FromMat(Picture(8, 8, CV_16UC1, 5));
  EXPECT_EQ(EncodeJpeg(deep, 90).error().code, ErrorCode::kInvalidArgument);
}

// ReadRgbImage as it was written with OpenCV's reader: imread unchanged, 16 bits scaled by
// 1/257, grey expanded, alpha dropped, BGR to RGB.
RgbImage ReadWithOpenCv(const std::string& path) {
  const cv::Mat raw = cv::imread(path, cv::IMREAD_UNCHANGED);
  EXPECT_FALSE(raw.empty()) << path;
  cv::Mat eight;
  if (raw.depth() == CV_16U) {
    raw.convertTo(eight, CV_8U, 1.0 / 257.0);
  } else {
    eight = raw;
  }
  RgbImage out(eight.cols, eight.rows);
  cv::Mat dst(out.height, out.width, CV_8UC3, out.pixels.data());
  static const int kCodes[] = {cv::COLOR_GRAY2RGB, -1, cv::COLOR_BGR2RGB, cv::COLOR_BGRA2RGB};
  cv::cvtColor(eight, dst, kCodes[eight.channels() - 1]);
  return out;
}

TEST(RgbImageIoTest, ReadsPngJpegAndTiffAsOpenCvDid) {
  TempDir dir;
  unsigned seed = 11;
  int files = 0;
  for (const std::string ext : {".png", ".tiff", ".jpg"}) {
    for (int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
      if (ext == ".jpg" && (CV_MAT_DEPTH(type) != CV_8U || CV_MAT_CN(type) == 4)) continue;
      const std::string what = ext + ", type " + std::to_string(type);
      // The name does not say the format: the first bytes do.
      const std::string path = dir.Write("image" + std::to_string(files++) + ".img",
                                         CvEncode(ext, Picture(48, 64, type, seed++)));
      const Result<ImageSize> header = ReadImageSize(path);
      ASSERT_TRUE(header.ok()) << what << ": " << header.error().ToString();
      EXPECT_EQ(header->format, ext == ".png"   ? ImageFormat::kPng
                                : ext == ".jpg" ? ImageFormat::kJpeg
                                                : ImageFormat::kTiff)
          << what;
      const Result<RgbImage> ours = ReadRgbImage(path);
      ASSERT_TRUE(ours.ok()) << what << ": " << ours.error().ToString();
      const RgbImage reference = ReadWithOpenCv(path);
      EXPECT_EQ(ours->width, reference.width) << what;
      EXPECT_EQ(ours->height, reference.height) << what;
      EXPECT_TRUE(ours->pixels == reference.pixels) << what << ": pixels differ";
    }
  }
  EXPECT_EQ(files, 14);
}

TEST(RgbImageIoTest, OtherFormatsMissingAndDamagedFilesAreClearErrors) {
  TempDir dir;
  const Result<RgbImage> bmp =
      ReadRgbImage(dir.Write("a.bmp", CvEncode(".bmp", Picture(8, 8, CV_8UC3, 1))));
  ASSERT_FALSE(bmp.ok());
  EXPECT_EQ(bmp.error().code, ErrorCode::kDataLoss);
  EXPECT_NE(bmp.error().message.find("not a PNG, JPEG or TIFF image"), std::string::npos)
      << bmp.error().ToString();
  const Result<RgbImage> missing = ReadRgbImage(dir.File("none.png"));
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, ErrorCode::kNotFound);
  const std::string jpeg = CvEncode(".jpg", Picture(32, 32, CV_8UC3, 2));
  const Result<RgbImage> cut = ReadRgbImage(dir.Write("cut.jpg", jpeg.substr(0, jpeg.size() - 40)));
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(cut.error().code, ErrorCode::kDataLoss) << cut.error().ToString();
  EXPECT_NE(cut.error().message.find("cut.jpg"), std::string::npos) << cut.error().ToString();
  const std::string png = CvEncode(".png", Picture(32, 32, CV_8UC3, 3));
  const Result<RgbImage> cut_png =
      ReadRgbImage(dir.Write("cut.png", png.substr(0, png.size() - 40)));
  ASSERT_FALSE(cut_png.ok());
  EXPECT_EQ(cut_png.error().code, ErrorCode::kDataLoss) << cut_png.error().ToString();
}

TEST(RgbImageIoTest, WrittenPngsReadBackAsWrittenByBothReaders) {
  TempDir dir;
  const cv::Mat bgr = Picture(30, 40, CV_8UC3, 21);
  const DecodedImage rgb = FromMat(bgr);  // RGB order.
  RgbImage image(rgb.width, rgb.height);
  image.pixels = rgb.bytes;
  const std::string path = dir.File("out.png");
  ASSERT_TRUE(WriteRgbPng(image, path).ok());
  const Result<RgbImage> back = ReadRgbImage(path);
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_TRUE(back->pixels == image.pixels);
  const cv::Mat theirs = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(theirs.type(), CV_8UC3);
  EXPECT_TRUE(FromMat(theirs).bytes == image.pixels);
  // Nothing is left beside it, and a bad image writes nothing.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.File("")),
                          std::filesystem::directory_iterator()),
            1);
  RgbImage bad(4, 4);
  bad.pixels.pop_back();
  EXPECT_EQ(WriteRgbPng(bad, dir.File("bad.png")).error().code, ErrorCode::kInvalidArgument);
  EXPECT_FALSE(std::filesystem::exists(dir.File("bad.png")));
}

}  // namespace
}  // namespace hpose
