#include "server/file_sequence_source.h"

#include <algorithm>
#include <filesystem>
#include <system_error>
#include <thread>
#include <utility>

#include "core/io/cloud_io.h"
#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"

namespace hpose::server {

namespace fs = std::filesystem;

Result<std::vector<std::string>> ListFiles(const std::string& directory,
                                           const std::string& extension) {
  std::error_code ec;
  fs::directory_iterator it(directory, ec);
  if (ec) {
    return MakeError(ErrorCode::kNotFound,
                     directory + ": cannot read the directory (" + ec.message() + ")");
  }
  std::vector<std::string> files;
  for (const fs::directory_entry& entry : it) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file(ec) && name.size() > extension.size() &&
        name.compare(name.size() - extension.size(), extension.size(), extension) == 0) {
      files.push_back(entry.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

FileSequenceSource::FileSequenceSource(std::string directory, Format format, ReplayOptions replay)
    : directory_(std::move(directory)), format_(format), replay_(replay) {}

std::string FileSequenceSource::kind() const {
  return format_ == Format::kDepthPng ? "png-dir" : "pcd-dir";
}

Status FileSequenceSource::Open() {
  if (!(replay_.fps > 0.0) || replay_.fps > 10000.0) {
    return MakeError(ErrorCode::kInvalidArgument,
                     directory_ + ": replay rate must be in (0, 10000] Hz");
  }
  if (format_ == Format::kDepthPng) {
    Result<Intrinsics> intrinsics = ReadIntrinsicsJson(directory_ + "/intrinsics.json");
    if (!intrinsics.ok()) return intrinsics.error();
    intrinsics_ = *intrinsics;
  }
  Result<std::vector<std::string>> files =
      ListFiles(directory_, format_ == Format::kDepthPng ? ".png" : ".pcd");
  if (!files.ok()) return files.error();
  if (files->empty()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     directory_ + (format_ == Format::kDepthPng ? ": no .png depth frames"
                                                                : ": no .pcd clouds"));
  }
  files_ = std::move(*files);
  if (opened_before_) ++epoch_;  // reopened: the clock starts over.
  opened_before_ = true;
  next_index_ = 0;
  start_ = std::chrono::steady_clock::now();
  paced_ = 0;
  return Status::Ok();
}

Result<Frame> FileSequenceSource::Next() {
  if (files_.empty()) {
    return MakeError(ErrorCode::kUnavailable, directory_ + ": source is not open");
  }
  if (next_index_ >= files_.size()) {
    if (!replay_.loop) {
      return MakeError(ErrorCode::kOutOfRange, directory_ + ": end of recording");
    }
    next_index_ = 0;
    ++epoch_;  // the recording's clock starts over.
  }
  if (replay_.realtime) {
    const auto due = start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                  std::chrono::duration<double>(paced_ / replay_.fps));
    std::this_thread::sleep_until(due);
  }
  ++paced_;
  const size_t index = next_index_++;
  const std::string& path = files_[index];

  Frame frame;
  frame.sequence = ++sequence_;
  frame.epoch = epoch_;
  frame.source_time_s = static_cast<double>(index) / replay_.fps;
  frame.origin = path;
  if (format_ == Format::kDepthPng) {
    Result<DepthImage> depth = ReadDepthPng(path);
    if (!depth.ok()) return depth.error();
    if (depth->width != intrinsics_.width || depth->height != intrinsics_.height) {
      return MakeError(ErrorCode::kInvalidArgument,
                       path + ": image is " + std::to_string(depth->width) + "x" +
                           std::to_string(depth->height) + " but intrinsics.json says " +
                           std::to_string(intrinsics_.width) + "x" +
                           std::to_string(intrinsics_.height));
    }
    frame.depth = std::move(*depth);
    frame.intrinsics = intrinsics_;
  } else {
    Result<PointCloud> cloud = ReadCloud(path);
    if (!cloud.ok()) return cloud.error();
    frame.is_cloud = true;
    frame.cloud = std::move(*cloud);
  }
  frame.received = std::chrono::system_clock::now();
  frame.received_steady = std::chrono::steady_clock::now();
  return frame;
}

void FileSequenceSource::Close() { files_.clear(); }

}  // namespace hpose::server
