#ifndef HPOSE_CORE_SIM_FRAME_SIMULATOR_H_
#define HPOSE_CORE_SIM_FRAME_SIMULATOR_H_

#include <cstdint>
#include <memory>
#include <string>

#include "core/common/pose2d.h"
#include "core/common/status.h"
#include "core/depth/depth_image.h"
#include "core/depth/floor_estimate.h"
#include "core/depth/intrinsics.h"
#include "core/sim/mesh_bvh.h"

namespace hpose {

// One simulated depth frame of one humanoid on a floor, with optional random clutter: the
// common case of the simulator in one call. Defaults are the paper's set-up (SPEC §1): sensor
// 0.34 m above the floor, level; humanoid 1 m in front of it, facing away (theta = 0).
struct FrameSpec {
  std::string preset = "standing";  // humanoid joint preset (HumanoidJoints::Preset).
  std::string body = "nao";         // humanoid proportions (HumanoidDimensions::Variant).
  // When set, this robot (a mesh in its template frame, e.g. UrdfRobot::Pose's) is rendered
  // instead of the parametric humanoid, and `preset` and `body` are ignored. Build it once
  // with MeshBvh::Build and share it between frames.
  std::shared_ptr<const MeshBvh> robot_mesh;
  Pose2D humanoid_pose{1.0, 0.0, 0.0};
  double sensor_height_m = 0.34;
  double sensor_pitch_rad = 0.0;  // + looks down.
  double sensor_roll_rad = 0.0;
  Intrinsics intrinsics = Intrinsics::KinectV1(640, 480);
  int clutter = 0;                      // random clutter objects (a ball, boxes, cylinders).
  std::uint64_t seed = 0;               // clutter and noise.
  bool noise = true;                    // Kinect v1 noise model (SPEC §5).
  double noise_correlated_share = 0.0;  // KinectNoiseOptions::correlated_share.
};

struct SimulatedFrame {
  DepthImage depth;
  FloorEstimate sensor_mount;  // the true floor (ground_from_sensor) of this frame.
  double humanoid_height_m = 0.0;
};

// Renders the frame. Fails (kInvalidArgument) on an unknown preset or body, bad intrinsics or a
// sensor below the floor, naming the problem; kFailedPrecondition when the clutter does not fit.
Result<SimulatedFrame> SimulateFrame(const FrameSpec& spec);

}  // namespace hpose

#endif  // HPOSE_CORE_SIM_FRAME_SIMULATOR_H_
