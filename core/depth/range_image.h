#ifndef HPOSE_CORE_DEPTH_RANGE_IMAGE_H_
#define HPOSE_CORE_DEPTH_RANGE_IMAGE_H_

#include <algorithm>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/depth/point_cloud.h"

namespace hpose {

// Slopes (x / z, y / z in the sensor frame, y down) of a view's edges. NaN: not known.
struct ViewSpan {
  double left = std::numeric_limits<double>::quiet_NaN();
  double right = std::numeric_limits<double>::quiet_NaN();
  double top = std::numeric_limits<double>::quiet_NaN();
  double bottom = std::numeric_limits<double>::quiet_NaN();
};

// What the sensor saw in each direction: the nearest depth (z, metres) per bin of a virtual
// pinhole camera at the sensor's optical centre. Built from any cloud in the sensor frame
// (organised or not, from a depth image or a PCD), so free-space reasoning does not need the
// original intrinsics. Bins without a point are unknown.
class RangeImage {
 public:
  // `focal_px` sets the bin size (300: about 3.3 mm at 1 m, like a 320x240 Kinect). The image
  // spans the cloud's own field of view (tan up to +-3), widened to `at_least` where that is
  // known and wider: a depth image's own edges, so that a direction the sensor looked in and
  // got no return from is known as such, not taken for one it did not look in (a level sensor
  // in an open room has no reading above its tallest object). A NaN edge leaves that side.
  // Sixteen points a step with AVX-512 where the CPU has it (SixteenLanes()), eight with AVX2
  // where it has only that (EightLanes(); FromCloudEightLanes takes that path whatever else the
  // CPU has, for the tests), four otherwise: FromCloudFourLanes, the reference they are tested
  // against. All compute every slope and bin with the same operations, so their images are
  // equal to the bit.
  static RangeImage FromCloud(const PointCloud& cloud_sensor, double focal_px = 300.0,
                              const ViewSpan& at_least = {});
  static RangeImage FromCloudFourLanes(const PointCloud& cloud_sensor, double focal_px = 300.0,
                                       const ViewSpan& at_least = {});
  static RangeImage FromCloudEightLanes(const PointCloud& cloud_sensor, double focal_px = 300.0);
  static bool SixteenLanes();
  static bool EightLanes();

  // Nearest observed depth (m) along the ray through `p_sensor`, or 0 when unknown (no point
  // in that bin, or p_sensor not in front of the sensor).
  float DepthToward(const Eigen::Vector3d& p_sensor) const {
    if (depth_.empty() || !(p_sensor.z() > 1e-3)) return 0.0f;
    const double uf = p_sensor.x() / p_sensor.z() * focal_ + u0_;
    const double vf = p_sensor.y() / p_sensor.z() * focal_ + v0_;
    if (!(uf >= 0.0 && vf >= 0.0 && uf < width_ && vf < height_)) return 0.0f;
    return depth_[static_cast<size_t>(vf) * width_ + static_cast<size_t>(uf)];
  }
  // True when the ray through `p_sensor` lies within the cloud's field of view (the image), so
  // an empty bin there means the sensor got no return, not that it did not look.
  bool Covers(const Eigen::Vector3d& p_sensor) const;
  // Nearest observed depth over the bins within `radius` bins of the ray through `p_sensor`
  // (0 when all are empty or out of view).
  float NearestAround(const Eigen::Vector3d& p_sensor, int radius) const;
  // Covers() and NearestAround() of the ray given by its slopes (x / z, y / z) of a point in
  // front of the sensor, for callers that already divided (inline: the refinement asks for
  // every visible template point).
  bool CoversRay(double tan_x, double tan_y) const {
    if (depth_.empty()) return false;
    const double uf = tan_x * focal_ + u0_;
    const double vf = tan_y * focal_ + v0_;
    return uf >= 0.0 && vf >= 0.0 && uf < width_ && vf < height_;
  }
  float NearestAroundRay(double tan_x, double tan_y, int radius) const {
    if (!CoversRay(tan_x, tan_y)) return 0.0f;
    const int u = static_cast<int>(tan_x * focal_ + u0_);
    const int v = static_cast<int>(tan_y * focal_ + v0_);
    // Branch-free: empty bins (0) count as infinitely far.
    constexpr float kFar = std::numeric_limits<float>::infinity();
    float best = kFar;
    for (int y = std::max(0, v - radius); y <= std::min(height_ - 1, v + radius); ++y) {
      for (int x = std::max(0, u - radius); x <= std::min(width_ - 1, u + radius); ++x) {
        const float d = depth_[static_cast<size_t>(y) * width_ + x];
        best = std::min(best, d > 0.0f ? d : kFar);
      }
    }
    return best == kFar ? 0.0f : best;
  }

  // The binning, for callers that bin many rays themselves: the bin of a ray of slopes (tx, ty)
  // is (floor(tx * focal() + u0()), floor(ty * focal() + v0())) when within the image, and
  // depth_data()[v * width() + u] its depth (0: unknown).
  double focal() const { return focal_; }
  double u0() const { return u0_; }
  double v0() const { return v0_; }
  const float* depth_data() const { return depth_.data(); }

  // Whether any bin's ray (through its centre) points at least `min_down_rad` below the
  // horizon of `ground_from_sensor`'s floor; NearestAroundSteepRays changes nothing otherwise.
  bool HasSteepRays(const Eigen::Isometry3d& ground_from_sensor, double min_down_rad) const;
  // A copy in which every known bin whose ray points at least `min_down_rad` below the horizon
  // holds the nearest known depth among the 3 x 3 bins around it (unknown bins stay unknown).
  RangeImage NearestAroundSteepRays(const Eigen::Isometry3d& ground_from_sensor,
                                    double min_down_rad) const;

  // Tangent (y / z, sensor frame: negative is up) of the image's top row.
  double TopTan() const { return -v0_ / focal_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  // Points a step of the passes over the cloud.
  enum class Lanes { kFour, kEight, kSixteen };
  static RangeImage Build(const PointCloud& cloud_sensor, double focal_px, Lanes lanes,
                          const ViewSpan& at_least);
  double focal_ = 300.0;
  double u0_ = 0.0;  // bin of tan = 0.
  double v0_ = 0.0;
  int width_ = 0;
  int height_ = 0;
  std::vector<float> depth_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_RANGE_IMAGE_H_
