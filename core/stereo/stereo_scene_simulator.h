#ifndef HPOSE_CORE_STEREO_STEREO_SCENE_SIMULATOR_H_
#define HPOSE_CORE_STEREO_STEREO_SCENE_SIMULATOR_H_

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/pose2d.h"
#include "core/stereo/rgb_image.h"
#include "core/stereo/stereo_calibration.h"
#include "core/stereo/stereo_rig.h"

namespace hpose {

using Rgb8 = std::array<std::uint8_t, 3>;

// A flat coloured disc lying on the floor (world frame, z up, metres).
struct SimDisc {
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();
  double radius_m = 0.04;
  Rgb8 color{40, 70, 190};
};

// A matte sphere (the ball).
struct SimBall {
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  double radius_m = 0.035;
  Rgb8 color{225, 105, 25};
};

// A flat rectangle lying on the floor (a cloth, a sheet of paper), drawn over the discs: a
// distractor when it has a landmark's or the ball's colour, an occluder when it covers part of
// a landmark disc.
struct SimPatch {
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d half_size_m{0.05, 0.05};  // along its own x and y axes.
  double yaw_rad = 0.0;                     // of its x axis from world +x.
  Rgb8 color{200, 200, 200};

  bool Contains(const Eigen::Vector2d& p) const;
};

// What the cameras see: a floor (carpet with a 0.1 m grid sheet), discs on it, patches over
// the discs, balls (spheres; the first is the tracked object, the others distractors).
struct SimScene {
  std::vector<SimDisc> discs;
  std::vector<SimPatch> patches;
  std::vector<SimBall> balls;
  Rgb8 floor_color{60, 110, 65};
  Rgb8 grid_color{150, 165, 150};
  double grid_spacing_m = 0.1;
  double grid_line_width_m = 0.004;
  Rgb8 wall_color{180, 170, 150};  // rays that miss the floor within 6 m.
  Eigen::Vector3d light_direction = Eigen::Vector3d(0.3, -0.4, 1.0);  // towards the light.
  // Carpet texture: relative brightness variation of 2 cm cells (fine) and of a smooth
  // pattern of carpet_scale_m (coarse), both multiplicative.
  double carpet_fine_contrast = 0.06;
  double carpet_coarse_contrast = 0.0;
  double carpet_scale_m = 0.15;
};

// Simulated stereo head. The left camera's calibration is the reference; the right camera is
// baseline_m to its right with a small mounting error.
struct StereoSimCameraOptions {
  int width = 512;   // pixels.
  int height = 240;  // pixels.
  double hfov_deg = 60.0;
  // fy / fx; <= 0 means the image spans a 4:3 field of view (512x240 NTSC fields: 0.625).
  double pixel_aspect = 0.0;
  std::vector<double> distortion{-0.22, 0.06, 0.0006, -0.0004, 0.0};  // k1 k2 p1 p2 k3.
  double baseline_m = 0.07;
  double right_yaw_deg = 0.6;  // mounting error of the right camera (toe-in), degrees.
  double right_roll_deg = 0.4;
  double right_focal_scale = 1.01;
  // Head on the robot: height of the head centre above the floor and downward tilt.
  double head_height_m = 0.45;
  double head_tilt_deg = 20.0;
};

// Sway of the head while walking, relative to its nominal place on the robot.
struct HeadSway {
  double lateral_m = 0.0;   // towards the robot's left.
  double vertical_m = 0.0;  // up.
  double roll_rad = 0.0;
  double pitch_rad = 0.0;  // positive tilts further down.
  double yaw_rad = 0.0;
};

// Amplitudes of the walking sway; the sway follows the step cycle.
struct HeadSwayModel {
  double step_frequency_hz = 1.6;
  double lateral_m = 0.02;
  double vertical_m = 0.006;
  double roll_deg = 3.0;
  double pitch_deg = 1.5;
  double yaw_deg = 2.0;

  HeadSway At(double t_s) const;
};

struct StereoSimNoiseOptions {
  double pixel_noise_sigma = 2.5;  // Gaussian noise per channel, grey levels.
  double gain_min = 0.8;           // per-frame global lighting gain range.
  double gain_max = 1.15;
  double gradient = 0.15;  // brightness change across the image width (fraction).
  double left_right_gain_difference = 0.05;
  int supersample = 3;  // samples per pixel along each axis (anti-aliasing).
  // Darkening towards the corners: brightness factor 1 - vignetting * (r / r_corner)^2.
  double vignetting = 0.0;
  // Single-chip colour sensor: the image is sampled through an RGGB Bayer mosaic, noise is
  // added per photosite (pixel_noise_sigma plus shot noise shot_noise * sqrt(level)), then the
  // mosaic is demosaiced (OpenCV, edge-aware). Without it noise is added per RGB channel.
  bool bayer = false;
  double shot_noise = 0.0;
  int jpeg_quality = 0;  // 1..100: JPEG-compress and decode each image; 0: none.
  // Up to this many small speckles (2..4 px across) of the colours in speckle_colors per image,
  // placed independently in the two images (dust, reflections, noise clusters).
  int speckles_per_image = 0;
  std::vector<Rgb8> speckle_colors;
};

// Ground truth of one rendered pair.
struct StereoSimTruth {
  Pose2D robot_nominal;  // the robot's walking pose, without sway (world frame).
  Pose2D head;           // head centre projected on the floor, heading of the optical axis:
                         // the quantity the stereo-marker estimator measures.
  Eigen::Vector3d head_position_m = Eigen::Vector3d::Zero();
  Eigen::Isometry3d world_from_left = Eigen::Isometry3d::Identity();
  bool object_present = false;
  Eigen::Vector3d object_world_m = Eigen::Vector3d::Zero();
  // Filled by the sequence generator: fraction of each landmark disc (P0, P1, P2) hidden under
  // an occluder patch, and how many distractors of the landmarks' / the ball's colour are in
  // the scene (their places are in the scene itself).
  std::array<double, 3> landmark_occluded_fraction{0.0, 0.0, 0.0};
  int landmark_color_distractors = 0;
  int ball_color_distractors = 0;
};

// Renders stereo pairs of a field by ray casting through the distorted lenses.
class StereoSceneSimulator final {
 public:
  explicit StereoSceneSimulator(const StereoSimCameraOptions& camera = {},
                                const StereoSimNoiseOptions& noise = {});
  ~StereoSceneSimulator();

  // The exact calibration of the simulated head (what a perfect calibration would give).
  const StereoCalibration& calibration() const { return calibration_; }
  const StereoSimCameraOptions& camera_options() const { return camera_; }

  // The left camera's pose for a robot pose and a head sway.
  Eigen::Isometry3d WorldFromLeft(const Pose2D& robot, const HeadSway& sway) const;

  // Renders one camera looking from `world_from_camera` (camera x right, y down, z forward)
  // with the given lighting gain; `seed` makes the noise reproducible.
  RgbImage Render(StereoSide side, const Eigen::Isometry3d& world_from_camera,
                  const SimScene& scene, double gain, std::uint64_t seed) const;

  struct Pair {
    RgbImage left;
    RgbImage right;
    StereoSimTruth truth;
  };
  // Renders both cameras of the head on a robot at `robot` with `sway`; the ball (first of
  // scene.balls, if any) is the object of the ground truth.
  Pair RenderPair(const Pose2D& robot, const HeadSway& sway, const SimScene& scene,
                  std::uint64_t seed) const;

  // The sensor after the optics: vignetting, speckles, Bayer sampling with noise and
  // demosaicing, JPEG round trip, as configured in the noise options. Render applies it.
  void ApplySensor(RgbImage* image, std::uint64_t seed) const;

 private:
  StereoSimCameraOptions camera_;
  StereoSimNoiseOptions noise_;
  StereoCalibration calibration_;
  // Undistorted normalised ray (x/z, y/z) of every sub-pixel sample, per camera.
  std::vector<Eigen::Vector2f> rays_[2];
};

// The paper's field: three landmark discs at `landmarks` (world, metres), optional distractor
// patches of colours outside the estimator's ranges, and optionally a ball.
SimScene MakeFieldScene(const std::array<Eigen::Vector3d, 3>& landmarks, bool distractors,
                        std::uint64_t seed);

// Default colours of the simulated landmarks and ball.
inline constexpr Rgb8 kSimLandmarkColor{35, 70, 190};
inline constexpr Rgb8 kSimBallColor{225, 105, 25};

// A second, different stereo head: 640x480 with square pixels, strong five-coefficient lens
// distortion (k1 k2 p1 p2 k3), a 76 mm baseline and larger mounting errors.
StereoSimCameraOptions VgaRigCameraOptions();

// Fraction of a disc of radius r hidden by a half-plane whose edge is `d` from its centre
// (d in [-r, r]; d > 0 means the centre is not covered).
double DiscCapFraction(double d, double r);

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_STEREO_SCENE_SIMULATOR_H_
