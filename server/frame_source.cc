#include "server/frame_source.h"

#include <filesystem>
#include <system_error>

#include "server/file_sequence_source.h"
#include "server/openni2_source.h"

namespace hpose::server {

namespace fs = std::filesystem;

namespace {

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

Result<std::unique_ptr<FrameSource>> MakeFrameSource(const std::string& spec,
                                                     const ReplayOptions& replay) {
  if (spec.empty()) return MakeError(ErrorCode::kInvalidArgument, "empty source");
  Openni2SourceOptions oni;
  oni.replay = replay;
  if (IsOpenni2DeviceSpec(spec)) {
    return std::unique_ptr<FrameSource>(std::make_unique<Openni2Source>(spec, oni));
  }
  std::error_code ec;
  const fs::file_status st = fs::status(spec, ec);
  if (ec || !fs::exists(st))
    return MakeError(ErrorCode::kNotFound, spec + ": no such file or directory");
  if (fs::is_regular_file(st)) {
    if (EndsWith(spec, ".oni") || EndsWith(spec, ".ONI")) {
      return std::unique_ptr<FrameSource>(std::make_unique<Openni2Source>(spec, oni));
    }
    return MakeError(ErrorCode::kInvalidArgument,
                     spec +
                         ": not a source (expected an .oni file, a directory of PNG depth "
                         "frames with intrinsics.json, a directory of PCD clouds, or "
                         "openni2://)");
  }
  if (!fs::is_directory(st)) {
    return MakeError(ErrorCode::kInvalidArgument, spec + ": not a file or directory");
  }
  if (fs::exists(fs::path(spec) / "intrinsics.json", ec)) {
    return std::unique_ptr<FrameSource>(
        std::make_unique<FileSequenceSource>(spec, FileSequenceSource::Format::kDepthPng, replay));
  }
  Result<std::vector<std::string>> pcds = ListFiles(spec, ".pcd");
  if (pcds.ok() && !pcds->empty()) {
    return std::unique_ptr<FrameSource>(
        std::make_unique<FileSequenceSource>(spec, FileSequenceSource::Format::kPcd, replay));
  }
  Result<std::vector<std::string>> pngs = ListFiles(spec, ".png");
  if (pngs.ok() && !pngs->empty()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     spec +
                         ": PNG depth frames need intrinsics.json in the same directory "
                         "({\"width\",\"height\",\"fx\",\"fy\",\"cx\",\"cy\"})");
  }
  return MakeError(ErrorCode::kInvalidArgument,
                   spec +
                       ": directory holds neither PNG depth frames with intrinsics.json nor "
                       "PCD clouds");
}

}  // namespace hpose::server
