#ifndef HPOSE_CORE_STEREO_COLOR_SEGMENTER_H_
#define HPOSE_CORE_STEREO_COLOR_SEGMENTER_H_

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/status.h"
#include "core/stereo/rgb_image.h"

namespace hpose {

// A colour class as a box in HSV. Hue in degrees [0, 360); when hue_min_deg > hue_max_deg the
// range wraps through 0 (e.g. 340..20 for red). Saturation and value in [0, 1].
struct HsvRange {
  double hue_min_deg = 0.0;
  double hue_max_deg = 360.0;
  double sat_min = 0.0;
  double sat_max = 1.0;
  double val_min = 0.0;
  double val_max = 1.0;

  bool Contains(double hue_deg, double sat, double val) const;
};

// Fails with kInvalidArgument naming `what` when a bound is non-finite or out of range, or a
// minimum exceeds its maximum (hue excepted: it wraps).
Status ValidateHsvRange(const HsvRange& range, const std::string& what);

// One connected component of a colour class.
struct ColorBlob {
  Eigen::Vector2d centroid_px = Eigen::Vector2d::Zero();  // pixel centres at integer coordinates.
  Eigen::Vector2d mask_centroid_px = Eigen::Vector2d::Zero();  // of the binary mask alone.
  int area_px = 0;
  int min_x = 0, min_y = 0, max_x = 0, max_y = 0;  // bounding box, inclusive, pixels.
};

struct ColorSegmenterOptions {
  int min_blob_area_px = 8;  // smaller components are noise and are dropped.
  int connectivity = 8;      // 4 or 8.
  // Refine each centroid to sub-pixel accuracy: pixels of the blob and its one-pixel outer ring
  // are weighted by their estimated coverage, the projection of their colour between the
  // blob's mean colour and its surroundings' mean colour (clamped to [0, 1]). Without it the
  // centroid is that of the binary mask, which is quantised along the blob's edge.
  bool subpixel_centroids = true;
};

// Colour segmentation, connected-component labelling and per-component centroids.
// The colour test is a lookup table over RGB quantised to 6 bits per channel, filled once by
// converting every table colour to HSV with OpenCV; labelling is OpenCV's
// connectedComponentsWithStats on each class's region of interest.
class ColorSegmenter final {
 public:
  // Up to 254 classes; a pixel that falls in several ranges goes to the first. Fails with
  // kInvalidArgument for an invalid range or option.
  static Result<ColorSegmenter> Create(const std::vector<HsvRange>& classes,
                                       const ColorSegmenterOptions& options = {});

  // Blobs of every class (outer index = class, in the order given to Create), each list sorted
  // by area, largest first. The image must be valid (asserts).
  std::vector<std::vector<ColorBlob>> Segment(const RgbImage& image) const;

  // Class index of one colour, or -1 when it is in no class (same quantised table as Segment).
  int Classify(std::uint8_t r, std::uint8_t g, std::uint8_t b) const;

  int num_classes() const { return num_classes_; }

 private:
  ColorSegmenter() = default;

  std::vector<std::uint8_t> table_;  // 2^18 entries: class index + 1, 0 = none.
  int num_classes_ = 0;
  ColorSegmenterOptions options_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_COLOR_SEGMENTER_H_
