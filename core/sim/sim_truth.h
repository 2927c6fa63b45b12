#ifndef HPOSE_CORE_SIM_SIM_TRUTH_H_
#define HPOSE_CORE_SIM_SIM_TRUTH_H_

#include <cstdint>
#include <string>
#include <vector>

#include "core/common/pose2d.h"
#include "core/common/status.h"
#include "core/depth/intrinsics.h"
#include "core/sim/primitive.h"

namespace hpose {

// One rendered frame of a simulation and where the main humanoid stood in it.
struct SimFrameTruth {
  int index = 0;
  std::string depth_file;        // relative to the truth file's directory, e.g. "depth_003.png".
  std::string cloud_file;        // e.g. "cloud_003.pcd" (sensor frame, metres).
  Pose2D humanoid_pose;          // ground frame: metres, radians in (-pi, pi].
  std::uint64_t noise_seed = 0;  // the seed this frame's noise was drawn from.
};

// Another humanoid in the scene (it does not move between frames).
struct SimHumanoidTruth {
  Pose2D pose;
  std::string preset;
};

// Ground truth of a simulation: everything needed to interpret and reproduce its frames.
// Serialised as truth.json (SI units: metres, radians).
struct SimTruth {
  std::string humanoid_preset = "standing";  // joint preset of the main humanoid.
  double humanoid_height_m = 0.0;
  Pose2D humanoid_pose;  // the first frame's pose of the main humanoid.
  std::vector<SimHumanoidTruth> other_humanoids;
  double sensor_height_m = 0.0;   // optical centre above the floor.
  double sensor_pitch_rad = 0.0;  // + looks down (FloorEstimate conventions).
  double sensor_roll_rad = 0.0;
  Intrinsics intrinsics;
  bool noise_enabled = true;
  double noise_correlated_share = 0.0;  // KinectNoiseOptions::correlated_share ...
  int noise_correlation_radius_px = 4;  // ... and correlation_radius_px.
  std::uint64_t seed = 0;               // clutter and noise seed given by the user.
  int clutter_count = 0;                // requested random clutter objects.
  std::vector<Primitive> clutter;       // ground frame.
  std::vector<SimFrameTruth> frames;
  std::string command;  // the command line that produced the frames.
};

// Serialises to JSON text ({"format":"hpose-sim-truth","version":1,...}).
std::string SimTruthToJson(const SimTruth& truth);
// Parses SimTruthToJson's output. Fails (kDataLoss) on malformed JSON, missing or mistyped
// fields, naming `origin` (e.g. the file path) and the field.
Result<SimTruth> ParseSimTruthJson(const std::string& text, const std::string& origin);
// Reads and parses the truth.json at `path`; errors name the file.
Result<SimTruth> LoadSimTruth(const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_SIM_SIM_TRUTH_H_
