#include "server/file_sequence_source.h"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <system_error>
#include <thread>
#include <utility>

#include "core/io/cloud_io.h"
#include "core/io/depth_frame_io.h"
#include "core/io/frame_file_time.h"
#include "core/io/intrinsics_json.h"

namespace hpose::server {

namespace fs = std::filesystem;

namespace {

const char* FormatNoun(FileSequenceSource::Format format) {
  switch (format) {
    case FileSequenceSource::Format::kDepthPng:
      return ".png depth frames";
    case FileSequenceSource::Format::kPcd:
      return ".pcd clouds";
    case FileSequenceSource::Format::kDepthTiff:
      return ".tif/.tiff depth frames";
    case FileSequenceSource::Format::kDepthPclzf:
      return "_depth.pclzf depth frames";
  }
  return "frames";
}

// Appends the files of `more` to `files` and sorts them by name.
void Merge(std::vector<std::string>* files, const Result<std::vector<std::string>>& more) {
  if (!more.ok()) return;
  files->insert(files->end(), more->begin(), more->end());
  std::sort(files->begin(), files->end());
}

// A frame file a reader refuses as too large (kOutOfRange: a side or a point count beyond what
// hpose reads) is one bad file of the recording; kOutOfRange from Next() means its end.
Error OneBadFile(Error error) {
  if (error.code == ErrorCode::kOutOfRange) error.code = ErrorCode::kInvalidArgument;
  return error;
}

}  // namespace

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

Result<std::vector<std::string>> ListFrameFiles(const std::string& directory,
                                                FileSequenceSource::Format format) {
  using Format = FileSequenceSource::Format;
  switch (format) {
    case Format::kDepthPng:
      return ListFiles(directory, ".png");
    case Format::kPcd:
      return ListFiles(directory, ".pcd");
    case Format::kDepthPclzf:
      return ListFiles(directory, "_depth.pclzf");
    case Format::kDepthTiff: {
      Result<std::vector<std::string>> depth = ListFiles(directory, "_depth.tiff");
      if (!depth.ok()) return depth;
      Merge(&*depth, ListFiles(directory, "_depth.tif"));
      if (!depth->empty()) return depth;
      Merge(&*depth, ListFiles(directory, ".tiff"));
      Merge(&*depth, ListFiles(directory, ".tif"));
      return depth;
    }
  }
  return std::vector<std::string>();
}

FileSequenceSource::FileSequenceSource(std::string path, Format format, ReplayOptions replay)
    : path_(std::move(path)), format_(format), replay_(replay) {}

std::string FileSequenceSource::kind() const {
  switch (format_) {
    case Format::kDepthPng:
      return "png-dir";
    case Format::kPcd:
      return "pcd-dir";
    case Format::kDepthTiff:
      return "tiff-dir";
    case Format::kDepthPclzf:
      return "pclzf-dir";
  }
  return "files";
}

Status FileSequenceSource::Open() {
  if (!(replay_.fps > 0.0) || replay_.fps > 10000.0) {
    return MakeError(ErrorCode::kInvalidArgument,
                     path_ + ": the replay rate (fps) must be in (0, 10000] Hz, got " +
                         std::to_string(replay_.fps));
  }
  std::error_code ec;
  const bool single = fs::is_regular_file(path_, ec);
  const std::string dir = single ? fs::path(path_).parent_path().string() : path_;
  std::vector<std::string> files;
  if (single) {
    files.push_back(path_);
  } else {
    Result<std::vector<std::string>> listed = ListFrameFiles(path_, format_);
    if (!listed.ok()) return listed.error();
    if (listed->empty()) {
      return MakeError(ErrorCode::kInvalidArgument,
                       path_ + ": no " + std::string(FormatNoun(format_)));
    }
    files = std::move(*listed);
  }
  has_intrinsics_ = false;
  if (replay_.has_intrinsics) {
    has_intrinsics_ = true;
    intrinsics_ = replay_.intrinsics;
  } else if (format_ != Format::kPcd) {
    const std::string json = (fs::path(dir.empty() ? "." : dir) / "intrinsics.json").string();
    if (fs::exists(json, ec)) {
      Result<Intrinsics> k = ReadIntrinsicsJson(json);
      if (!k.ok()) return k.error();
      has_intrinsics_ = true;
      intrinsics_ = *k;
    } else if (format_ == Format::kDepthPng) {
      return MakeError(ErrorCode::kNotFound,
                       json +
                           ": no such file (PNG depth frames need their intrinsics: "
                           "{\"width\",\"height\",\"fx\",\"fy\",\"cx\",\"cy\"}, or give them "
                           "with source.intrinsics / --intrinsics)");
    }
  }
  // Source times from the names when every name records one, else index / fps.
  times_.assign(files.size(), 0.0);
  times_from_names_ = true;
  for (size_t i = 0; i < files.size() && times_from_names_; ++i) {
    const std::optional<double> t = TimeFromFrameFileName(files[i]);
    times_from_names_ = t.has_value();
    if (t) times_[i] = *t;
  }
  if (!times_from_names_) {
    for (size_t i = 0; i < files.size(); ++i) times_[i] = static_cast<double>(i) / replay_.fps;
  }
  files_ = std::move(files);
  if (opened_before_) ++epoch_;  // reopened: the clock starts over.
  opened_before_ = true;
  next_index_ = 0;
  start_ = std::chrono::steady_clock::now();
  pass_offset_s_ = times_.front();
  return Status::Ok();
}

Result<Frame> FileSequenceSource::Next() {
  if (files_.empty()) {
    return MakeError(ErrorCode::kUnavailable, path_ + ": source is not open");
  }
  if (next_index_ >= files_.size()) {
    if (!replay_.loop) {
      return MakeError(ErrorCode::kOutOfRange, path_ + ": end of recording");
    }
    // The next pass starts one frame period after the last frame was due.
    const double period = files_.size() > 1 ? (times_.back() - times_.front()) / (files_.size() - 1)
                                            : 1.0 / replay_.fps;
    start_ += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(times_.back() - pass_offset_s_ + period));
    pass_offset_s_ = times_.front();
    next_index_ = 0;
    ++epoch_;  // the recording's clock starts over.
  }
  const size_t index = next_index_++;
  if (replay_.realtime) {
    const auto due = start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                  std::chrono::duration<double>(times_[index] - pass_offset_s_));
    std::this_thread::sleep_until(due);
  }
  const std::string& path = files_[index];

  Frame frame;
  frame.sequence = ++sequence_;
  frame.epoch = epoch_;
  frame.source_time_s = times_[index];
  frame.origin = path;
  if (format_ == Format::kPcd) {
    Result<PointCloud> cloud = ReadCloud(path);
    if (!cloud.ok()) return OneBadFile(cloud.error());
    frame.is_cloud = true;
    frame.cloud = std::move(*cloud);
  } else {
    Result<DepthFrameFile> read = ReadDepthFrame(path);
    if (!read.ok()) return OneBadFile(read.error());
    frame.depth = std::move(read->depth);
    frame.intrinsics = has_intrinsics_ ? intrinsics_
                       : read->has_intrinsics
                           ? read->intrinsics
                           : Intrinsics::KinectV1(frame.depth.width, frame.depth.height);
    if (frame.depth.width != frame.intrinsics.width ||
        frame.depth.height != frame.intrinsics.height) {
      return MakeError(ErrorCode::kInvalidArgument,
                       path + ": image is " + std::to_string(frame.depth.width) + "x" +
                           std::to_string(frame.depth.height) + " but the intrinsics are for " +
                           std::to_string(frame.intrinsics.width) + "x" +
                           std::to_string(frame.intrinsics.height));
    }
  }
  frame.received = std::chrono::system_clock::now();
  frame.received_steady = std::chrono::steady_clock::now();
  return frame;
}

void FileSequenceSource::Close() { files_.clear(); }

}  // namespace hpose::server
