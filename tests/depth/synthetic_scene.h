// Test helper: a tiny ray caster that renders a depth camera's view of a floor with boxes and
// standing cylinders ("people"), independently of the code under test.
#ifndef HPOSE_TESTS_DEPTH_SYNTHETIC_SCENE_H_
#define HPOSE_TESTS_DEPTH_SYNTHETIC_SCENE_H_

#include <vector>

#include <Eigen/Geometry>

#include "core/depth/intrinsics.h"
#include "core/depth/point_cloud.h"

namespace hpose {
namespace testing_scene {

// Axis-aligned box in the ground frame (metres).
struct Box {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
};

// Vertical cylinder standing on the floor, ground frame.
struct Cylinder {
  double x = 0.0;
  double y = 0.0;
  double radius = 0.2;
  double height = 1.7;
};

struct Scene {
  bool floor = true;  // the plane z = 0.
  std::vector<Box> boxes;
  std::vector<Cylinder> cylinders;
};

// Pose of the sensor (optical frame: x right, y down, z forward) in the ground frame, built
// from first principles: a level sensor looking along +x at `height_m`, pitched down by
// `pitch_rad` (about its x axis), then rolled by `roll_rad` about its optical axis with the
// image's right side going down for positive roll. Yaw is zero.
Eigen::Isometry3d GroundFromSensor(double height_m, double pitch_rad, double roll_rad);

struct RenderOptions {
  double max_range_m = 5.0;    // along the ray.
  double noise_sigma_k = 0.0;  // depth noise sigma = k * z^2 (Kinect v1: 1.425e-3).
  unsigned seed = 1;
  bool organised = false;
};

// Casts one ray per pixel through `intrinsics` and returns the nearest hits in the sensor frame.
PointCloud Render(const Scene& scene, const Eigen::Isometry3d& ground_from_sensor,
                  const Intrinsics& intrinsics, const RenderOptions& options = {});

}  // namespace testing_scene
}  // namespace hpose

#endif  // HPOSE_TESTS_DEPTH_SYNTHETIC_SCENE_H_
