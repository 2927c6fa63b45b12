#include "core/io/depth_frame_io.h"

#include <pcl/io/lzf_image_io.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/io/decoded_image.h"
#include "core/io/depth_png.h"
#include "core/io/tiff_reader.h"

namespace hpose {

namespace {

std::string LowerExtension(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

Status CheckRegularFile(const std::string& path, const std::string& what) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0)
    return MakeError(ErrorCode::kNotFound, path + ": no such file");
  if (!S_ISREG(st.st_mode)) {
    return MakeError(ErrorCode::kInvalidArgument, path + ": not a regular file (" + what + ")");
  }
  return Status::Ok();
}

Result<DepthImage> ReadDepthTiff(const std::string& path) {
  Result<DecodedImage> image = ReadTiff(path);
  if (!image.ok()) return image.error();
  return DepthFromDecodedImage(*image, path);
}

// PCL's reader, opened up to give the raw 16-bit values instead of a point cloud.
class RawLzfDepthReader final : public pcl::io::LZFDepth16ImageReader {
 public:
  // The decompressed values (row-major) and the factor turning them into metres.
  bool ReadRaw(const std::string& path, std::vector<std::uint16_t>* values, double* to_metres) {
    std::uint32_t size = 0;
    std::vector<char> compressed;
    if (!loadImageBlob(path, compressed, size)) return false;
    if (size != getWidth() * getHeight() * 2 || size == 0) return false;
    std::vector<char> raw(size);
    if (!decompress(compressed, raw) || raw.size() != size) return false;
    values->resize(size / 2);
    std::memcpy(values->data(), raw.data(), size);
    *to_metres = z_multiplication_factor_;
    return true;
  }
};

Result<DepthFrameFile> ReadPclzf(const std::string& path) {
  if (Status s = CheckRegularFile(path, "expected a .pclzf depth image"); !s.ok()) {
    return s.error();
  }
  const std::string xml = PclzfParameterPath(path);
  if (Status s = CheckRegularFile(xml, "expected the camera parameters of " + path); !s.ok()) {
    return s.error();
  }
  RawLzfDepthReader reader;
  if (!reader.readParameters(xml)) {
    return MakeError(ErrorCode::kDataLoss,
                     xml + ": cannot read the <depth> camera parameters of " + path);
  }
  std::vector<std::uint16_t> values;
  double to_metres = 0.0;
  if (!reader.ReadRaw(path, &values, &to_metres)) {
    return MakeError(ErrorCode::kDataLoss, path + ": not a 16-bit PCL-LZF depth image (type '" +
                                               reader.getImageType() + "')");
  }
  if (!(to_metres > 0.0 && to_metres < 1.0)) {
    return MakeError(ErrorCode::kDataLoss, xml + ": z_multiplication_factor must be in (0, 1) m");
  }
  DepthFrameFile out;
  out.depth = DepthImage(static_cast<int>(reader.getWidth()), static_cast<int>(reader.getHeight()));
  const double to_mm = to_metres * 1000.0;
  for (size_t i = 0; i < values.size(); ++i) {
    const double mm = std::round(values[i] * to_mm);
    out.depth.mm[i] = mm > 65535.0 ? 0 : static_cast<std::uint16_t>(mm);
  }
  const pcl::io::CameraParameters p = reader.getParameters();
  out.has_intrinsics = true;
  out.intrinsics.width = out.depth.width;
  out.intrinsics.height = out.depth.height;
  out.intrinsics.fx = p.focal_length_x;
  out.intrinsics.fy = p.focal_length_y;
  out.intrinsics.cx = p.principal_point_x;
  out.intrinsics.cy = p.principal_point_y;
  Status valid = out.intrinsics.Validate();
  if (!valid.ok()) return MakeError(ErrorCode::kDataLoss, xml + ": " + valid.error().message);
  return out;
}

}  // namespace

bool IsDepthFrameFile(const std::string& path) {
  const std::string ext = LowerExtension(path);
  return ext == ".png" || ext == ".tif" || ext == ".tiff" || ext == ".pclzf";
}

std::string PclzfParameterPath(const std::string& pclzf_path) {
  const std::string suffix = "_depth.pclzf";
  if (pclzf_path.size() > suffix.size() &&
      pclzf_path.compare(pclzf_path.size() - suffix.size(), suffix.size(), suffix) == 0) {
    return pclzf_path.substr(0, pclzf_path.size() - suffix.size()) + ".xml";
  }
  const size_t dot = pclzf_path.find_last_of('.');
  return pclzf_path.substr(0, dot) + ".xml";
}

Result<DepthFrameFile> ReadDepthFrame(const std::string& path) {
  const std::string ext = LowerExtension(path);
  if (ext == ".pclzf") return ReadPclzf(path);
  Result<DepthImage> depth = MakeError(ErrorCode::kInternal, "unread");
  if (ext == ".tif" || ext == ".tiff") {
    depth = ReadDepthTiff(path);
  } else if (ext == ".png") {
    depth = ReadDepthPng(path);
  } else {
    return MakeError(ErrorCode::kInvalidArgument,
                     path + ": unknown depth frame format (expected .png, .tif, .tiff or .pclzf)");
  }
  if (!depth.ok()) return depth.error();
  DepthFrameFile out;
  out.depth = std::move(*depth);
  return out;
}

}  // namespace hpose
