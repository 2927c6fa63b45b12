#include "server/frame_source.h"

#include <filesystem>
#include <system_error>

#include "core/common/file_names.h"
#include "server/file_sequence_source.h"
#include "server/openni2_source.h"

namespace hpose::server {

namespace fs = std::filesystem;

Result<std::unique_ptr<FrameSource>> MakeFrameSource(const std::string& spec,
                                                     const ReplayOptions& replay,
                                                     const LiveDeviceOptions& device) {
  if (spec.empty()) return MakeError(ErrorCode::kInvalidArgument, "empty source");
  Openni2SourceOptions oni;
  oni.device = device;
  oni.replay = replay;
  if (IsOpenni2DeviceSpec(spec)) {
    return std::unique_ptr<FrameSource>(std::make_unique<Openni2Source>(spec, oni));
  }
  std::error_code ec;
  const fs::file_status st = fs::status(spec, ec);
  if (ec || !fs::exists(st))
    return MakeError(ErrorCode::kNotFound, spec + ": no such file or directory");
  using Format = FileSequenceSource::Format;
  auto files = [&](Format format) {
    return std::unique_ptr<FrameSource>(std::make_unique<FileSequenceSource>(spec, format, replay));
  };
  if (fs::is_regular_file(st)) {
    const std::string lower = LowerCase(spec);
    if (EndsWith(lower, ".oni")) {
      return std::unique_ptr<FrameSource>(std::make_unique<Openni2Source>(spec, oni));
    }
    if (EndsWith(lower, ".pcd")) return files(Format::kPcd);
    if (EndsWith(lower, ".png")) return files(Format::kDepthPng);
    if (EndsWith(lower, ".tif") || EndsWith(lower, ".tiff")) return files(Format::kDepthTiff);
    if (EndsWith(lower, ".pclzf")) return files(Format::kDepthPclzf);
    return MakeError(ErrorCode::kInvalidArgument,
                     spec +
                         ": not a source: expected an .oni recording, one frame file (.png, "
                         ".tif, .tiff, .pclzf or .pcd), a directory of such frames, or "
                         "openni2://");
  }
  if (!fs::is_directory(st)) {
    return MakeError(ErrorCode::kInvalidArgument, spec + ": not a file or directory");
  }
  // The first format the directory holds frames of, in this order.
  for (Format format : {Format::kDepthPng, Format::kDepthTiff, Format::kDepthPclzf, Format::kPcd}) {
    Result<std::vector<std::string>> listed = ListFrameFiles(spec, format);
    if (!listed.ok()) return listed.error();
    if (listed->empty()) continue;
    if (format == Format::kDepthPng && !replay.has_intrinsics &&
        !fs::exists(fs::path(spec) / "intrinsics.json", ec)) {
      return MakeError(ErrorCode::kInvalidArgument,
                       spec +
                           ": PNG depth frames need intrinsics.json in the same directory "
                           "({\"width\",\"height\",\"fx\",\"fy\",\"cx\",\"cy\"}) or "
                           "given intrinsics");
    }
    return files(format);
  }
  return MakeError(ErrorCode::kInvalidArgument,
                   spec +
                       ": the directory holds no frames: expected 16-bit depth images (*.png "
                       "with intrinsics.json, *.tif / *.tiff, *_depth.pclzf with their .xml) "
                       "or point clouds (*.pcd)");
}

}  // namespace hpose::server
