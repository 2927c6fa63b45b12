// `hpose simulate turntable`: renders the captures of a humanoid on a turntable (or turned by
// hand) that `hpose template from-captures` makes a 360 degree template from, with their truth.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/common/pose2d.h"
#include "core/io/atomic_file.h"
#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "core/sim/turntable_captures.h"
#include "tools/cmd_simulate_turntable_flags.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"

namespace hpose::tools {
namespace {

const char kTurntableCmd[] = "simulate turntable";

// "X,Y" -> two finite numbers.
bool ParsePair(const std::string& text, double* a, double* b) {
  char comma = 0, extra = 0;
  std::istringstream in(text);
  if (!(in >> *a >> comma >> *b) || comma != ',' || (in >> extra)) return false;
  return std::isfinite(*a) && std::isfinite(*b);
}

nlohmann::json PoseJson(const Pose2D& p) { return {{"x", p.x}, {"y", p.y}, {"theta", p.theta}}; }

}  // namespace

int RunSimulateTurntable(int argc, char** argv) {
  TurntableFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  if (f.out_dir.empty()) return UsageError(kTurntableCmd, "--out DIR is required");
  if (!ParsePair(f.offset, &f.spec.robot_on_table.x, &f.spec.robot_on_table.y)) {
    return UsageError(kTurntableCmd, "--robot-offset needs X,Y in metres (e.g. 0.03,-0.02), got '" +
                                         f.offset + "'");
  }
  if (std::abs(f.axis_x) > 10.0 || std::abs(f.axis_y) > 10.0) {
    return UsageError(kTurntableCmd, "--axis-x and --axis-y must be within +-10 m");
  }
  if (!(std::abs(f.step_deg) <= 360.0) || !(std::abs(f.error_deg) <= 90.0)) {
    return UsageError(kTurntableCmd,
                      "--step-deg must be within +-360 and --hand-error-deg within [0, 90]");
  }
  if (f.seed < 0) return UsageError(kTurntableCmd, "--seed must be >= 0");
  if (f.width < 16 || f.width > 4096 || f.height < 16 || f.height > 4096) {
    return UsageError(kTurntableCmd, "--width and --height must be in [16, 4096] pixels");
  }
  f.spec.preset = f.pose_name;
  f.spec.axis_ground = Eigen::Vector2d(f.axis_x, f.axis_y);
  f.spec.step_rad = DegToRad(f.step_deg);
  f.spec.start_angle_rad = DegToRad(f.start_deg);
  f.spec.sensor_pitch_rad = DegToRad(f.pitch_deg);
  f.spec.sensor_roll_rad = DegToRad(f.roll_deg);
  f.spec.intrinsics = Intrinsics::KinectV1(f.width, f.height);
  f.spec.noise = !f.no_noise;
  f.spec.seed = static_cast<std::uint64_t>(f.seed);
  // Facing the sensor in view 0: the robot's x axis from its origin towards the sensor.
  f.spec.robot_on_table.theta = 0.0;
  const Pose2D at_start = TurntableRobotPose(f.spec, f.spec.start_angle_rad);
  f.spec.robot_on_table.theta = NormalizeAngle(std::atan2(-at_start.y, -at_start.x) -
                                               f.spec.start_angle_rad + DegToRad(f.yaw_deg));
  if (f.error_deg > 0.0) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(f.seed) + 77);
    std::uniform_real_distribution<double> u(-f.error_deg, f.error_deg);
    f.spec.angle_errors_rad.push_back(0.0);
    for (int i = 1; i < f.spec.views; ++i) f.spec.angle_errors_rad.push_back(DegToRad(u(rng)));
  }

  std::cout << "rendering " << f.spec.views << " captures...\n";
  Result<TurntableCaptures> captures = SimulateTurntableCaptures(f.spec);
  if (!captures.ok()) {
    if (captures.error().code == ErrorCode::kInvalidArgument) {
      return UsageError(kTurntableCmd, captures.error().message);
    }
    return ReportError(kTurntableCmd, captures.error());
  }
  std::error_code ec;
  std::filesystem::create_directories(f.out_dir, ec);
  if (ec || !std::filesystem::is_directory(f.out_dir)) {
    return ReportError(kTurntableCmd,
                       MakeError(ErrorCode::kInternal,
                                 "cannot create directory " + f.out_dir + ": " + ec.message()));
  }
  const std::filesystem::path dir(f.out_dir);
  if (Status s = WriteIntrinsicsJson(f.spec.intrinsics, (dir / "intrinsics.json").string());
      !s.ok()) {
    return ReportError(kTurntableCmd, s.error());
  }
  const Eigen::Isometry3d sensor_from_ground = captures->sensor_mount.ground_from_sensor.inverse();
  const Eigen::Vector3d axis_point = sensor_from_ground * Eigen::Vector3d(f.axis_x, f.axis_y, 0.0);
  const Eigen::Vector3d axis_dir = sensor_from_ground.linear() * Eigen::Vector3d::UnitZ();
  nlohmann::json truth = {
      {"format", "hpose-turntable-truth"},
      {"version", 1},
      {"humanoid_preset", f.pose_name},
      {"humanoid_height_m", captures->humanoid_height_m},
      {"axis_ground", {{"x", f.axis_x}, {"y", f.axis_y}}},
      {"axis_sensor",
       {{"point_on_floor", {axis_point.x(), axis_point.y(), axis_point.z()}},
        {"direction", {axis_dir.x(), axis_dir.y(), axis_dir.z()}}}},
      {"table", {{"radius_m", f.spec.table_radius_m}, {"height_m", f.spec.table_height_m}}},
      {"robot_on_table", PoseJson(f.spec.robot_on_table)},
      {"sensor",
       {{"height_m", f.spec.sensor_height_m},
        {"pitch_rad", f.spec.sensor_pitch_rad},
        {"roll_rad", f.spec.sensor_roll_rad}}},
      {"noise_enabled", f.spec.noise},
      {"seed", f.seed},
      {"clutter_count", f.spec.clutter},
      {"views", nlohmann::json::array()}};
  std::string command;
  for (int i = 0; i < argc; ++i) command += (i ? " " : "") + std::string(argv[i]);
  truth["command"] = command;
  for (int i = 0; i < f.spec.views; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "depth_%03d.png", i);
    if (Status s = WriteDepthPng(captures->depth[i], (dir / name).string()); !s.ok()) {
      return ReportError(kTurntableCmd, s.error());
    }
    truth["views"].push_back({{"depth_file", name},
                              {"table_angle_rad", captures->table_angles_rad[i]},
                              {"robot_pose", PoseJson(captures->robot_poses[i])},
                              {"noise_seed", captures->noise_seeds[i]}});
    char line[160];
    std::snprintf(line, sizeof(line), "%s: table %.1f deg, robot at x %.0f y %.0f mm, %.1f deg\n",
                  name, RadToDeg(captures->table_angles_rad[i]),
                  captures->robot_poses[i].x * 1000.0, captures->robot_poses[i].y * 1000.0,
                  RadToDeg(captures->robot_poses[i].theta));
    std::cout << line;
  }
  if (Status s = WriteFileAtomically((dir / "truth.json").string(), truth.dump(2) + "\n");
      !s.ok()) {
    return ReportError(kTurntableCmd, s.error());
  }
  std::cout << "wrote " << f.spec.views << " captures, intrinsics.json and truth.json to "
            << f.out_dir << "\n";
  return kExitOk;
}

}  // namespace hpose::tools
