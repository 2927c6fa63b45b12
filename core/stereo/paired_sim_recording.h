#ifndef HPOSE_CORE_STEREO_PAIRED_SIM_RECORDING_H_
#define HPOSE_CORE_STEREO_PAIRED_SIM_RECORDING_H_

#include <functional>
#include <string>

#include "core/common/pose2d.h"
#include "core/common/status.h"
#include "core/stereo/stereo_sim_sequence.h"

namespace hpose {

// A depth sensor (Kinect v1 model) watching the robot of a simulated stereo sequence from off
// the robot, so that both estimators see the same robot at the same instants.
struct PairedDepthSensorSpec {
  // Where the depth sensor's ground frame lies in the world (landmark) frame: the floor point
  // below its optical centre (x, y, metres) and its optical axis on the floor (theta, radians
  // counter-clockwise from world +x) — what `calibrate world-from-ground` should recover.
  Pose2D world_from_ground{-1.1, -2.1, kPi / 4};
  double height_m = 0.34;  // optical centre above the floor.
  double pitch_rad = 0.0;  // + looks down.
  int width = 320;         // depth image size, pixels (Kinect v1 intrinsics scaled).
  int height = 240;
  int every = 3;  // one depth frame per `every` stereo frames (15 Hz stereo: 5 Hz).
  std::string preset = "standing";  // parametric humanoid's joint preset and proportions.
  std::string body = "nao";
  bool noise = true;  // Kinect v1 noise model.
};

// Fails with kInvalidArgument naming the first bad field.
Status ValidatePairedDepthSensorSpec(const PairedDepthSensorSpec& spec);

// Writes a recording seen by both estimators:
//   DIR/stereo/  the stereo sequence (WriteStereoSimSequence's layout);
//   DIR/depth/   16-bit depth PNGs (millimetres) named by their time in seconds on the stereo
//                sequence's clock ("0001.200000.png", which hposed and `hpose replay` read as
//                the frame time), intrinsics.json, and truth.csv: timestamp_s, the humanoid's
//                pose in the depth sensor's ground frame and in the world frame.
// The humanoid stands at the stereo robot's nominal pose (the stereo head is above it, so the
// template origin and the head coincide on the floor: head_to_reference_m = 0), facing the
// robot's heading. The head sway of a walking robot moves only the stereo head.
// `progress`, when given, is called after each stereo frame with (done, total).
Status WritePairedSimRecording(const StereoSimSequenceSpec& stereo,
                               const PairedDepthSensorSpec& depth, const std::string& dir,
                               const std::function<void(int, int)>& progress = nullptr);

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_PAIRED_SIM_RECORDING_H_
