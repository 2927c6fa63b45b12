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
  std::string out_dir, pose_name = "standing", offset = "0.035,-0.025";
  TurntableSpec spec;
  double axis_x = spec.axis_ground.x(), axis_y = spec.axis_ground.y();
  double step_deg = 30.0, start_deg = 0.0, yaw_deg = 0.0, error_deg = 0.0;
  double pitch_deg = 0.0, roll_deg = 0.0;
  int seed = 1, width = 640, height = 480;
  bool no_noise = false;
  FlagParser flags(
      "hpose simulate turntable --out DIR [--views N --step-deg D] [--axis-x M --axis-y M] "
      "[--robot-offset X,Y --robot-yaw-deg D] [--table-radius M --table-height M] "
      "[--hand-error-deg D] [--clutter N --seed S --no-noise]",
      "Renders captures of the parametric humanoid standing on a turntable in front of a fixed\n"
      "Kinect v1 (same renderer and noise model as `hpose simulate`): the table turns by\n"
      "--step-deg between views (counter-clockwise seen from above). The robot stands off the\n"
      "axis by --robot-offset (table frame: origin on the axis at the table top, x = the ground\n"
      "x axis in view 0). By default it faces the sensor in view 0 (its x axis points from its\n"
      "origin to the sensor). --hand-error-deg adds a random error of up to +-D to every angle\n"
      "but the first: a robot turned by hand to roughly known headings.\n"
      "Writes DIR/depth_000.png ... (16-bit, mm), DIR/intrinsics.json and DIR/truth.json (axis\n"
      "position in the ground and sensor frames, the robot on the table, every view's true\n"
      "angle and robot pose; metres, radians).");
  flags.AddString("out", &out_dir, "output directory (created if missing)", "DIR");
  flags.AddInt("views", &spec.views, "number of captures", "N");
  flags.AddDouble("step-deg", &step_deg, "table turn between captures, degrees", "D");
  flags.AddDouble("start-deg", &start_deg, "table angle of the first capture, degrees", "D");
  flags.AddDouble("axis-x", &axis_x, "axis position on the floor, ground x (ahead), metres", "M");
  flags.AddDouble("axis-y", &axis_y, "axis position on the floor, ground y (left), metres", "M");
  flags.AddString("robot-offset", &offset, "robot origin on the table, table frame, metres", "X,Y");
  flags.AddDouble("robot-yaw-deg", &yaw_deg,
                  "robot heading in view 0 relative to facing the sensor, degrees", "D");
  flags.AddDouble("table-radius", &spec.table_radius_m, "turntable disc radius, metres", "M");
  flags.AddDouble("table-height", &spec.table_height_m,
                  "turntable top above the floor, metres (0: no disc)", "M");
  flags.AddDouble("hand-error-deg", &error_deg,
                  "random error of every angle but the first, up to +-D degrees", "D");
  flags.AddString("pose", &pose_name, "joint preset: standing or right_arm_raised", "NAME");
  flags.AddDouble("sensor-height", &spec.sensor_height_m, "optical centre above the floor, m", "M");
  flags.AddDouble("pitch-deg", &pitch_deg, "sensor pitch, degrees (+ looks down)", "D");
  flags.AddDouble("roll-deg", &roll_deg, "sensor roll, degrees", "D");
  flags.AddInt("clutter", &spec.clutter, "random still objects on the floor, off the table", "N");
  flags.AddInt("seed", &seed, "seed of the noise, clutter and hand errors", "S");
  flags.AddInt("width", &width, "image width, pixels", "PX");
  flags.AddInt("height", &height, "image height, pixels", "PX");
  flags.AddBool("no-noise", &no_noise, "exact depth: no noise or quantisation");
  flags.SetEpilog(
      "examples:\n"
      "  hpose simulate turntable --out tt --views 12 --step-deg 30 --axis-x 1.3 --axis-y -0.05\n"
      "  hpose simulate turntable --out hand --views 8 --step-deg 45 --table-height 0 "
      "--hand-error-deg 10\n"
      "\nexit status: 0 ok, 1 error writing the files, 2 bad flags or values");
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  if (out_dir.empty()) return UsageError(kTurntableCmd, "--out DIR is required");
  if (!ParsePair(offset, &spec.robot_on_table.x, &spec.robot_on_table.y)) {
    return UsageError(kTurntableCmd,
                      "--robot-offset needs X,Y in metres (e.g. 0.03,-0.02), got '" + offset + "'");
  }
  if (std::abs(axis_x) > 10.0 || std::abs(axis_y) > 10.0) {
    return UsageError(kTurntableCmd, "--axis-x and --axis-y must be within +-10 m");
  }
  if (!(std::abs(step_deg) <= 360.0) || !(std::abs(error_deg) <= 90.0)) {
    return UsageError(kTurntableCmd,
                      "--step-deg must be within +-360 and --hand-error-deg within [0, 90]");
  }
  if (seed < 0) return UsageError(kTurntableCmd, "--seed must be >= 0");
  if (width < 16 || width > 4096 || height < 16 || height > 4096) {
    return UsageError(kTurntableCmd, "--width and --height must be in [16, 4096] pixels");
  }
  spec.preset = pose_name;
  spec.axis_ground = Eigen::Vector2d(axis_x, axis_y);
  spec.step_rad = DegToRad(step_deg);
  spec.start_angle_rad = DegToRad(start_deg);
  spec.sensor_pitch_rad = DegToRad(pitch_deg);
  spec.sensor_roll_rad = DegToRad(roll_deg);
  spec.intrinsics = Intrinsics::KinectV1(width, height);
  spec.noise = !no_noise;
  spec.seed = static_cast<std::uint64_t>(seed);
  // Facing the sensor in view 0: the robot's x axis from its origin towards the sensor.
  spec.robot_on_table.theta = 0.0;
  const Pose2D at_start = TurntableRobotPose(spec, spec.start_angle_rad);
  spec.robot_on_table.theta = NormalizeAngle(std::atan2(-at_start.y, -at_start.x) -
                                             spec.start_angle_rad + DegToRad(yaw_deg));
  if (error_deg > 0.0) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed) + 77);
    std::uniform_real_distribution<double> u(-error_deg, error_deg);
    spec.angle_errors_rad.push_back(0.0);
    for (int i = 1; i < spec.views; ++i) spec.angle_errors_rad.push_back(DegToRad(u(rng)));
  }

  std::cout << "rendering " << spec.views << " captures...\n";
  Result<TurntableCaptures> captures = SimulateTurntableCaptures(spec);
  if (!captures.ok()) {
    if (captures.error().code == ErrorCode::kInvalidArgument) {
      return UsageError(kTurntableCmd, captures.error().message);
    }
    return ReportError(kTurntableCmd, captures.error());
  }
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec || !std::filesystem::is_directory(out_dir)) {
    return ReportError(kTurntableCmd,
                       MakeError(ErrorCode::kInternal,
                                 "cannot create directory " + out_dir + ": " + ec.message()));
  }
  const std::filesystem::path dir(out_dir);
  if (Status s = WriteIntrinsicsJson(spec.intrinsics, (dir / "intrinsics.json").string());
      !s.ok()) {
    return ReportError(kTurntableCmd, s.error());
  }
  const Eigen::Isometry3d sensor_from_ground = captures->sensor_mount.ground_from_sensor.inverse();
  const Eigen::Vector3d axis_point = sensor_from_ground * Eigen::Vector3d(axis_x, axis_y, 0.0);
  const Eigen::Vector3d axis_dir = sensor_from_ground.linear() * Eigen::Vector3d::UnitZ();
  nlohmann::json truth = {
      {"format", "hpose-turntable-truth"},
      {"version", 1},
      {"humanoid_preset", pose_name},
      {"humanoid_height_m", captures->humanoid_height_m},
      {"axis_ground", {{"x", axis_x}, {"y", axis_y}}},
      {"axis_sensor",
       {{"point_on_floor", {axis_point.x(), axis_point.y(), axis_point.z()}},
        {"direction", {axis_dir.x(), axis_dir.y(), axis_dir.z()}}}},
      {"table", {{"radius_m", spec.table_radius_m}, {"height_m", spec.table_height_m}}},
      {"robot_on_table", PoseJson(spec.robot_on_table)},
      {"sensor",
       {{"height_m", spec.sensor_height_m},
        {"pitch_rad", spec.sensor_pitch_rad},
        {"roll_rad", spec.sensor_roll_rad}}},
      {"noise_enabled", spec.noise},
      {"seed", seed},
      {"clutter_count", spec.clutter},
      {"views", nlohmann::json::array()}};
  std::string command;
  for (int i = 0; i < argc; ++i) command += (i ? " " : "") + std::string(argv[i]);
  truth["command"] = command;
  for (int i = 0; i < spec.views; ++i) {
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
  std::cout << "wrote " << spec.views << " captures, intrinsics.json and truth.json to " << out_dir
            << "\n";
  return kExitOk;
}

}  // namespace hpose::tools
