// Test helper: OpenCV's image codecs as the reference for hpose's own PNG and TIFF code.
#ifndef HPOSE_TESTS_IO_CV_REFERENCE_H_
#define HPOSE_TESTS_IO_CV_REFERENCE_H_

#include <cstring>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/io/decoded_image.h"

namespace hpose {

// OpenCV's pixels in DecodedImage's layout: RGB(A) instead of BGR(A), host byte order.
inline DecodedImage FromMat(const cv::Mat& mat) {
  cv::Mat ordered;  // a new buffer: converting into a copy of `mat`'s header would change it.
  if (mat.channels() == 3) {
    cv::cvtColor(mat, ordered, cv::COLOR_BGR2RGB);
  } else if (mat.channels() == 4) {
    cv::cvtColor(mat, ordered, cv::COLOR_BGRA2RGBA);
  } else {
    ordered = mat;
  }
  DecodedImage image;
  image.width = mat.cols;
  image.height = mat.rows;
  image.channels = mat.channels();
  image.bits_per_sample = mat.depth() == CV_16U ? 16 : 8;
  image.bytes.resize(image.RowBytes() * image.height);
  for (int v = 0; v < mat.rows; ++v) {
    std::memcpy(image.bytes.data() + image.RowBytes() * v, ordered.ptr(v), image.RowBytes());
  }
  return image;
}

// Random samples over the whole range (both bytes of 16-bit samples vary, so that a byte-order
// slip shows).
inline cv::Mat RandomMat(int rows, int cols, int type, unsigned seed) {
  cv::Mat mat(rows, cols, type);
  cv::RNG rng(seed);
  rng.fill(mat, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return mat;
}

inline void ExpectSameImage(const DecodedImage& a, const DecodedImage& b, const std::string& what) {
  EXPECT_EQ(a.width, b.width) << what;
  EXPECT_EQ(a.height, b.height) << what;
  EXPECT_EQ(a.channels, b.channels) << what;
  EXPECT_EQ(a.bits_per_sample, b.bits_per_sample) << what;
  EXPECT_TRUE(a.bytes == b.bytes) << what << ": pixels differ";
}

}  // namespace hpose

#endif  // HPOSE_TESTS_IO_CV_REFERENCE_H_
