#ifndef HPOSE_SERVER_FILE_SEQUENCE_SOURCE_H_
#define HPOSE_SERVER_FILE_SEQUENCE_SOURCE_H_

#include <chrono>
#include <string>
#include <vector>

#include "core/depth/intrinsics.h"
#include "server/frame_source.h"

namespace hpose::server {

// Frames from files, replayed in file-name order: a directory of frames of one format, or a
// single file. Formats: 16-bit PNG or TIFF depth images (millimetres), PCL's pclzf depth images
// (with their .xml camera parameters), or PCD clouds (sensor frame, metres).
//
// Intrinsics of depth images, first that applies: ReplayOptions::intrinsics when given; the
// intrinsics.json in the frames' directory; the file's own (.xml of a pclzf); for TIFF, Kinect
// v1 defaults for the image size (PCL's grabbers write Kinect frames); PNG frames need one of
// the first two.
//
// Source time: when every file name records a time (TimeFromFrameFileName), that time; else
// frame i of the pass is at i / fps. Recorded-rate replay follows these times.
class FileSequenceSource final : public FrameSource {
 public:
  enum class Format { kDepthPng, kPcd, kDepthTiff, kDepthPclzf };

  // `path` is a directory (its frames of `format`) or one file of that format.
  FileSequenceSource(std::string path, Format format, ReplayOptions replay);

  // Lists the files (and reads intrinsics.json when needed). kNotFound when the directory or
  // required intrinsics are missing, kInvalidArgument when it holds no frame of the format.
  Status Open() override;
  Result<Frame> Next() override;
  void Close() override;

  std::string kind() const override;
  std::string description() const override { return path_; }
  bool live() const override { return false; }
  long frame_count() const override { return static_cast<long>(files_.size()); }

  // True when source times come from the file names.
  bool times_from_names() const { return times_from_names_; }

 private:
  std::string path_;
  Format format_;
  ReplayOptions replay_;
  bool has_intrinsics_ = false;  // intrinsics_ applies to every frame.
  Intrinsics intrinsics_;
  std::vector<std::string> files_;
  std::vector<double> times_;  // source time of each file.
  bool times_from_names_ = false;
  size_t next_index_ = 0;  // into files_.
  std::uint64_t sequence_ = 0;
  std::uint64_t epoch_ = 0;  // see Frame::epoch.
  bool opened_before_ = false;
  std::chrono::steady_clock::time_point start_;  // when the first frame of this pass was due.
  double pass_offset_s_ = 0.0;                   // source time that start_ stands for.
};

// Lists the regular files in `directory` whose names end with `extension` (e.g. ".png"),
// sorted by name, as full paths. kNotFound when the directory cannot be read.
Result<std::vector<std::string>> ListFiles(const std::string& directory,
                                           const std::string& extension);

// The frame files of `format` in `directory`: *.png, *.pcd, *_depth.pclzf, and for TIFF the
// *_depth.tif(f) files when there are any (PCL's grabbers write *_rgb.tiff beside them), else
// every *.tif / *.tiff.
Result<std::vector<std::string>> ListFrameFiles(const std::string& directory,
                                                FileSequenceSource::Format format);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_FILE_SEQUENCE_SOURCE_H_
