#ifndef HPOSE_CORE_STEREO_STEREO_SEQUENCE_H_
#define HPOSE_CORE_STEREO_STEREO_SEQUENCE_H_

#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/stereo/rgb_image.h"

namespace hpose {

// One frame pair of a sequence directory.
struct StereoFrameEntry {
  double timestamp_s = 0.0;
  std::string left_path;
  std::string right_path;
};

// A directory of stereo frame pairs:
//
//   DIR/calibration.yaml   (or .yml / .xml) OpenCV stereo calibration; optional here, the
//                          caller may pass its own
//   DIR/frames.csv         optional: one line per pair "timestamp_s,left,right" (paths relative
//                          to DIR; a first line starting with "timestamp" is a header; lines
//                          starting with '#' are comments)
//   DIR/left/NAME.png      without frames.csv: every image in left/ whose NAME also exists in
//   DIR/right/NAME.png     right/, in name order, at timestamps index / fps
//
// `hpose simulate-stereo` writes this layout (plus ground_truth.csv).
class StereoSequence final {
 public:
  // Lists the pairs. Fails with kNotFound (no directory, or neither frames.csv nor left/ and
  // right/), kDataLoss (malformed frames.csv line, named by number) or kInvalidArgument (a
  // left image without a right one, fps <= 0, timestamps not increasing).
  static Result<StereoSequence> Open(const std::string& dir, double fps = 15.0);

  size_t size() const { return frames_.size(); }
  const StereoFrameEntry& frame(size_t i) const { return frames_[i]; }
  const std::string& dir() const { return dir_; }
  // DIR/calibration.{yaml,yml,xml} when present, else "".
  const std::string& calibration_path() const { return calibration_path_; }

  // Reads pair i. Fails like ReadRgbImage, or with kInvalidArgument when the two images
  // differ in size.
  Result<std::pair<RgbImage, RgbImage>> Load(size_t i) const;

 private:
  std::string dir_;
  std::string calibration_path_;
  std::vector<StereoFrameEntry> frames_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_STEREO_SEQUENCE_H_
