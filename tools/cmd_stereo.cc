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
#include "tools/cmd_stereo_flags.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/fixed_text.h"
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
        std::cout << ApproachText(a.distance_m, a.t_s - f.timestamp_s);
      }
    }
    std::cout << "\n";
  } else if (!f.object_reason.empty()) {
    std::cout << "            ball: " << f.object_reason << "\n";
  }
}

}  // namespace

int RunEstimateStereo(int argc, char** argv) {
  EstimateStereoFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  const std::string cmd = "estimate-stereo";
  const bool single = !f.left.empty() || !f.right.empty();
  if (single == !f.sequence.empty() || (single && (f.left.empty() || f.right.empty()))) {
    std::cerr << "hpose " << cmd
              << ": give either --left and --right, or --sequence (see --help)\n";
    return kExitUsage;
  }
  if (f.calib_unit != "m" && f.calib_unit != "mm") {
    std::cerr << "hpose " << cmd << ": --calib-unit must be m or mm\n";
    return kExitUsage;
  }
  Result<StereoSequence> seq = MakeError(ErrorCode::kNotFound, "");
  if (!single) {
    seq = StereoSequence::Open(f.sequence, f.fps);
    if (!seq.ok()) return ReportError(cmd, seq.error());
    if (f.calibration_paths.empty() && !seq->calibration_path().empty()) {
      f.calibration_paths.push_back(seq->calibration_path());
    }
  }
  if (f.calibration_paths.empty()) {
    std::cerr << "hpose " << cmd << ": --calibration is required\n";
    return kExitUsage;
  }
  StereoCalibrationReadOptions read_options;
  read_options.translation_unit_m = f.calib_unit == "mm" ? 0.001 : 1.0;
  auto calibration = ReadStereoCalibration(f.calibration_paths, read_options);
  if (!calibration.ok()) return ReportError(cmd, calibration.error());
  StereoMarkerOptions options;
  if (!f.options_path.empty()) {
    auto loaded = LoadStereoMarkerOptions(f.options_path);
    if (!loaded.ok()) return ReportError(cmd, loaded.error());
    options = *loaded;
  }
  if (!f.method.empty()) {
    auto parsed = ParseRigidFitMethod(f.method);
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
      auto li = ReadRgbImage(f.left);
      if (!li.ok()) return ReportError(cmd, li.error());
      auto ri = ReadRgbImage(f.right);
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
      e.message = (single ? f.left + ", " + f.right : seq->frame(i).left_path) + ": " + e.message;
      if (e.message.find("calibration") != std::string::npos) {
        e.message += " (" + f.calibration_paths.front() + ")";
      }
      return ReportError(cmd, e);
    }
    const StereoTrackState state = tracker.Update(*result);
    if (result->ok()) ++ok_frames;
    last_status = result->status;
    last_reason = result->reason;
    if (f.json) {
      std::cout << FrameJson(*result, state, i).dump() << "\n";
    } else {
      PrintFrameText(*result, state, i);
    }
  }
  if (!f.json && !single) {
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
  SimulateStereoFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  const std::string cmd = "simulate-stereo";
  if (!f.depth_size.empty() &&
      std::sscanf(f.depth_size.c_str(), "%dx%d", &f.depth.width, &f.depth.height) != 2) {
    std::cerr << "hpose " << cmd << ": --depth-size must be WxH (e.g. 320x240), got '"
              << f.depth_size << "'\n";
    return kExitUsage;
  }
  if (!f.depth_sensor.empty()) {
    double yaw_deg = 0;
    char end = 0;
    if (std::sscanf(f.depth_sensor.c_str(), "%lf,%lf,%lf%c", &f.depth.world_from_ground.x,
                    &f.depth.world_from_ground.y, &yaw_deg, &end) != 3) {
      std::cerr << "hpose " << cmd
                << ": --depth-sensor must be X,Y,YAW_DEG (e.g. -1.1,-2.1,45), got '"
                << f.depth_sensor << "'\n";
      return kExitUsage;
    }
    f.depth.world_from_ground.theta = NormalizeAngle(DegToRad(yaw_deg));
    f.depth.pitch_rad = DegToRad(f.depth_pitch_deg);
  } else if (flags.Seen("depth-mount-height") || flags.Seen("depth-pitch") ||
             flags.Seen("depth-size") || flags.Seen("depth-every")) {
    std::cerr << "hpose " << cmd << ": the --depth-* flags need --depth-sensor\n";
    return kExitUsage;
  }
  if (f.rig != "paper" && f.rig != "vga") {
    std::cerr << "hpose " << cmd << ": --rig must be paper or vga\n";
    return kExitUsage;
  }
  if (f.rig == "vga") {
    // The rig's camera, with any camera flag given explicitly kept.
    const StereoSimCameraOptions given = f.spec.camera;
    f.spec.camera = VgaRigCameraOptions();
    if (flags.Seen("width")) f.spec.camera.width = given.width;
    if (flags.Seen("height")) f.spec.camera.height = given.height;
    if (flags.Seen("hfov")) f.spec.camera.hfov_deg = given.hfov_deg;
    if (flags.Seen("baseline")) f.spec.camera.baseline_m = given.baseline_m;
    if (flags.Seen("head-height")) f.spec.camera.head_height_m = given.head_height_m;
    if (flags.Seen("tilt")) f.spec.camera.head_tilt_deg = given.head_tilt_deg;
  }
  if (f.out.empty()) {
    std::cerr << "hpose " << cmd << ": --out is required\n";
    return kExitUsage;
  }
  auto parsed = ParseStereoSimScenario(f.scenario);
  if (!parsed.ok()) {
    std::cerr << "hpose " << cmd << ": " << parsed.error().message << "\n";
    return kExitUsage;
  }
  f.spec.scenario = *parsed;
  f.spec.distractors = !f.no_distractors;
  f.spec.sway_enabled = !f.no_sway;
  f.spec.noise.pixel_noise_sigma = f.noise;
  if (f.hard) {
    MakeStereoSimHard(&f.spec);
    if (flags.Seen("noise")) f.spec.noise.pixel_noise_sigma = f.noise;
  }
  f.spec.seed = static_cast<std::uint64_t>(f.seed);
  if (f.depth_sensor.empty()) {
    Status s = WriteStereoSimSequence(f.spec, f.out);
    if (!s.ok()) return ReportError(cmd, s.error());
    std::cout << "wrote " << StereoSimFrameCount(f.spec) << " stereo pairs (" << f.spec.camera.width
              << "x" << f.spec.camera.height << ", scenario "
              << StereoSimScenarioName(f.spec.scenario) << ") to " << f.out << "\n";
    return kExitOk;
  }
  Status s = WritePairedSimRecording(f.spec, f.depth, f.out, [](int done, int total) {
    if (done % 10 == 0 || done == total) {
      std::cerr << "\r  rendered " << done << "/" << total << " frames" << std::flush;
    }
  });
  std::cerr << "\n";
  if (!s.ok()) return ReportError(cmd, s.error());
  const int frames = StereoSimFrameCount(f.spec);
  std::cout << "wrote " << frames << " stereo pairs (" << f.spec.camera.width << "x"
            << f.spec.camera.height << ", scenario " << StereoSimScenarioName(f.spec.scenario)
            << ") to " << f.out << "/stereo and " << (frames + f.depth.every - 1) / f.depth.every
            << " depth frames (" << f.depth.width << "x" << f.depth.height << ") to " << f.out
            << "/depth; world_from_ground x " << f.depth.world_from_ground.x << " m, y "
            << f.depth.world_from_ground.y << " m, yaw " << f.depth.world_from_ground.theta
            << " rad\n";
  return kExitOk;
}

}  // namespace hpose::tools
