#include "core/io/depth_png.h"

#include <sys/stat.h>

#include <cstring>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/io/atomic_file.h"
#include "core/io/image_header.h"

namespace hpose {
namespace {

constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

std::string DepthName(int depth) {
  switch (depth) {
    case CV_8U:
      return "8-bit unsigned";
    case CV_8S:
      return "8-bit signed";
    case CV_16U:
      return "16-bit unsigned";
    case CV_16S:
      return "16-bit signed";
    case CV_32S:
      return "32-bit integer";
    case CV_32F:
      return "32-bit float";
    case CV_64F:
      return "64-bit float";
    default:
      return "unknown depth";
  }
}

}  // namespace

Result<DepthImage> ReadDepthPng(const std::string& path) {
  // A regular file (a FIFO would block) whose header announces a decodable size.
  const Status size = CheckImageSize(path);
  if (!size.ok()) return size.error();
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) return MakeError(ErrorCode::kInternal, path + ": cannot open the file");
    unsigned char signature[sizeof(kPngSignature)] = {};
    in.read(reinterpret_cast<char*>(signature), sizeof(signature));
    if (in.gcount() != static_cast<std::streamsize>(sizeof(signature)) ||
        std::memcmp(signature, kPngSignature, sizeof(signature)) != 0) {
      return MakeError(ErrorCode::kDataLoss, path + ": not a PNG file (bad signature)");
    }
  }
  cv::Mat image;
  try {
    image = cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_UNCHANGED);
  } catch (const std::exception& e) {
    return MakeError(ErrorCode::kDataLoss, path + ": cannot decode the PNG: " + e.what());
  }
  if (image.empty()) {
    return MakeError(ErrorCode::kDataLoss, path + ": cannot decode the PNG (corrupt or truncated)");
  }
  if (image.channels() != 1) {
    return MakeError(
        ErrorCode::kInvalidArgument,
        path + ": depth PNG must have one channel, it has " + std::to_string(image.channels()));
  }
  if (image.depth() != CV_16U) {
    return MakeError(
        ErrorCode::kInvalidArgument,
        path + ": depth PNG must be 16-bit unsigned, it is " + DepthName(image.depth()));
  }
  DepthImage depth(image.cols, image.rows);
  for (int v = 0; v < image.rows; ++v) {
    const std::uint16_t* row = image.ptr<std::uint16_t>(v);
    std::memcpy(depth.mm.data() + static_cast<size_t>(v) * image.cols, row,
                sizeof(std::uint16_t) * image.cols);
  }
  return depth;
}

Status WriteDepthPng(const DepthImage& depth, const std::string& path) {
  if (depth.width <= 0 || depth.height <= 0 ||
      depth.mm.size() != static_cast<size_t>(depth.width) * depth.height) {
    return MakeError(ErrorCode::kInvalidArgument,
                     path + ": cannot write a " + std::to_string(depth.width) + "x" +
                         std::to_string(depth.height) + " depth image holding " +
                         std::to_string(depth.mm.size()) + " values");
  }
  // The Mat only borrows the pixels; imencode does not modify them.
  const cv::Mat image(depth.height, depth.width, CV_16UC1,
                      const_cast<std::uint16_t*>(depth.mm.data()));
  std::vector<unsigned char> encoded;
  try {
    if (!cv::imencode(".png", image, encoded)) {
      return MakeError(ErrorCode::kInternal, path + ": PNG encoding failed");
    }
  } catch (const std::exception& e) {
    return MakeError(ErrorCode::kInternal, path + ": PNG encoding failed: " + e.what());
  }
  return WriteFileAtomically(path, std::string(encoded.begin(), encoded.end()));
}

}  // namespace hpose
