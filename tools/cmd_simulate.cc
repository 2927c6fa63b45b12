// `hpose simulate`: renders simulated Kinect v1 depth frames of a humanoid on a floor among
// clutter, with the ground truth needed to score an estimator on them.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/common/pose2d.h"
#include "core/depth/depth_to_cloud.h"
#include "core/depth/floor_estimate.h"
#include "core/depth/intrinsics.h"
#include "core/io/atomic_file.h"
#include "core/io/cloud_io.h"
#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "core/sim/depth_renderer.h"
#include "core/sim/humanoid_model.h"
#include "core/sim/kinect_noise_model.h"
#include "core/sim/scene.h"
#include "core/sim/sim_truth.h"
#include "tools/cmd_simulate_flags.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/fixed_text.h"
#include "tools/flag_parser.h"
#include "tools/robot_flags.h"

namespace hpose::tools {
namespace {

const char kSimulateCmd[] = "simulate";

std::string FrameName(const std::string& stem, const std::string& ext, int index, int frames) {
  if (frames == 1) return stem + ext;
  char buf[32];
  std::snprintf(buf, sizeof(buf), "_%03d", index);
  return stem + buf + ext;
}

double FootprintRadius(const Eigen::AlignedBox3d& b) {
  return std::max(b.min().head<2>().norm(), b.max().head<2>().norm());
}

// The main robot of the simulation: the parametric humanoid, or a mesh robot from a URDF.
struct MainRobot {
  std::optional<HumanoidModel> model;
  std::shared_ptr<const MeshBvh> mesh;
  std::string label;  // preset, or ROBOT/JOINT_SET.

  const Eigen::AlignedBox3d& Bounds() const { return mesh ? mesh->bounds() : model->bounds(); }
  Status AddTo(Scene* scene, const Pose2D& pose) const {
    return mesh ? scene->AddMeshRobot(mesh, pose, label) : scene->AddHumanoid(*model, pose, label);
  }
};

int RunSimulateScene(int argc, char** argv) {
  SimulateFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;

  // Values.
  if (f.out_dir.empty()) return UsageError(kSimulateCmd, "--out DIR is required");
  if (!(std::abs(f.x) <= 20.0 && std::abs(f.y) <= 20.0)) {
    return UsageError(kSimulateCmd, "--x and --y must be within +-20 m");
  }
  if (!(std::abs(f.theta_deg) <= 3600.0)) {
    return UsageError(kSimulateCmd, "--theta-deg must be within +-3600 degrees");
  }
  if (!(f.sensor_height > 0.05 && f.sensor_height <= 3.0)) {
    return UsageError(kSimulateCmd,
                      "--sensor-height must be in (0.05, 3] m, got " + Fixed(f.sensor_height, 3));
  }
  if (std::abs(f.pitch_deg) > 85.0)
    return UsageError(kSimulateCmd, "--pitch-deg must be within +-85 degrees");
  if (std::abs(f.roll_deg) > 45.0)
    return UsageError(kSimulateCmd, "--roll-deg must be within +-45 degrees");
  if (f.clutter < 0 || f.clutter > 50)
    return UsageError(kSimulateCmd, "--clutter must be in [0, 50]");
  if (f.seed < 0) return UsageError(kSimulateCmd, "--seed must be >= 0");
  if (f.width < 16 || f.width > 4096 || f.height < 16 || f.height > 4096) {
    return UsageError(kSimulateCmd, "--width and --height must be in [16, 4096] pixels");
  }
  if (f.frames < 1 || f.frames > 1000)
    return UsageError(kSimulateCmd, "--frames must be in [1, 1000]");
  if (!(f.noise_correlation >= 0.0 && f.noise_correlation <= 1.0)) {
    return UsageError(kSimulateCmd, "--noise-correlation must be in [0, 1], got " +
                                        Fixed(f.noise_correlation, 3));
  }
  if (f.noise_correlation_px < 1 || f.noise_correlation_px > 64) {
    return UsageError(kSimulateCmd, "--noise-correlation-px must be in [1, 64]");
  }
  if (std::abs(f.turn_deg) > 180.0)
    return UsageError(kSimulateCmd, "--turn-deg must be within +-180 degrees");
  if (std::abs(f.step_m) > 1.0) return UsageError(kSimulateCmd, "--step-m must be within +-1 m");
  if (flags.Seen("robot") && f.robot_urdf.empty()) {
    return UsageError(kSimulateCmd, "--robot needs a URDF file, got an empty path");
  }
  MainRobot robot;
  if (!f.robot_urdf.empty()) {
    if (flags.Seen("pose") || flags.Seen("body")) {
      return UsageError(kSimulateCmd,
                        "--pose and --body describe the parametric humanoid: not with --robot");
    }
    Result<std::shared_ptr<const MeshBvh>> mesh =
        LoadPosedRobotMesh(f.robot_flags, f.robot_urdf, kSimulateCmd, &robot.label);
    if (!mesh.ok()) return ReportError(kSimulateCmd, mesh.error());
    robot.mesh = *mesh;
  } else {
    Result<HumanoidDimensions> dimensions = HumanoidDimensions::Variant(f.body);
    if (!dimensions.ok()) return UsageError(kSimulateCmd, "--body: " + dimensions.error().message);
    Result<HumanoidModel> model = HumanoidModel::FromPreset(f.pose_name, *dimensions);
    if (!model.ok()) return UsageError(kSimulateCmd, "--pose: " + model.error().message);
    robot.model = *model;
    robot.label = f.body == "nao" ? f.pose_name : f.pose_name + "/" + f.body;
  }
  std::vector<PlacedHumanoid> others;
  if (!f.second_at.empty() || flags.Seen("second-pose")) {
    Pose2D p;
    if (!ParsePoseTriple(f.second_at, &p)) {
      return UsageError(kSimulateCmd, "--second-at needs X,Y,THETA_DEG (e.g. 2,0.5,90), got '" +
                                          f.second_at + "'");
    }
    if (!(std::abs(p.x) <= 20.0 && std::abs(p.y) <= 20.0)) {
      return UsageError(kSimulateCmd, "--second-at: X and Y must be within +-20 m, as --x and --y");
    }
    Result<HumanoidModel> m = HumanoidModel::FromPreset(f.second_pose);
    if (!m.ok()) return UsageError(kSimulateCmd, "--second-pose: " + m.error().message);
    others.push_back({*m, p, f.second_pose});
  }

  // Where the main humanoid stands in every frame.
  std::vector<Pose2D> poses;
  Pose2D pose{f.x, f.y, NormalizeAngle(DegToRad(f.theta_deg))};
  for (int i = 0; i < f.frames; ++i) {
    poses.push_back(pose);
    pose.x += f.step_m * std::cos(pose.theta);
    pose.y += f.step_m * std::sin(pose.theta);
    pose.theta = NormalizeAngle(pose.theta + DegToRad(f.turn_deg));
  }
  for (const PlacedHumanoid& o : others) {
    for (const Pose2D& p : poses) {
      const double gap = std::hypot(o.pose.x - p.x, o.pose.y - p.y);
      if (gap < FootprintRadius(o.model.bounds()) + FootprintRadius(robot.Bounds())) {
        return UsageError(kSimulateCmd, "--second-at: the second humanoid would overlap the first");
      }
    }
  }

  // The clutter keeps clear of the humanoid in every frame: lay it out around all its poses.
  std::vector<Primitive> clutter_objects;
  if (f.clutter > 0) {
    Scene layout;
    for (const Pose2D& p : poses) robot.AddTo(&layout, p);
    for (const PlacedHumanoid& o : others) layout.AddHumanoid(o.model, o.pose);
    const Status s = layout.AddRandomClutter(f.clutter, static_cast<std::uint64_t>(f.seed));
    if (!s.ok()) return UsageError(kSimulateCmd, "--clutter: " + s.error().message);
    clutter_objects = layout.clutter();
  }

  const FloorEstimate mount = FloorEstimate::FromHeightPitchRoll(
      f.sensor_height, DegToRad(f.pitch_deg), DegToRad(f.roll_deg));
  const Intrinsics intrinsics = Intrinsics::KinectV1(f.width, f.height);
  Result<DepthRenderer> renderer = DepthRenderer::Create(intrinsics, mount);
  if (!renderer.ok()) return ReportError(kSimulateCmd, renderer.error());
  KinectNoiseOptions noise_options;
  noise_options.noise_enabled = !f.no_noise;
  noise_options.correlated_share = f.noise_correlation;
  noise_options.correlation_radius_px = f.noise_correlation_px;
  Result<KinectNoiseModel> noise = KinectNoiseModel::Create(noise_options);
  if (!noise.ok()) return ReportError(kSimulateCmd, noise.error());

  std::error_code ec;
  std::filesystem::create_directories(f.out_dir, ec);
  if (ec || !std::filesystem::is_directory(f.out_dir)) {
    return ReportError(kSimulateCmd,
                       MakeError(ErrorCode::kInternal,
                                 "cannot create directory " + f.out_dir + ": " + ec.message()));
  }
  const std::filesystem::path dir(f.out_dir);

  SimTruth truth;
  truth.humanoid_preset = robot.label;
  truth.humanoid_height_m = robot.Bounds().max().z();
  truth.humanoid_pose = poses.front();
  for (const PlacedHumanoid& o : others) truth.other_humanoids.push_back({o.pose, o.preset});
  truth.sensor_height_m = f.sensor_height;
  truth.sensor_pitch_rad = DegToRad(f.pitch_deg);
  truth.sensor_roll_rad = DegToRad(f.roll_deg);
  truth.intrinsics = intrinsics;
  truth.noise_enabled = !f.no_noise;
  truth.noise_correlated_share = f.noise_correlation;
  truth.noise_correlation_radius_px = f.noise_correlation_px;
  truth.seed = static_cast<std::uint64_t>(f.seed);
  truth.clutter_count = f.clutter;
  truth.clutter = clutter_objects;
  for (int i = 0; i < argc; ++i) truth.command += (i ? " " : "") + std::string(argv[i]);

  if (Status s = WriteIntrinsicsJson(intrinsics, (dir / "intrinsics.json").string()); !s.ok()) {
    return ReportError(kSimulateCmd, s.error());
  }
  double render_seconds = 0.0;
  for (int i = 0; i < f.frames; ++i) {
    Scene scene;
    if (Status s = robot.AddTo(&scene, poses[i]); !s.ok()) {
      return ReportError(kSimulateCmd, s.error());
    }
    for (const PlacedHumanoid& o : others) scene.AddHumanoid(o.model, o.pose, o.preset);
    for (const Primitive& c : clutter_objects) scene.AddClutter(c);

    SimFrameTruth frame;
    frame.index = i;
    frame.humanoid_pose = poses[i];
    frame.noise_seed =
        static_cast<std::uint64_t>(f.seed) * 1000003ULL + static_cast<std::uint64_t>(i);
    frame.depth_file = FrameName("depth", ".png", i, f.frames);
    frame.cloud_file = f.no_cloud ? "" : FrameName("cloud", ".pcd", i, f.frames);

    const auto start = std::chrono::steady_clock::now();
    const DepthImage depth = renderer->Render(scene, &*noise, frame.noise_seed);
    render_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (Status s = WriteDepthPng(depth, (dir / frame.depth_file).string()); !s.ok()) {
      return ReportError(kSimulateCmd, s.error());
    }
    if (!f.no_cloud) {
      DepthToCloudOptions cloud_options;
      cloud_options.min_range_m = 0.0;
      cloud_options.max_range_m = 65.535;
      cloud_options.keep_organised = true;
      Result<PointCloud> cloud = DepthToCloud(depth, intrinsics, cloud_options);
      if (!cloud.ok()) return ReportError(kSimulateCmd, cloud.error());
      if (Status s = WritePcd(*cloud, (dir / frame.cloud_file).string()); !s.ok()) {
        return ReportError(kSimulateCmd, s.error());
      }
    }
    size_t valid = 0;
    for (const std::uint16_t mm : depth.mm) valid += mm != 0 ? 1 : 0;
    std::cout << frame.depth_file << ": humanoid x " << Fixed(poses[i].x * 1000.0, 0) << " mm, y "
              << Fixed(poses[i].y * 1000.0, 0) << " mm, theta "
              << Fixed(RadToDeg(poses[i].theta), 1) << " deg; " << valid << " of "
              << depth.mm.size() << " pixels with a reading\n";
    truth.frames.push_back(frame);
  }
  if (Status s = WriteFileAtomically((dir / "truth.json").string(), SimTruthToJson(truth));
      !s.ok()) {
    return ReportError(kSimulateCmd, s.error());
  }
  std::cout << "wrote " << f.frames << " frame(s), intrinsics.json and truth.json to " << f.out_dir
            << " (rendering " << Fixed(render_seconds * 1000.0 / f.frames, 0) << " ms per frame)\n";
  return kExitOk;
}

}  // namespace

int RunSimulate(int argc, char** argv) {
  return RunSimulateSubcommand({RunSimulateScene, RunSimulateStereo, RunSimulateTurntable}, argc,
                               argv);
}

}  // namespace hpose::tools
