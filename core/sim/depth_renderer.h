#ifndef HPOSE_CORE_SIM_DEPTH_RENDERER_H_
#define HPOSE_CORE_SIM_DEPTH_RENDERER_H_

#include <cstdint>

#include "core/common/status.h"
#include "core/depth/depth_image.h"
#include "core/depth/floor_estimate.h"
#include "core/depth/intrinsics.h"
#include "core/sim/kinect_noise_model.h"
#include "core/sim/scene.h"

namespace hpose {

// Renders depth images of a Scene by casting one ray per pixel through pinhole intrinsics and
// intersecting it analytically with the floor and every primitive (bounding spheres per object
// and per primitive skip most tests), and with the triangles of mesh robots (through their
// bounding-volume hierarchies).
class DepthRenderer final {
 public:
  // `sensor_mount` places the sensor: its ground_from_sensor (e.g. from
  // FloorEstimate::FromHeightPitchRoll) maps the sensor frame (x right, y down, z forward) to
  // the scene's ground frame. Fails (kInvalidArgument) on invalid intrinsics, a non-finite
  // transform or a sensor that is not above the floor.
  static Result<DepthRenderer> Create(const Intrinsics& intrinsics,
                                      const FloorEstimate& sensor_mount);

  const Intrinsics& intrinsics() const { return intrinsics_; }
  const FloorEstimate& sensor_mount() const { return sensor_mount_; }

  // Depth in millimetres along the optical axis, 0 where nothing is hit.
  // Without a noise model: the exact depth of the nearest surface through each pixel centre,
  // rounded to 1 mm (nothing beyond 65.535 m). With one: each pixel's ray is jittered, the depth
  // gets the axial noise and quantisation, and the range and incidence limits apply, all drawn
  // from `seed` (the same seed gives the same image).
  DepthImage Render(const Scene& scene, const KinectNoiseModel* noise = nullptr,
                    std::uint64_t seed = 0) const;

 private:
  DepthRenderer(const Intrinsics& intrinsics, const FloorEstimate& sensor_mount)
      : intrinsics_(intrinsics), sensor_mount_(sensor_mount) {}

  Intrinsics intrinsics_;
  FloorEstimate sensor_mount_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SIM_DEPTH_RENDERER_H_
