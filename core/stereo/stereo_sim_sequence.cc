#include "core/stereo/stereo_sim_sequence.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>

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

}  // namespace

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
  if (!(s.fps > 0)) return bad("fps must be > 0");
  if (s.frames < 1 || s.frames > 100000) return bad("frames must be 1..100000");
  if (!(s.ball_radius_m > 0)) return bad("ball radius must be > 0");
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
  std::mt19937_64 rng(spec.seed * 7919 + 17);
  const int n = StereoSimFrameCount(spec);
  const Eigen::Vector2d centroid =
      (spec.landmarks_m[0] + spec.landmarks_m[1] + spec.landmarks_m[2]).head<2>() / 3.0;
  const int nx = GridCount(spec.grid_x_min_m, spec.grid_x_max_m, spec.grid_step_m);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> phase(0.0, 10.0);
  Pose2D grid_pose;
  Eigen::Vector2d grid_ball = spec.ball_start_m;
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
        }
        robot = grid_pose;
        ball = grid_ball;
        break;
      }
    }
    SimScene scene = base;
    scene.balls.push_back(SimBall{Eigen::Vector3d(ball.x(), ball.y(), spec.ball_radius_m),
                                  spec.ball_radius_m, Rgb8{225, 105, 25}});
    StereoSceneSimulator::Pair pair =
        sim.RenderPair(robot, sway, scene, spec.seed * 1000003ull + static_cast<std::uint64_t>(i));
    frame.left = std::move(pair.left);
    frame.right = std::move(pair.right);
    frame.truth = pair.truth;
    Status s = sink(frame);
    if (!s.ok()) return s;
  }
  return Status::Ok();
}

Status WriteStereoSimSequence(const StereoSimSequenceSpec& spec, const std::string& dir) {
  Status valid = ValidateStereoSimSequenceSpec(spec);
  if (!valid.ok()) return valid;
  for (const std::string& d : {dir, dir + "/left", dir + "/right"}) {
    Status s = MakeDirs(d);
    if (!s.ok()) return s;
  }
  {
    const StereoSceneSimulator sim_for_cal(spec.camera, StereoSimNoiseOptions{0, 1, 1, 0, 0, 1});
    Status s = WriteStereoCalibration(sim_for_cal.calibration(), dir + "/calibration.yaml");
    if (!s.ok()) return s;
  }
  std::ofstream frames(dir + "/frames.csv");
  std::ofstream truth(dir + "/ground_truth.csv");
  if (!frames || !truth) return MakeError(ErrorCode::kInternal, dir + ": cannot write CSV files");
  frames << "timestamp_s,left,right\n";
  truth << "index,timestamp_s,robot_x_m,robot_y_m,robot_theta_rad,head_x_m,head_y_m,"
           "head_theta_rad,head_z_m,object_present,object_x_m,object_y_m,object_z_m,"
           "object_moving\n";
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
          << t.object_world_m.z() << "," << (f.object_moving ? 1 : 0) << "\n";
    return Status::Ok();
  });
  if (!status.ok()) return status;
  frames.close();
  truth.close();
  if (!frames || !truth) return MakeError(ErrorCode::kInternal, dir + ": cannot write CSV files");
  return Status::Ok();
}

}  // namespace hpose
