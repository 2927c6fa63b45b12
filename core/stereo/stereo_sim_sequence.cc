#include "core/stereo/stereo_sim_sequence.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>

#include "core/common/clock_limits.h"
#include "core/stereo/rgb_image_io.h"

namespace hpose {
namespace {

int GridCount(double lo, double hi, double step) {
  return static_cast<int>(std::floor((hi - lo) / step + 1e-9)) + 1;
}

Status MakeDirs(const std::string& dir) {
  std::string partial;
  size_t pos = 0;
  while (pos != std::string::npos) {
    pos = dir.find('/', pos + 1);
    partial = dir.substr(0, pos);
    if (partial.empty()) continue;
    if (mkdir(partial.c_str(), 0755) != 0 && errno != EEXIST) {
      return MakeError(ErrorCode::kInternal, partial + ": cannot create directory");
    }
  }
  return Status::Ok();
}

// Ball position after the kick at constant deceleration until it stops.
Eigen::Vector2d RollingBallAt(const StereoSimSequenceSpec& s, double t, bool* moving) {
  const double dt = t - s.kick_time_s;
  const double v0 = s.ball_velocity_mps.norm();
  if (dt <= 0 || v0 <= 0) {
    *moving = false;
    return s.ball_start_m;
  }
  const Eigen::Vector2d dir = s.ball_velocity_mps / v0;
  const double a = s.ball_deceleration_mps2;
  const double t_stop = a > 0 ? v0 / a : std::numeric_limits<double>::infinity();
  const double tt = std::min(dt, t_stop);
  *moving = dt < t_stop;
  return s.ball_start_m + dir * (v0 * tt - 0.5 * a * tt * tt);
}

// Distance from a disc's centre of a straight edge that hides `fraction` of the disc.
double EdgeDistanceForFraction(double fraction, double r) {
  double lo = -r, hi = r;  // DiscCapFraction decreases from 1 to 0 over [-r, r].
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (DiscCapFraction(mid, r) > fraction ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double SegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                       const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double u = std::clamp((p - a).dot(ab) / std::max(1e-12, ab.squaredNorm()), 0.0, 1.0);
  return (a + u * ab - p).norm();
}

// Adds the same-coloured distractors and the occluder of one placement to `scene` and records
// them in `truth`. `eye` is the robot's place (no sphere stands between it and a landmark).
void AddClutter(const StereoSimSequenceSpec& spec, const Eigen::Vector2d& eye,
                const Eigen::Vector2d& ball, std::mt19937_64& rng, SimScene* scene,
                StereoSimTruth* truth) {
  const StereoSimClutterOptions& c = spec.clutter;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double landmark_radius = scene->discs.empty() ? 0.06 : scene->discs.front().radius_m;
  auto clear_of = [&](const Eigen::Vector2d& p, double size, bool sphere) {
    if ((p - ball).norm() < size + spec.ball_radius_m + 0.12) return false;
    for (const Eigen::Vector3d& l : spec.landmarks_m) {
      if ((p - l.head<2>()).norm() < size + landmark_radius + 0.12) return false;
      if (sphere && SegmentDistance(p, eye, l.head<2>()) < size + landmark_radius + 0.05) {
        return false;
      }
    }
    return true;
  };
  auto place = [&](double size, bool sphere, Eigen::Vector2d* where) {
    for (int attempt = 0; attempt < 100; ++attempt) {
      const Eigen::Vector2d p(-0.6 + 1.2 * unit(rng), -0.45 + 1.35 * unit(rng));
      if (clear_of(p, size, sphere)) {
        *where = p;
        return true;
      }
    }
    return false;
  };
  if (unit(rng) < c.same_color_distractor_probability) {
    for (int colour = 0; colour < 2; ++colour) {
      const Rgb8 rgb = colour == 0 ? kSimLandmarkColor : kSimBallColor;
      const int count = 1 + (unit(rng) < 0.5 ? 1 : 0);
      for (int k = 0; k < count; ++k) {
        const int kind = static_cast<int>(unit(rng) * 3);  // disc, cloth, sphere.
        Eigen::Vector2d p;
        if (kind == 0) {
          // Discs: smaller or larger than a landmark, or a landmark's twin.
          const double choices[] = {0.03, 0.06, 0.1};
          const double r = choices[static_cast<int>(unit(rng) * 3)];
          if (!place(r, false, &p)) continue;
          if (colour == 0) {
            scene->discs.push_back(SimDisc{p, r, rgb});
          } else {
            scene->patches.push_back(
                SimPatch{p, Eigen::Vector2d(r, r) * 0.8, unit(rng) * kPi, rgb});
          }
        } else if (kind == 1) {
          const Eigen::Vector2d half(0.04 + 0.1 * unit(rng), 0.02 + 0.05 * unit(rng));
          if (!place(half.norm(), false, &p)) continue;
          scene->patches.push_back(SimPatch{p, half, unit(rng) * kPi, rgb});
        } else {
          // A sphere clearly larger than the ball (a toy, a bigger ball).
          const double r = 0.065 + 0.035 * unit(rng);
          if (!place(r, true, &p)) continue;
          scene->balls.push_back(SimBall{Eigen::Vector3d(p.x(), p.y(), r), r, rgb});
        }
        ++(colour == 0 ? truth->landmark_color_distractors : truth->ball_color_distractors);
      }
    }
  }
  if (unit(rng) < c.occluder_probability) {
    const int k = std::min(2, static_cast<int>(unit(rng) * 3));
    const double fraction = c.occluded_min + (c.occluded_max - c.occluded_min) * unit(rng);
    const double d = EdgeDistanceForFraction(fraction, landmark_radius);
    const double phi = 2 * kPi * unit(rng);
    const Eigen::Vector2d n(std::cos(phi), std::sin(phi));
    const double half_depth = 0.08;
    const Rgb8 neutral[] = {{205, 200, 190}, {85, 80, 78}, {160, 140, 110}};
    scene->patches.push_back(SimPatch{spec.landmarks_m[k].head<2>() + n * (d + half_depth),
                                      Eigen::Vector2d(half_depth, 0.12), phi,
                                      neutral[static_cast<int>(unit(rng) * 3) % 3]});
    truth->landmark_occluded_fraction[k] = fraction;
  }
}

}  // namespace

void MakeStereoSimHard(StereoSimSequenceSpec* spec) {
  StereoSimNoiseOptions& n = spec->noise;
  n.bayer = true;
  n.pixel_noise_sigma = 2.0;
  n.shot_noise = 0.35;
  n.vignetting = 0.35;
  n.jpeg_quality = 80;
  n.speckles_per_image = 3;
  n.speckle_colors = {kSimLandmarkColor, kSimBallColor};
  spec->clutter.same_color_distractor_probability = 0.4;
  spec->clutter.occluder_probability = 0.15;
  spec->clutter.carpet_fine_contrast = 0.12;
  spec->clutter.carpet_coarse_contrast = 0.25;
}

const char* StereoSimScenarioName(StereoSimScenario scenario) {
  switch (scenario) {
    case StereoSimScenario::kRollingBall:
      return "rolling";
    case StereoSimScenario::kWalking:
      return "walking";
    case StereoSimScenario::kGrid:
      return "grid";
  }
  return "unknown";
}

Result<StereoSimScenario> ParseStereoSimScenario(const std::string& name) {
  for (StereoSimScenario s :
       {StereoSimScenario::kRollingBall, StereoSimScenario::kWalking, StereoSimScenario::kGrid}) {
    if (name == StereoSimScenarioName(s)) return s;
  }
  return MakeError(ErrorCode::kInvalidArgument,
                   "unknown scenario '" + name + "' (rolling, walking or grid)");
}

Status ValidateStereoSimSequenceSpec(const StereoSimSequenceSpec& s) {
  auto bad = [](const std::string& what) {
    return Status(MakeError(ErrorCode::kInvalidArgument, "simulation: " + what));
  };
  if (s.camera.width < 16 || s.camera.height < 16 || s.camera.width > 4096 ||
      s.camera.height > 4096) {
    return bad("image size must be within 16..4096 pixels");
  }
  if (!(s.camera.hfov_deg > 10 && s.camera.hfov_deg < 150)) return bad("hfov must be 10..150 deg");
  if (!(s.camera.baseline_m > 0.005 && s.camera.baseline_m < 2)) return bad("baseline 0.005..2 m");
  if (!(s.camera.head_height_m > 0.05)) return bad("head height must exceed 0.05 m");
  if (s.noise.supersample < 1 || s.noise.supersample > 4) return bad("supersample must be 1..4");
  if (!(s.noise.pixel_noise_sigma >= 0)) return bad("pixel noise must be >= 0");
  if (!(s.noise.gain_min > 0 && s.noise.gain_max >= s.noise.gain_min)) return bad("gain range");
  if (!FrameRateInRange(s.fps)) return bad("fps must be 0.01..10000");  // as hposed's.
  if (s.frames < 1 || s.frames > 100000) return bad("frames must be 1..100000");
  if (!(s.ball_radius_m > 0 && s.ball_radius_m <= 1)) return bad("ball radius must be 0..1 m");
  if (!(std::abs(s.robot_speed_mps) <= 2.0)) return bad("robot speed must be within +-2 m/s");
  if (s.noise.jpeg_quality < 0 || s.noise.jpeg_quality > 100) return bad("JPEG quality 0..100");
  if (!(s.noise.vignetting >= 0 && s.noise.vignetting < 1)) return bad("vignetting must be 0..1");
  if (!(s.clutter.occluded_min >= 0 && s.clutter.occluded_max <= 0.9 &&
        s.clutter.occluded_min <= s.clutter.occluded_max)) {
    return bad("occluded fraction range must be within 0..0.9");
  }
  if (s.scenario == StereoSimScenario::kGrid &&
      (!(s.grid_step_m > 0) || s.grid_x_max_m < s.grid_x_min_m || s.grid_y_max_m < s.grid_y_min_m ||
       s.frames_per_position < 1)) {
    return bad("grid ranges/step/frames_per_position");
  }
  return Status::Ok();
}

int StereoSimFrameCount(const StereoSimSequenceSpec& s) {
  if (s.scenario != StereoSimScenario::kGrid) return s.frames;
  return GridCount(s.grid_x_min_m, s.grid_x_max_m, s.grid_step_m) *
         GridCount(s.grid_y_min_m, s.grid_y_max_m, s.grid_step_m) * s.frames_per_position;
}

Status GenerateStereoSimSequence(const StereoSimSequenceSpec& spec,
                                 const std::function<Status(const StereoSimFrame&)>& sink) {
  Status valid = ValidateStereoSimSequenceSpec(spec);
  if (!valid.ok()) return valid;
  const StereoSceneSimulator sim(spec.camera, spec.noise);
  SimScene base = MakeFieldScene(spec.landmarks_m, spec.distractors, spec.seed);
  if (spec.clutter.carpet_fine_contrast >= 0) {
    base.carpet_fine_contrast = spec.clutter.carpet_fine_contrast;
  }
  if (spec.clutter.carpet_coarse_contrast >= 0) {
    base.carpet_coarse_contrast = spec.clutter.carpet_coarse_contrast;
  }
  std::mt19937_64 rng(spec.seed * 7919 + 17);
  const int n = StereoSimFrameCount(spec);
  const Eigen::Vector2d centroid =
      (spec.landmarks_m[0] + spec.landmarks_m[1] + spec.landmarks_m[2]).head<2>() / 3.0;
  const int nx = GridCount(spec.grid_x_min_m, spec.grid_x_max_m, spec.grid_step_m);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> phase(0.0, 10.0);
  Pose2D grid_pose;
  Eigen::Vector2d grid_ball = spec.ball_start_m;
  // Clutter of the current placement (a grid position, or the whole sequence).
  SimScene cluttered = base;
  StereoSimTruth clutter_truth;
  std::mt19937_64 clutter_rng(spec.seed * 104729 + 3);
  if (spec.scenario != StereoSimScenario::kGrid) {
    AddClutter(spec, Eigen::Vector2d(spec.robot_start.x, spec.robot_start.y), spec.ball_start_m,
               clutter_rng, &cluttered, &clutter_truth);
  }
  for (int i = 0; i < n; ++i) {
    StereoSimFrame frame;
    frame.index = i;
    frame.timestamp_s = i / spec.fps;
    Pose2D robot = spec.robot_start;
    HeadSway sway;
    Eigen::Vector2d ball = spec.ball_start_m;
    switch (spec.scenario) {
      case StereoSimScenario::kRollingBall:
        ball = RollingBallAt(spec, frame.timestamp_s, &frame.object_moving);
        if (spec.sway_enabled) sway = spec.sway.At(frame.timestamp_s);
        break;
      case StereoSimScenario::kWalking:
        robot.x += std::cos(robot.theta) * spec.robot_speed_mps * frame.timestamp_s;
        robot.y += std::sin(robot.theta) * spec.robot_speed_mps * frame.timestamp_s;
        if (spec.sway_enabled) sway = spec.sway.At(frame.timestamp_s);
        break;
      case StereoSimScenario::kGrid: {
        const int cell = i / spec.frames_per_position;
        if (i % spec.frames_per_position == 0) {
          grid_pose.x = spec.grid_x_min_m + (cell % nx) * spec.grid_step_m;
          grid_pose.y = spec.grid_y_min_m + (cell / nx) * spec.grid_step_m;
          grid_pose.theta =
              NormalizeAngle(std::atan2(centroid.y() - grid_pose.y, centroid.x() - grid_pose.x) +
                             DegToRad(spec.heading_jitter_deg) * unit(rng));
          // A ball somewhere between the robot and the landmarks, clear of the discs.
          for (int attempt = 0; attempt < 100; ++attempt) {
            const Eigen::Vector2d b(0.4 * unit(rng), 0.15 + 0.45 * unit(rng));
            bool clear = true;
            for (const SimDisc& d : base.discs) {
              clear &= (b - d.centre_m).norm() > d.radius_m + spec.ball_radius_m + 0.03;
            }
            // Not in the line of sight from the robot to a landmark either.
            const Eigen::Vector2d eye(grid_pose.x, grid_pose.y);
            for (const Eigen::Vector3d& l : spec.landmarks_m) {
              const Eigen::Vector2d seg = l.head<2>() - eye;
              const double u = std::clamp((b - eye).dot(seg) / seg.squaredNorm(), 0.0, 1.0);
              clear &= (eye + u * seg - b).norm() > 0.06 + spec.ball_radius_m + 0.03;
            }
            if (clear) {
              grid_ball = b;
              break;
            }
          }
          cluttered = base;
          clutter_truth = StereoSimTruth();
          AddClutter(spec, Eigen::Vector2d(grid_pose.x, grid_pose.y), grid_ball, clutter_rng,
                     &cluttered, &clutter_truth);
        }
        robot = grid_pose;
        ball = grid_ball;
        break;
      }
    }
    SimScene scene = cluttered;
    scene.balls.insert(scene.balls.begin(),
                       SimBall{Eigen::Vector3d(ball.x(), ball.y(), spec.ball_radius_m),
                               spec.ball_radius_m, kSimBallColor});
    StereoSceneSimulator::Pair pair =
        sim.RenderPair(robot, sway, scene, spec.seed * 1000003ull + static_cast<std::uint64_t>(i));
    frame.left = std::move(pair.left);
    frame.right = std::move(pair.right);
    frame.truth = pair.truth;
    frame.truth.landmark_occluded_fraction = clutter_truth.landmark_occluded_fraction;
    frame.truth.landmark_color_distractors = clutter_truth.landmark_color_distractors;
    frame.truth.ball_color_distractors = clutter_truth.ball_color_distractors;
    Status s = sink(frame);
    if (!s.ok()) return s;
  }
  return Status::Ok();
}

Status WriteStereoSimSequence(const StereoSimSequenceSpec& spec, const std::string& dir,
                              const std::function<Status(const StereoSimFrame&)>& also) {
  Status valid = ValidateStereoSimSequenceSpec(spec);
  if (!valid.ok()) return valid;
  for (const std::string& d : {dir, dir + "/left", dir + "/right"}) {
    Status s = MakeDirs(d);
    if (!s.ok()) return s;
  }
  {
    StereoSimNoiseOptions quiet;
    quiet.supersample = 1;
    const StereoSceneSimulator sim_for_cal(spec.camera, quiet);
    Status s = WriteStereoCalibration(sim_for_cal.calibration(), dir + "/calibration.yaml");
    if (!s.ok()) return s;
  }
  std::ofstream frames(dir + "/frames.csv");
  std::ofstream truth(dir + "/ground_truth.csv");
  if (!frames || !truth) return MakeError(ErrorCode::kInternal, dir + ": cannot write CSV files");
  frames << "timestamp_s,left,right\n";
  truth << "index,timestamp_s,robot_x_m,robot_y_m,robot_theta_rad,head_x_m,head_y_m,"
           "head_theta_rad,head_z_m,object_present,object_x_m,object_y_m,object_z_m,"
           "object_moving,occluded_p0,occluded_p1,occluded_p2,landmark_color_distractors,"
           "ball_color_distractors\n";
  frames.precision(9);
  truth.precision(9);
  Status status = GenerateStereoSimSequence(spec, [&](const StereoSimFrame& f) -> Status {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", f.index);
    Status s = WriteRgbPng(f.left, dir + "/left/" + name);
    if (!s.ok()) return s;
    s = WriteRgbPng(f.right, dir + "/right/" + name);
    if (!s.ok()) return s;
    frames << f.timestamp_s << ",left/" << name << ",right/" << name << "\n";
    const StereoSimTruth& t = f.truth;
    truth << f.index << "," << f.timestamp_s << "," << t.robot_nominal.x << "," << t.robot_nominal.y
          << "," << t.robot_nominal.theta << "," << t.head.x << "," << t.head.y << ","
          << t.head.theta << "," << t.head_position_m.z() << "," << (t.object_present ? 1 : 0)
          << "," << t.object_world_m.x() << "," << t.object_world_m.y() << ","
          << t.object_world_m.z() << "," << (f.object_moving ? 1 : 0) << ","
          << t.landmark_occluded_fraction[0] << "," << t.landmark_occluded_fraction[1] << ","
          << t.landmark_occluded_fraction[2] << "," << t.landmark_color_distractors << ","
          << t.ball_color_distractors << "\n";
    return also ? also(f) : Status::Ok();
  });
  if (!status.ok()) return status;
  frames.close();
  truth.close();
  if (!frames || !truth) return MakeError(ErrorCode::kInternal, dir + ": cannot write CSV files");
  return Status::Ok();
}

}  // namespace hpose
