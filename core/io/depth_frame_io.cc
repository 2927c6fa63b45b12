#include "core/io/depth_frame_io.h"

#include <sys/stat.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/common/file_names.h"
#include "core/io/decoded_image.h"
#include "core/io/depth_png.h"
#include "core/io/pclzf_reader.h"
#include "core/io/tiff_reader.h"

namespace hpose {

namespace {

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

Result<DepthFrameFile> ReadPclzf(const std::string& path) {
  if (Status s = CheckRegularFile(path, "expected a .pclzf depth image"); !s.ok()) {
    return s.error();
  }
  const std::string xml = PclzfParameterPath(path);
  if (Status s = CheckRegularFile(xml, "expected the camera parameters of " + path); !s.ok()) {
    return s.error();
  }
  Result<PclzfDepthCamera> camera = ReadPclzfDepthCamera(xml);
  if (!camera.ok()) {
    return MakeError(camera.error().code, camera.error().message + " (the camera of " + path + ")");
  }
  const double to_metres = camera->z_multiplication_factor;
  if (!(to_metres > 0.0 && to_metres < 1.0)) {
    return MakeError(ErrorCode::kDataLoss, xml + ": z_multiplication_factor must be in (0, 1) m");
  }
  Result<PclzfDepth16> raw = ReadPclzfDepth16(path);
  if (!raw.ok()) return raw.error();
  DepthFrameFile out;
  out.depth = DepthImage(raw->width, raw->height);
  const double to_mm = to_metres * 1000.0;
  for (size_t i = 0; i < raw->values.size(); ++i) {
    const double mm = std::round(raw->values[i] * to_mm);
    out.depth.mm[i] = mm > 65535.0 ? 0 : static_cast<std::uint16_t>(mm);
  }
  out.has_intrinsics = true;
  out.intrinsics.width = out.depth.width;
  out.intrinsics.height = out.depth.height;
  out.intrinsics.fx = camera->focal_length_x;
  out.intrinsics.fy = camera->focal_length_y;
  out.intrinsics.cx = camera->principal_point_x;
  out.intrinsics.cy = camera->principal_point_y;
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
