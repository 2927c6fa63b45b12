#ifndef HPOSE_CORE_STEREO_LOCAL_MARKER_ESTIMATOR_H_
#define HPOSE_CORE_STEREO_LOCAL_MARKER_ESTIMATOR_H_

#include <array>
#include <memory>

#include <Eigen/Core>

#include "core/common/status.h"
#include "core/stereo/color_segmenter.h"
#include "core/stereo/rgb_image.h"
#include "core/stereo/stereo_calibration.h"

namespace hpose {

struct LocalMarkerOptions {
  // Colour of the two markers on the robot's body (left and right of its feet).
  HsvRange marker_color{285.0, 330.0, 0.45, 1.0, 0.15, 1.0};
  HsvRange object_color{8.0, 40.0, 0.5, 1.0, 0.15, 1.0};
  double marker_spacing_m = 0.12;  // distance between the markers' centres.
  // Height of the object's centre above the markers' plane (e.g. ball radius minus marker
  // height), metres; its image offset is scaled to that depth.
  double object_height_above_markers_m = 0.0;
  ColorSegmenterOptions segmentation;
};

// The local mode, from one image: the camera looks straight down at the robot's feet, with the
// image's top edge towards the robot's front. Origin = the midpoint of the two markers; +y from
// the right marker to the left marker; +x forward (perpendicular, towards the image top); metres.
struct LocalObjectResult {
  Eigen::Vector2d object_in_robot_m = Eigen::Vector2d::Zero();
  double marker_depth_m = 0.0;                 // distance of the camera from the markers' plane.
  std::array<Eigen::Vector2d, 2> marker_px{};  // distorted centroids: [0] right, [1] left.
  Eigen::Vector2d object_px = Eigen::Vector2d::Zero();
};

class LocalMarkerEstimator final {
 public:
  // Fails with kInvalidArgument for an invalid camera or options.
  static Result<std::unique_ptr<LocalMarkerEstimator>> Create(const CameraModel& camera,
                                                              const LocalMarkerOptions& options);

  // Fails with kInvalidArgument for an invalid image and kFailedPrecondition when not exactly
  // two marker blobs or no object blob are seen (the message says which).
  Result<LocalObjectResult> Process(const RgbImage& image) const;

 private:
  LocalMarkerEstimator(const CameraModel& camera, ColorSegmenter segmenter,
                       const LocalMarkerOptions& options);

  CameraModel camera_;
  ColorSegmenter segmenter_;
  LocalMarkerOptions options_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_LOCAL_MARKER_ESTIMATOR_H_
