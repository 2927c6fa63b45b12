// `hpose estimate-stereo` and `hpose simulate-stereo`: the stereo-marker estimator on frame
// pairs, and the simulator that renders such pairs with ground truth.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/common/pose2d.h"
#include "core/stereo/paired_sim_recording.h"
#include "core/stereo/rgb_image_io.h"
#include "core/stereo/stereo_calibration.h"
#include "core/stereo/stereo_estimator.h"
#include "core/stereo/stereo_marker_options.h"
#include "core/stereo/stereo_sequence.h"
#include "core/stereo/stereo_sim_sequence.h"
#include "core/stereo/stereo_tracker.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"

namespace hpose::tools {
namespace {

nlohmann::json Vec(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (int i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

nlohmann::json FrameJson(const StereoFrameResult& f, const StereoTrackState& t, size_t index) {
  nlohmann::json j;
  j["index"] = index;
  j["timestamp_s"] = f.timestamp_s;
  j["estimator"] = "stereo_marker";
  j["frame"] = "world";
  j["status"] = StereoFrameStatusName(f.status);
  if (!f.ok()) j["reason"] = f.reason;
  j["landmark_blobs"] = {f.landmark_blobs_left, f.landmark_blobs_right};
  if (f.ok()) {
    j["robot"] = {{"x_m", f.robot.x}, {"y_m", f.robot.y}, {"theta_rad", f.robot.theta}};
    j["camera_height_m"] = f.camera_height_m;
    j["method"] = RigidFitMethodName(f.method);
    j["svd_rms_residual_m"] = f.svd.rms_residual_m;
    if (f.closed_form_ok) {
      j["closed_form_rms_residual_m"] = f.closed_form.rms_residual_m;
      j["closed_form_orthonormality_error"] = f.closed_form.orthonormality_error;
    }
    j["max_epipolar_error_px"] = f.max_epipolar_error_px;
    j["head"] = {{"x_m", f.head.x}, {"y_m", f.head.y}, {"theta_rad", f.head.theta}};
    j["landmark_visible_fraction"] = f.landmark_visible_fraction;
    if (!f.landmark_notes.empty()) j["landmark_notes"] = f.landmark_notes;
    if (!f.landmark_blobs_excluded.empty()) {
      j["landmark_blobs_excluded"] = f.landmark_blobs_excluded;
    }
  }
  j["landmark_candidates"] = f.landmark_candidates;
  j["landmark_triples"] = f.landmark_triples;
  if (f.landmark_triples > 0) {
    j["landmark_best_rms_m"] = f.landmark_best_rms_m;
    if (std::isfinite(f.landmark_runner_up_rms_m)) {
      j["landmark_runner_up_rms_m"] = f.landmark_runner_up_rms_m;
    }
  }
  if (t.robot_valid) {
    j["robot_mean"] = {{"x_m", t.robot_mean.x},
                       {"y_m", t.robot_mean.y},
                       {"theta_rad", t.robot_mean.theta},
                       {"frames", t.robot_frames}};
  }
  nlohmann::json o;
  o["in_world"] = f.object_in_world;
  if (f.object_in_world) o["position_m"] = Vec(f.object_world_m);
  if (f.object_in_camera) o["camera_position_m"] = Vec(f.object_camera_m);
  if (!f.object_in_world && !f.object_reason.empty()) o["reason"] = f.object_reason;
  o["moving"] = t.object_moving;
  if (t.object_moving) o["motion_start_s"] = t.motion_start_s;
  if (t.path_valid) {
    o["path"] = {{"t0_s", t.path.t0_s},
                 {"origin_m", Vec(t.path.origin_m)},
                 {"velocity_mps", Vec(t.path.velocity_mps)},
                 {"rms_residual_m", t.path.rms_residual_m}};
    if (t.robot_valid) {
      const auto a = t.path.ClosestApproach(Eigen::Vector2d(t.robot_mean.x, t.robot_mean.y));
      o["path"]["closest_approach_to_robot"] = {{"time_s", a.t_s},
                                                {"time_to_reach_s", a.t_s - f.timestamp_s},
                                                {"distance_m", a.distance_m}};
    }
  }
  j["object"] = o;
  return j;
}

void PrintFrameText(const StereoFrameResult& f, const StereoTrackState& t, size_t index) {
  char buf[512];
  std::snprintf(buf, sizeof(buf), "frame %4zu  t=%7.3f s  ", index, f.timestamp_s);
  std::cout << buf;
  if (f.ok()) {
    std::snprintf(buf, sizeof(buf),
                  "robot x=%8.1f mm y=%8.1f mm theta=%7.2f deg (mean of %d: %8.1f %8.1f mm "
                  "%7.2f deg)  fit rms %.1f mm",
                  f.robot.x * 1e3, f.robot.y * 1e3, RadToDeg(f.robot.theta), t.robot_frames,
                  t.robot_mean.x * 1e3, t.robot_mean.y * 1e3, RadToDeg(t.robot_mean.theta),
                  f.fit().rms_residual_m * 1e3);
    std::cout << buf;
  } else {
    std::cout << "rejected (" << StereoFrameStatusName(f.status) << "): " << f.reason;
  }
  std::cout << "\n";
  if (f.object_in_world) {
    std::snprintf(buf, sizeof(buf), "            ball x=%8.1f mm y=%8.1f mm z=%6.1f mm  %s",
                  f.object_world_m.x() * 1e3, f.object_world_m.y() * 1e3,
                  f.object_world_m.z() * 1e3, t.object_moving ? "MOVING" : "at rest");
    std::cout << buf;
    if (t.path_valid) {
      std::snprintf(buf, sizeof(buf), "  path v=(%.0f, %.0f) mm/s", t.path.velocity_mps.x() * 1e3,
                    t.path.velocity_mps.y() * 1e3);
      std::cout << buf;
      if (t.robot_valid) {
        const auto a = t.path.ClosestApproach(Eigen::Vector2d(t.robot_mean.x, t.robot_mean.y));
        std::snprintf(buf, sizeof(buf), ", passes %.0f mm from the robot in %.2f s",
                      a.distance_m * 1e3, a.t_s - f.timestamp_s);
        std::cout << buf;
      }
    }
    std::cout << "\n";
  } else if (!f.object_reason.empty()) {
    std::cout << "            ball: " << f.object_reason << "\n";
  }
}

}  // namespace

int RunEstimateStereo(int argc, char** argv) {
  std::vector<std::string> calibration_paths;
  std::string left, right, sequence, options_path, method, calib_unit = "m";
  double fps = 15.0;
  bool json = false;
  FlagParser flags(
      "hpose estimate-stereo --calibration CAL.yaml (--left L.png --right R.png | --sequence DIR)",
      "Locates the robot (its stereo head projected on the floor, or the point set by the "
      "options' head_to_reference_m) and the ball in the field frame of three same-coloured "
      "landmarks, from one stereo pair or a sequence directory "
      "(layout: DIR/frames.csv or DIR/left/*.png + DIR/right/*.png, optional "
      "DIR/calibration.yaml). Over a sequence it also averages the robot pose over 8 frames, "
      "detects when the ball starts moving and predicts its straight path. The landmarks are "
      "chosen among all blobs of their colour by geometry (epipolar match, size for the "
      "distance, spacing of the known layout), the ball as the most ball-like blob pair; a "
      "partly hidden landmark is down-weighted, and every rejected frame names its reason.");
  flags.AddStrings("calibration", &calibration_paths,
                   "OpenCV stereo calibration (YAML/XML: M1 D1 M2 D2 R T); give two files for "
                   "separate intrinsics and extrinsics",
                   "FILE");
  flags.AddString("calib-unit", &calib_unit, "unit of T in the calibration: m or mm", "UNIT");
  flags.AddString("left", &left, "left image of a single pair", "IMAGE");
  flags.AddString("right", &right, "right image of a single pair", "IMAGE");
  flags.AddString("sequence", &sequence, "directory of frame pairs", "DIR");
  flags.AddDouble("fps", &fps, "frame rate when the sequence has no frames.csv", "HZ");
  flags.AddString("options", &options_path,
                  "estimator options (YAML: colours, landmark positions, thresholds)", "FILE");
  flags.AddString("method", &method,
                  "camera->world fit: svd, closed_form or covariance (default: the options file's)",
                  "NAME");
  flags.AddBool("json", &json, "print one JSON object per frame (SI units) instead of text");
  flags.SetEpilog(
      "exit status: 0 ok; 1 bad input; 2 usage; 3 a single pair gave no robot pose.\n"
      "example:\n  hpose simulate stereo --out /tmp/seq && hpose estimate-stereo --sequence "
      "/tmp/seq --json\n");
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  const std::string cmd = "estimate-stereo";
  const bool single = !left.empty() || !right.empty();
  if (single == !sequence.empty() || (single && (left.empty() || right.empty()))) {
    std::cerr << "hpose " << cmd
              << ": give either --left and --right, or --sequence (see --help)\n";
    return kExitUsage;
  }
  if (calib_unit != "m" && calib_unit != "mm") {
    std::cerr << "hpose " << cmd << ": --calib-unit must be m or mm\n";
    return kExitUsage;
  }
  Result<StereoSequence> seq = MakeError(ErrorCode::kNotFound, "");
  if (!single) {
    seq = StereoSequence::Open(sequence, fps);
    if (!seq.ok()) return ReportError(cmd, seq.error());
    if (calibration_paths.empty() && !seq->calibration_path().empty()) {
      calibration_paths.push_back(seq->calibration_path());
    }
  }
  if (calibration_paths.empty()) {
    std::cerr << "hpose " << cmd << ": --calibration is required\n";
    return kExitUsage;
  }
  StereoCalibrationReadOptions read_options;
  read_options.translation_unit_m = calib_unit == "mm" ? 0.001 : 1.0;
  auto calibration = ReadStereoCalibration(calibration_paths, read_options);
  if (!calibration.ok()) return ReportError(cmd, calibration.error());
  StereoMarkerOptions options;
  if (!options_path.empty()) {
    auto loaded = LoadStereoMarkerOptions(options_path);
    if (!loaded.ok()) return ReportError(cmd, loaded.error());
    options = *loaded;
  }
  if (!method.empty()) {
    auto parsed = ParseRigidFitMethod(method);
    if (!parsed.ok()) {
      std::cerr << "hpose " << cmd << ": --method: " << parsed.error().message << "\n";
      return kExitUsage;
    }
    options.method = *parsed;
  }
  auto estimator = StereoEstimator::Create(*calibration, options);
  if (!estimator.ok()) return ReportError(cmd, estimator.error());
  StereoTracker tracker;

  const size_t n = single ? 1 : seq->size();
  size_t ok_frames = 0;
  StereoFrameStatus last_status = StereoFrameStatus::kOk;
  std::string last_reason;
  for (size_t i = 0; i < n; ++i) {
    RgbImage l, r;
    double t = 0.0;
    if (single) {
      auto li = ReadRgbImage(left);
      if (!li.ok()) return ReportError(cmd, li.error());
      auto ri = ReadRgbImage(right);
      if (!ri.ok()) return ReportError(cmd, ri.error());
      l = std::move(li).value();
      r = std::move(ri).value();
    } else {
      auto pair = seq->Load(i);
      if (!pair.ok()) return ReportError(cmd, pair.error());
      l = std::move(pair->first);
      r = std::move(pair->second);
      t = seq->frame(i).timestamp_s;
    }
    StereoObjectPrior prior;
    auto result = (*estimator)->Process(l, r, t, tracker.ObjectPrior(&prior) ? &prior : nullptr);
    if (!result.ok()) {
      Error e = result.error();
      e.message = (single ? left + ", " + right : seq->frame(i).left_path) + ": " + e.message;
      if (e.message.find("calibration") != std::string::npos) {
        e.message += " (" + calibration_paths.front() + ")";
      }
      return ReportError(cmd, e);
    }
    const StereoTrackState state = tracker.Update(*result);
    if (result->ok()) ++ok_frames;
    last_status = result->status;
    last_reason = result->reason;
    if (json) {
      std::cout << FrameJson(*result, state, i).dump() << "\n";
    } else {
      PrintFrameText(*result, state, i);
    }
  }
  if (!json && !single) {
    std::cout << ok_frames << " of " << n << " frame pairs gave a robot pose\n";
  }
  if (ok_frames == 0) {
    std::cerr << "hpose " << cmd << ": no robot pose in " << (single ? "the pair" : "any pair");
    if (single) std::cerr << " (" << StereoFrameStatusName(last_status) << "): " << last_reason;
    std::cerr << "\n";
  }
  return ok_frames == 0 && single ? kExitNoHumanoid : kExitOk;
}

int RunSimulateStereo(int argc, char** argv) {
  StereoSimSequenceSpec spec;
  std::string out, scenario = "rolling", rig = "paper";
  bool no_distractors = false, no_sway = false, hard = false;
  int seed = 1;
  PairedDepthSensorSpec depth;
  std::string depth_sensor, depth_size;
  double depth_pitch_deg = 0.0;
  double noise = spec.noise.pixel_noise_sigma;
  FlagParser flags(
      "hpose simulate-stereo --out DIR [--scenario rolling|walking|grid]",
      "Renders stereo pairs (PNG) of the field seen from the robot's head: floor with a grid "
      "sheet, three blue landmark discs at the paper's positions, an orange ball, optional "
      "distractor colours, with lens distortion, image noise, lighting variation and head sway "
      "while walking. Writes DIR/calibration.yaml (OpenCV), DIR/left/, DIR/right/, "
      "DIR/frames.csv and DIR/ground_truth.csv (SI units). --hard adds what real rigs see: "
      "carpet texture, vignetting, Bayer sensor noise with demosaicing, JPEG, speckles, "
      "distractors of the landmark and ball colours (40 % of placements) and occluders over "
      "part of a landmark (15 %); ground_truth.csv then records the occluded fraction of each "
      "landmark and the number of same-coloured distractors.");
  flags.AddString("out", &out, "output directory (created)", "DIR");
  flags.AddString("rig", &rig,
                  "stereo head: paper (512x240, 70 mm baseline) or vga (640x480, strong "
                  "k1 k2 p1 p2 k3 distortion, 76 mm baseline); camera flags override it",
                  "NAME");
  flags.AddBool("hard", &hard, "realistic sensor and cluttered scenes (see above)");
  flags.AddString("scenario", &scenario,
                  "rolling: ball kicked towards a standing robot; walking: robot walks, ball at "
                  "rest; grid: the paper's grid of robot positions",
                  "NAME");
  flags.AddInt("frames", &spec.frames, "frames (rolling, walking)");
  flags.AddDouble("fps", &spec.fps, "frame rate", "HZ");
  flags.AddInt("width", &spec.camera.width, "image width", "PX");
  flags.AddInt("height", &spec.camera.height, "image height", "PX");
  flags.AddDouble("hfov", &spec.camera.hfov_deg, "horizontal field of view", "DEG");
  flags.AddDouble("baseline", &spec.camera.baseline_m, "stereo baseline", "M");
  flags.AddDouble("head-height", &spec.camera.head_height_m, "head height above the floor", "M");
  flags.AddDouble("tilt", &spec.camera.head_tilt_deg, "head tilt below horizontal", "DEG");
  flags.AddDouble("noise", &noise, "image noise sigma, grey levels", "LEVELS");
  flags.AddDouble("robot-x", &spec.robot_start.x, "robot start x (world)", "M");
  flags.AddDouble("robot-y", &spec.robot_start.y, "robot start y (world)", "M");
  flags.AddDouble("robot-theta", &spec.robot_start.theta, "robot start heading (world)", "RAD");
  flags.AddDouble("kick-time", &spec.kick_time_s, "when the ball is kicked (rolling)", "S");
  flags.AddDouble("ball-vx", &spec.ball_velocity_mps.x(), "ball velocity after the kick, x", "M/S");
  flags.AddDouble("ball-vy", &spec.ball_velocity_mps.y(), "ball velocity after the kick, y", "M/S");
  flags.AddInt("frames-per-position", &spec.frames_per_position, "frames per grid position");
  flags.AddBool("no-distractors", &no_distractors, "no distractor colours on the floor");
  flags.AddBool("no-sway", &no_sway, "no head sway");
  flags.AddInt("seed", &seed, "random seed");
  flags.AddDouble("speed", &spec.robot_speed_mps, "robot walking speed (walking)", "M/S");
  flags.AddString("depth-sensor", &depth_sensor,
                  "also render a depth sensor (Kinect v1 model) watching the robot, its ground "
                  "frame at X,Y (world, metres) facing YAW degrees from world +x: writes "
                  "DIR/stereo/ and DIR/depth/ (see below)",
                  "X,Y,YAW");
  flags.AddDouble("depth-mount-height", &depth.height_m,
                  "depth sensor's optical centre above the floor", "M");
  flags.AddDouble("depth-pitch", &depth_pitch_deg, "depth sensor pitch (+ looks down)", "DEG");
  flags.AddString("depth-size", &depth_size, "depth image size", "WxH");
  flags.AddInt("depth-every", &depth.every, "one depth frame per N stereo frames", "N");
  flags.SetEpilog(
      "With --depth-sensor the output is a recording both estimators see: DIR/stereo/ (the "
      "layout above) and DIR/depth/ (16-bit depth PNGs named by their time in seconds on the "
      "stereo clock, intrinsics.json, truth.csv with the humanoid's ground and world poses). "
      "The humanoid stands where the robot's stereo head is (head_to_reference_m = 0). Use it "
      "with `hpose calibrate world-from-ground --recording DIR`, and as hposed's source.path "
      "(DIR/depth) and stereo.source (DIR/stereo).\n"
      "example:\n  hpose simulate stereo --out rec --scenario walking --frames 90 --fps 10 "
      "--speed 0.08 --robot-y -1.35 --depth-sensor -1.1,-2.1,45\n");
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  const std::string cmd = "simulate-stereo";
  if (!depth_size.empty() &&
      std::sscanf(depth_size.c_str(), "%dx%d", &depth.width, &depth.height) != 2) {
    std::cerr << "hpose " << cmd << ": --depth-size must be WxH (e.g. 320x240), got '" << depth_size
              << "'\n";
    return kExitUsage;
  }
  if (!depth_sensor.empty()) {
    double yaw_deg = 0;
    char end = 0;
    if (std::sscanf(depth_sensor.c_str(), "%lf,%lf,%lf%c", &depth.world_from_ground.x,
                    &depth.world_from_ground.y, &yaw_deg, &end) != 3) {
      std::cerr << "hpose " << cmd
                << ": --depth-sensor must be X,Y,YAW_DEG (e.g. -1.1,-2.1,45), got '" << depth_sensor
                << "'\n";
      return kExitUsage;
    }
    depth.world_from_ground.theta = NormalizeAngle(DegToRad(yaw_deg));
    depth.pitch_rad = DegToRad(depth_pitch_deg);
  } else if (flags.Seen("depth-mount-height") || flags.Seen("depth-pitch") ||
             flags.Seen("depth-size") || flags.Seen("depth-every")) {
    std::cerr << "hpose " << cmd << ": the --depth-* flags need --depth-sensor\n";
    return kExitUsage;
  }
  if (rig != "paper" && rig != "vga") {
    std::cerr << "hpose " << cmd << ": --rig must be paper or vga\n";
    return kExitUsage;
  }
  if (rig == "vga") {
    // The rig's camera, with any camera flag given explicitly kept.
    const StereoSimCameraOptions given = spec.camera;
    spec.camera = VgaRigCameraOptions();
    if (flags.Seen("width")) spec.camera.width = given.width;
    if (flags.Seen("height")) spec.camera.height = given.height;
    if (flags.Seen("hfov")) spec.camera.hfov_deg = given.hfov_deg;
    if (flags.Seen("baseline")) spec.camera.baseline_m = given.baseline_m;
    if (flags.Seen("head-height")) spec.camera.head_height_m = given.head_height_m;
    if (flags.Seen("tilt")) spec.camera.head_tilt_deg = given.head_tilt_deg;
  }
  if (out.empty()) {
    std::cerr << "hpose " << cmd << ": --out is required\n";
    return kExitUsage;
  }
  auto parsed = ParseStereoSimScenario(scenario);
  if (!parsed.ok()) {
    std::cerr << "hpose " << cmd << ": " << parsed.error().message << "\n";
    return kExitUsage;
  }
  spec.scenario = *parsed;
  spec.distractors = !no_distractors;
  spec.sway_enabled = !no_sway;
  spec.noise.pixel_noise_sigma = noise;
  if (hard) {
    MakeStereoSimHard(&spec);
    if (flags.Seen("noise")) spec.noise.pixel_noise_sigma = noise;
  }
  spec.seed = static_cast<std::uint64_t>(seed);
  if (depth_sensor.empty()) {
    Status s = WriteStereoSimSequence(spec, out);
    if (!s.ok()) return ReportError(cmd, s.error());
    std::cout << "wrote " << StereoSimFrameCount(spec) << " stereo pairs (" << spec.camera.width
              << "x" << spec.camera.height << ", scenario " << StereoSimScenarioName(spec.scenario)
              << ") to " << out << "\n";
    return kExitOk;
  }
  Status s = WritePairedSimRecording(spec, depth, out, [](int done, int total) {
    if (done % 10 == 0 || done == total) {
      std::cerr << "\r  rendered " << done << "/" << total << " frames" << std::flush;
    }
  });
  std::cerr << "\n";
  if (!s.ok()) return ReportError(cmd, s.error());
  const int frames = StereoSimFrameCount(spec);
  std::cout << "wrote " << frames << " stereo pairs (" << spec.camera.width << "x"
            << spec.camera.height << ", scenario " << StereoSimScenarioName(spec.scenario)
            << ") to " << out << "/stereo and " << (frames + depth.every - 1) / depth.every
            << " depth frames (" << depth.width << "x" << depth.height << ") to " << out
            << "/depth; world_from_ground x " << depth.world_from_ground.x << " m, y "
            << depth.world_from_ground.y << " m, yaw " << depth.world_from_ground.theta << " rad\n";
  return kExitOk;
}

}  // namespace hpose::tools
