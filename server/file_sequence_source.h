#ifndef HPOSE_SERVER_FILE_SEQUENCE_SOURCE_H_
#define HPOSE_SERVER_FILE_SEQUENCE_SOURCE_H_

#include <chrono>
#include <string>
#include <vector>

#include "core/depth/intrinsics.h"
#include "server/frame_source.h"

namespace hpose::server {

// A directory of frames replayed in file-name order: 16-bit PNG depth images (millimetres) with
// the directory's intrinsics.json, or PCD clouds (sensor frame, metres). Frame i carries
// source time i / fps.
class FileSequenceSource final : public FrameSource {
 public:
  enum class Format { kDepthPng, kPcd };

  FileSequenceSource(std::string directory, Format format, ReplayOptions replay);

  // Lists the files (and reads intrinsics.json for PNG). kNotFound when the directory or the
  // intrinsics are missing, kInvalidArgument when it holds no frame of the format.
  Status Open() override;
  Result<Frame> Next() override;
  void Close() override;

  std::string kind() const override;
  std::string description() const override { return directory_; }
  bool live() const override { return false; }
  long frame_count() const override { return static_cast<long>(files_.size()); }

 private:
  std::string directory_;
  Format format_;
  ReplayOptions replay_;
  Intrinsics intrinsics_;
  std::vector<std::string> files_;
  size_t next_index_ = 0;  // into files_.
  std::uint64_t sequence_ = 0;
  std::uint64_t epoch_ = 0;  // see Frame::epoch.
  bool opened_before_ = false;
  std::chrono::steady_clock::time_point start_;  // when frame 0 of this pass was due.
  std::uint64_t paced_ = 0;                      // frames since start_.
};

// Lists the regular files in `directory` whose names end with `extension` (e.g. ".png"),
// sorted by name, as full paths. kNotFound when the directory cannot be read.
Result<std::vector<std::string>> ListFiles(const std::string& directory,
                                           const std::string& extension);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_FILE_SEQUENCE_SOURCE_H_
