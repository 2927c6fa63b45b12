#include "core/stereo/paired_sim_recording.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <Eigen/Geometry>

#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "core/sim/frame_simulator.h"

namespace hpose {
namespace {

// The robot's world pose in the depth sensor's ground frame.
Pose2D WorldToGround(const Pose2D& world_from_ground, const Pose2D& world) {
  const Eigen::Rotation2Dd ground_r_world(-world_from_ground.theta);
  const Eigen::Vector2d p = ground_r_world * Eigen::Vector2d(world.x - world_from_ground.x,
                                                             world.y - world_from_ground.y);
  return Pose2D{p.x(), p.y(), NormalizeAngle(world.theta - world_from_ground.theta)};
}

}  // namespace

Status ValidatePairedDepthSensorSpec(const PairedDepthSensorSpec& s) {
  auto bad = [](const std::string& what) {
    return Status(MakeError(ErrorCode::kInvalidArgument, "depth sensor: " + what));
  };
  if (!std::isfinite(s.world_from_ground.x + s.world_from_ground.y + s.world_from_ground.theta)) {
    return bad("world_from_ground must be finite");
  }
  if (!(s.height_m > 0.05 && s.height_m <= 3.0)) return bad("height must be in (0.05, 3] m");
  if (!(std::abs(s.pitch_rad) <= DegToRad(60.0))) return bad("pitch must be within +-60 deg");
  if (s.width < 16 || s.height < 16 || s.width > 4096 || s.height > 4096) {
    return bad("image size must be within 16..4096 pixels");
  }
  if (s.every < 1) return bad("every must be >= 1 (a depth frame per N stereo frames)");
  return Status::Ok();
}

Status WritePairedSimRecording(const StereoSimSequenceSpec& stereo,
                               const PairedDepthSensorSpec& depth, const std::string& dir,
                               const std::function<void(int, int)>& progress) {
  if (Status s = ValidatePairedDepthSensorSpec(depth); !s.ok()) return s;
  if (Status s = ValidateStereoSimSequenceSpec(stereo); !s.ok()) return s;
  const std::string depth_dir = dir + "/depth";
  std::error_code ec;
  std::filesystem::create_directories(depth_dir, ec);
  if (ec) return MakeError(ErrorCode::kInternal, depth_dir + ": cannot create directory");
  FrameSpec frame;
  frame.preset = depth.preset;
  frame.body = depth.body;
  frame.sensor_height_m = depth.height_m;
  frame.sensor_pitch_rad = depth.pitch_rad;
  frame.intrinsics = Intrinsics::KinectV1(depth.width, depth.height);
  frame.noise = depth.noise;
  if (Status s = WriteIntrinsicsJson(frame.intrinsics, depth_dir + "/intrinsics.json"); !s.ok()) {
    return s;
  }
  std::ofstream truth(depth_dir + "/truth.csv");
  if (!truth) return MakeError(ErrorCode::kInternal, depth_dir + "/truth.csv: cannot write");
  truth << "timestamp_s,file,ground_x_m,ground_y_m,ground_theta_rad,world_x_m,world_y_m,"
           "world_theta_rad\n";
  truth.precision(9);
  const int total = StereoSimFrameCount(stereo);
  Status status =
      WriteStereoSimSequence(stereo, dir + "/stereo", [&](const StereoSimFrame& f) -> Status {
        if (f.index % depth.every == 0) {
          const Pose2D world = f.truth.robot_nominal;
          frame.humanoid_pose = WorldToGround(depth.world_from_ground, world);
          frame.seed = stereo.seed * 7777 + static_cast<std::uint64_t>(f.index);
          Result<SimulatedFrame> rendered = SimulateFrame(frame);
          if (!rendered.ok()) return rendered.error();
          char name[64];
          std::snprintf(name, sizeof(name), "%011.6f.png", f.timestamp_s);
          if (Status s = WriteDepthPng(rendered->depth, depth_dir + "/" + name); !s.ok()) return s;
          truth << f.timestamp_s << "," << name << "," << frame.humanoid_pose.x << ","
                << frame.humanoid_pose.y << "," << frame.humanoid_pose.theta << "," << world.x
                << "," << world.y << "," << world.theta << "\n";
        }
        if (progress) progress(f.index + 1, total);
        return Status::Ok();
      });
  if (!status.ok()) return status;
  truth.close();
  if (!truth) return MakeError(ErrorCode::kInternal, depth_dir + "/truth.csv: cannot write");
  return Status::Ok();
}

}  // namespace hpose
