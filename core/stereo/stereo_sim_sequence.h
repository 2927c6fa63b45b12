#ifndef HPOSE_CORE_STEREO_STEREO_SIM_SEQUENCE_H_
#define HPOSE_CORE_STEREO_STEREO_SIM_SEQUENCE_H_

#include <array>
#include <cstdint>
#include <functional>
#include <string>

#include <Eigen/Core>

#include "core/common/pose2d.h"
#include "core/common/status.h"
#include "core/stereo/stereo_scene_simulator.h"

namespace hpose {

enum class StereoSimScenario {
  kRollingBall,  // robot standing (swaying), ball at rest, then kicked towards the robot.
  kWalking,      // robot walking forward with head sway, ball at rest.
  kGrid,         // the paper's protocol: robot standing on a grid of positions, ball at rest.
};
// "rolling" | "walking" | "grid"; ParseStereoSimScenario fails with kInvalidArgument.
const char* StereoSimScenarioName(StereoSimScenario scenario);
Result<StereoSimScenario> ParseStereoSimScenario(const std::string& name);

// Objects that make a scene hard (all off by default). A "placement" is one grid position, or
// the whole rolling/walking sequence; each draws its clutter independently.
struct StereoSimClutterOptions {
  // Probability that a placement has distractors of the landmarks' colour and of the ball's
  // colour (1..2 of each: discs and cloths of other sizes, larger spheres) near the landmarks.
  double same_color_distractor_probability = 0.0;
  // Probability that a placement has an occluder (a neutral sheet) lying over part of one
  // landmark disc, hiding between occluded_min and occluded_max of its area.
  double occluder_probability = 0.0;
  double occluded_min = 0.1;
  double occluded_max = 0.45;
  // Carpet texture of the floor (see SimScene); negative keeps the scene's default.
  double carpet_fine_contrast = -1.0;
  double carpet_coarse_contrast = -1.0;
};

// Everything that defines a simulated sequence; defaults in one place. World frame = field
// frame of the landmarks (z up), metres, radians, seconds.
struct StereoSimSequenceSpec {
  StereoSimScenario scenario = StereoSimScenario::kRollingBall;
  StereoSimCameraOptions camera;
  StereoSimNoiseOptions noise;
  HeadSwayModel sway;
  bool sway_enabled = true;  // grid frames are always taken standing still (no sway).
  std::array<Eigen::Vector3d, 3> landmarks_m = {Eigen::Vector3d(0.0, 0.0, 0.0),
                                                Eigen::Vector3d(-0.25, 0.4, 0.0),
                                                Eigen::Vector3d(0.25, 0.4, 0.0)};
  bool distractors = true;
  StereoSimClutterOptions clutter;
  int frames = 60;    // rolling and walking scenarios.
  double fps = 15.0;  // frame rate.
  Pose2D robot_start{0.05, -1.0, kPi / 2};
  double robot_speed_mps = 0.06;  // walking scenario, forward.
  double ball_radius_m = 0.035;
  Eigen::Vector2d ball_start_m{0.35, 0.1};
  double kick_time_s = 1.6;  // rolling scenario.
  Eigen::Vector2d ball_velocity_mps{-0.12, -0.45};
  double ball_deceleration_mps2 = 0.12;  // rolling friction.
  // Grid scenario: robot positions (x, y) on this grid, facing the landmarks' centroid with a
  // random heading offset, `frames_per_position` frames each, ball at a random place.
  double grid_x_min_m = -0.3, grid_x_max_m = 0.4;
  double grid_y_min_m = -1.3, grid_y_max_m = -0.7;
  double grid_step_m = 0.1;
  int frames_per_position = 4;
  double heading_jitter_deg = 8.0;
  std::uint64_t seed = 1;
};

// Turns on everything that makes frames look like a real rig's: carpet texture, vignetting,
// Bayer sampling with shot noise and demosaicing, JPEG (quality 80), speckles of the landmark
// and ball colours, same-coloured distractors in 40 % of placements and occluders in 15 %.
void MakeStereoSimHard(StereoSimSequenceSpec* spec);

// Fails with kInvalidArgument naming the first bad field.
Status ValidateStereoSimSequenceSpec(const StereoSimSequenceSpec& spec);

struct StereoSimFrame {
  int index = 0;
  double timestamp_s = 0.0;
  RgbImage left;
  RgbImage right;
  StereoSimTruth truth;
  bool object_moving = false;  // the ball is rolling at this instant.
};

// Number of frames the spec produces.
int StereoSimFrameCount(const StereoSimSequenceSpec& spec);

// Renders the frames in order and hands each to `sink`; stops at the first error (from the spec
// or the sink). Deterministic for a given spec.
Status GenerateStereoSimSequence(const StereoSimSequenceSpec& spec,
                                 const std::function<Status(const StereoSimFrame&)>& sink);

// Writes the sequence in the StereoSequence directory layout: calibration.yaml, left/NNNNNN.png,
// right/NNNNNN.png, frames.csv, and ground_truth.csv (index, timestamp_s, nominal robot pose,
// head pose = what the estimator measures, head height, object presence, position and motion,
// the occluded fraction of each landmark and the number of same-coloured distractors).
// Creates `dir` (and parents) if needed. Fails with kInternal when a file cannot be written.
// `also`, when given, sees every frame after it was written (e.g. to render what another
// sensor sees at that instant); its error stops the writing.
Status WriteStereoSimSequence(const StereoSimSequenceSpec& spec, const std::string& dir,
                              const std::function<Status(const StereoSimFrame&)>& also = nullptr);

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_STEREO_SIM_SEQUENCE_H_
