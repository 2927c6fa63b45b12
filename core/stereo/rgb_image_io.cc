#include "core/stereo/rgb_image_io.h"

#include <sys/stat.h>

#include <cstdio>
#include <fstream>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/io/image_header.h"

namespace hpose {

Result<RgbImage> ReadRgbImage(const std::string& path) {
  // Only PNG, JPEG and TIFF reach OpenCV: it picks a decoder by content, and some of the others
  // it links (e.g. GDCM's DICOM reader) abort on damaged files instead of failing.
  const Result<ImageSize> kind = ReadImageSize(path);
  if (!kind.ok()) return kind.error();
  if (!kind->known) {
    return MakeError(ErrorCode::kDataLoss, path + ": not a PNG, JPEG or TIFF image");
  }
  const Status size = CheckImageSize(path);  // regular file, sides <= 8192 px, before decoding.
  if (!size.ok()) return size.error();
  cv::Mat raw;
  try {
    raw = cv::imread(path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    return MakeError(ErrorCode::kDataLoss, path + ": cannot decode image (" + e.what() + ")");
  }
  if (raw.empty()) {
    return MakeError(ErrorCode::kDataLoss, path + ": not a decodable image (corrupt or truncated)");
  }
  cv::Mat eight;
  if (raw.depth() == CV_8U) {
    eight = raw;
  } else if (raw.depth() == CV_16U) {
    raw.convertTo(eight, CV_8U, 1.0 / 257.0);
  } else {
    return MakeError(ErrorCode::kDataLoss, path + ": unsupported pixel depth (need 8 or 16 bit)");
  }
  RgbImage out(eight.cols, eight.rows);
  cv::Mat dst(out.height, out.width, CV_8UC3, out.pixels.data());
  switch (eight.channels()) {
    case 1:
      cv::cvtColor(eight, dst, cv::COLOR_GRAY2RGB);
      break;
    case 3:
      cv::cvtColor(eight, dst, cv::COLOR_BGR2RGB);
      break;
    case 4:
      cv::cvtColor(eight, dst, cv::COLOR_BGRA2RGB);
      break;
    default:
      return MakeError(ErrorCode::kDataLoss,
                       path + ": unsupported channel count " + std::to_string(eight.channels()));
  }
  return out;
}

Status WriteRgbPng(const RgbImage& image, const std::string& path) {
  if (!image.valid()) {
    return MakeError(ErrorCode::kInvalidArgument, path + ": image buffer does not match its size");
  }
  const cv::Mat rgb(image.height, image.width, CV_8UC3,
                    const_cast<std::uint8_t*>(image.pixels.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  std::vector<std::uint8_t> encoded;
  if (!cv::imencode(".png", bgr, encoded, {cv::IMWRITE_PNG_COMPRESSION, 1})) {
    return MakeError(ErrorCode::kInternal, path + ": cannot encode PNG");
  }
  // Write beside the target and rename, so readers never see a half-written image.
  const std::string temp = path + ".partial";
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(encoded.data()),
              static_cast<std::streamsize>(encoded.size()));
    if (!out) {
      std::remove(temp.c_str());
      return MakeError(ErrorCode::kInternal, path + ": cannot write file");
    }
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    std::remove(temp.c_str());
    return MakeError(ErrorCode::kInternal, path + ": cannot rename temporary file into place");
  }
  return Status::Ok();
}

}  // namespace hpose
