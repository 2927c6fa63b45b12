#include "tools/picture_png.h"

#include <opencv2/core.hpp>

#include "core/io/atomic_file.h"
#include "core/io/decoded_image.h"
#include "core/io/png_codec.h"

namespace hpose::tools {

Status WritePicturePng(const cv::Mat& bgr, const std::string& path, int compression_level) {
  if (bgr.type() != CV_8UC3) {
    return MakeError(ErrorCode::kInternal,
                     "cannot write picture " + path + ": not an 8-bit BGR image");
  }
  DecodedImage rgb;
  rgb.width = bgr.cols;
  rgb.height = bgr.rows;
  rgb.channels = 3;
  rgb.bits_per_sample = 8;
  rgb.bytes.resize(rgb.RowBytes() * rgb.height);
  for (int v = 0; v < bgr.rows; ++v) {
    const cv::Vec3b* in = bgr.ptr<cv::Vec3b>(v);
    std::uint8_t* out = rgb.bytes.data() + rgb.RowBytes() * v;
    for (int u = 0; u < bgr.cols; ++u) {
      out[3 * u] = in[u][2];
      out[3 * u + 1] = in[u][1];
      out[3 * u + 2] = in[u][0];
    }
  }
  Result<std::string> png = EncodePng(rgb, compression_level);
  if (!png.ok()) {
    return MakeError(png.error().code, "cannot write picture " + path + ": " + png.error().message);
  }
  return WriteFileAtomically(path, *png);
}

}  // namespace hpose::tools
