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

}  // namespace

int RunSimulate(int argc, char** argv) {
  // `hpose simulate stereo ...` renders stereo pairs: the same as `hpose simulate-stereo ...`.
  if (argc >= 2 && std::string(argv[1]) == "stereo") {
    std::string prog = "hpose simulate stereo";
    argv[1] = prog.data();
    return RunSimulateStereo(argc - 1, argv + 1);
  }
  if (argc >= 2 && std::string(argv[1]) == "turntable") {
    std::string prog = "hpose simulate turntable";
    argv[1] = prog.data();
    return RunSimulateTurntable(argc - 1, argv + 1);
  }
  std::string out_dir;
  double x = 1.0, y = 0.0, theta_deg = 0.0;
  std::string pose_name = "standing";
  std::string body = "nao", robot_urdf;
  RobotFlags robot_flags;
  double sensor_height = 0.34, pitch_deg = 0.0, roll_deg = 0.0;
  int clutter = 0, seed = 1, width = 640, height = 480, frames = 1;
  bool no_noise = false, no_cloud = false;
  double turn_deg = 0.0, step_m = 0.0;
  std::string second_at, second_pose = "standing";

  FlagParser flags(
      "hpose simulate --out DIR [--x M --y M --theta-deg D] [--pose NAME --body NAME | --robot "
      "ROBOT.urdf [--joints FILE.yaml --joint-set NAME | --joint N=RAD]] [--sensor-height M "
      "--pitch-deg D --roll-deg D] [--clutter N --seed S] [--frames N --turn-deg D --step-m M]",
      "Renders simulated Kinect v1 depth frames of the parametric humanoid (or, with --robot, a\n"
      "robot described by a URDF and its meshes) standing on a floor,\n"
      "optionally among clutter (a ball, boxes, cylinders) and a second humanoid, with the\n"
      "a Kinect v1 sensor model: axial noise 1.425e-3 z^2 m, 0.8 px lateral jitter, 11-bit\n"
      "disparity quantisation, no reading outside 0.8-4.0 m or beyond 80 degrees incidence.\n"
      "Writes DIR/depth.png (16-bit, mm), DIR/intrinsics.json, DIR/cloud.pcd (sensor frame, m)\n"
      "and DIR/truth.json (poses in the ground frame, metres and radians); with --frames N > 1\n"
      "the frames are depth_000.png, cloud_000.pcd, ... Poses: ground frame origin on the floor\n"
      "below the sensor, x along the optical axis projected on the floor, y left; theta = 0\n"
      "means the humanoid faces away from the sensor.");
  flags.AddString("out", &out_dir, "output directory (created if missing)", "DIR");
  flags.AddDouble("x", &x, "humanoid x in the ground frame, metres (distance ahead)", "M");
  flags.AddDouble("y", &y, "humanoid y in the ground frame, metres (left)", "M");
  flags.AddDouble("theta-deg", &theta_deg, "humanoid heading, degrees (0 = facing away)", "D");
  flags.AddString("pose", &pose_name, "joint preset: standing or right_arm_raised", "NAME");
  flags.AddString("body", &body, "humanoid proportions: nao, long_legs or tall", "NAME");
  flags.AddString("robot", &robot_urdf,
                  "render this URDF robot instead of the parametric humanoid (see the joint "
                  "and package flags below)",
                  "ROBOT.urdf");
  robot_flags.Register(&flags, /*one_set=*/true);
  flags.AddDouble("sensor-height", &sensor_height, "optical centre above the floor, metres", "M");
  flags.AddDouble("pitch-deg", &pitch_deg, "sensor pitch, degrees (+ looks down)", "D");
  flags.AddDouble("roll-deg", &roll_deg, "sensor roll, degrees (+ image right side down)", "D");
  flags.AddInt("clutter", &clutter,
               "random clutter objects: the first a ball, then boxes and cylinders", "N");
  flags.AddInt("seed", &seed, "seed of the clutter layout and the sensor noise", "S");
  flags.AddInt("width", &width, "image width, pixels (Kinect v1 intrinsics scaled)", "PX");
  flags.AddInt("height", &height, "image height, pixels", "PX");
  flags.AddBool("no-noise", &no_noise,
                "exact depth: no random noise or quantisation (range and incidence limits "
                "still apply)");
  flags.AddInt("frames", &frames, "number of frames; the humanoid moves between them", "N");
  flags.AddDouble("turn-deg", &turn_deg, "humanoid turn per frame, degrees (counter-clockwise)",
                  "D");
  flags.AddDouble("step-m", &step_m, "humanoid walk per frame along its heading, metres", "M");
  flags.AddString("second-at", &second_at,
                  "add a second (still) humanoid at X,Y,THETA_DEG (metres, degrees)", "X,Y,DEG");
  flags.AddString("second-pose", &second_pose, "joint preset of the second humanoid", "NAME");
  flags.AddBool("no-cloud", &no_cloud, "do not write the point clouds");
  flags.SetEpilog(
      "examples:\n"
      "  hpose simulate --out sim1                      # the paper's setup: 1 m ahead, theta 0\n"
      "  hpose simulate --out sim2 --x 2 --theta-deg 90 --pose right_arm_raised --clutter 6\n"
      "  hpose simulate --out turn --frames 12 --turn-deg 30   # a full turn in 30 deg steps\n"
      "  hpose simulate --out darwin --robot ../shared/data/darwin_op/robots/robotis_op.urdf \\\n"
      "      --allow-missing --theta-deg 60 --clutter 4\n"
      "  hpose simulate turntable --help   # captures on a turntable for template from-captures\n"
      "\nexit status: 0 ok, 1 error writing the files, 2 bad flags or values");
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;

  // Values.
  if (out_dir.empty()) return UsageError(kSimulateCmd, "--out DIR is required");
  if (std::abs(x) > 20.0 || std::abs(y) > 20.0) {
    return UsageError(kSimulateCmd, "--x and --y must be within +-20 m");
  }
  if (!(sensor_height > 0.05 && sensor_height <= 3.0)) {
    return UsageError(kSimulateCmd,
                      "--sensor-height must be in (0.05, 3] m, got " + Fixed(sensor_height, 3));
  }
  if (std::abs(pitch_deg) > 60.0)
    return UsageError(kSimulateCmd, "--pitch-deg must be within +-60 degrees");
  if (std::abs(roll_deg) > 45.0)
    return UsageError(kSimulateCmd, "--roll-deg must be within +-45 degrees");
  if (clutter < 0 || clutter > 50) return UsageError(kSimulateCmd, "--clutter must be in [0, 50]");
  if (seed < 0) return UsageError(kSimulateCmd, "--seed must be >= 0");
  if (width < 16 || width > 4096 || height < 16 || height > 4096) {
    return UsageError(kSimulateCmd, "--width and --height must be in [16, 4096] pixels");
  }
  if (frames < 1 || frames > 1000) return UsageError(kSimulateCmd, "--frames must be in [1, 1000]");
  if (std::abs(turn_deg) > 180.0)
    return UsageError(kSimulateCmd, "--turn-deg must be within +-180 degrees");
  if (std::abs(step_m) > 1.0) return UsageError(kSimulateCmd, "--step-m must be within +-1 m");
  MainRobot robot;
  if (!robot_urdf.empty()) {
    if (flags.Seen("pose") || flags.Seen("body")) {
      return UsageError(kSimulateCmd,
                        "--pose and --body describe the parametric humanoid: not with --robot");
    }
    Result<std::shared_ptr<const MeshBvh>> mesh =
        LoadPosedRobotMesh(robot_flags, robot_urdf, kSimulateCmd, &robot.label);
    if (!mesh.ok()) return ReportError(kSimulateCmd, mesh.error());
    robot.mesh = *mesh;
  } else {
    Result<HumanoidDimensions> dimensions = HumanoidDimensions::Variant(body);
    if (!dimensions.ok()) return UsageError(kSimulateCmd, "--body: " + dimensions.error().message);
    Result<HumanoidModel> model = HumanoidModel::FromPreset(pose_name, *dimensions);
    if (!model.ok()) return UsageError(kSimulateCmd, "--pose: " + model.error().message);
    robot.model = *model;
    robot.label = body == "nao" ? pose_name : pose_name + "/" + body;
  }
  std::vector<PlacedHumanoid> others;
  if (!second_at.empty() || flags.Seen("second-pose")) {
    Pose2D p;
    if (!ParsePoseTriple(second_at, &p)) {
      return UsageError(kSimulateCmd,
                        "--second-at needs X,Y,THETA_DEG (e.g. 2,0.5,90), got '" + second_at + "'");
    }
    Result<HumanoidModel> m = HumanoidModel::FromPreset(second_pose);
    if (!m.ok()) return UsageError(kSimulateCmd, "--second-pose: " + m.error().message);
    others.push_back({*m, p, second_pose});
  }

  // Where the main humanoid stands in every frame.
  std::vector<Pose2D> poses;
  Pose2D pose{x, y, NormalizeAngle(DegToRad(theta_deg))};
  for (int i = 0; i < frames; ++i) {
    poses.push_back(pose);
    pose.x += step_m * std::cos(pose.theta);
    pose.y += step_m * std::sin(pose.theta);
    pose.theta = NormalizeAngle(pose.theta + DegToRad(turn_deg));
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
  if (clutter > 0) {
    Scene layout;
    for (const Pose2D& p : poses) robot.AddTo(&layout, p);
    for (const PlacedHumanoid& o : others) layout.AddHumanoid(o.model, o.pose);
    const Status s = layout.AddRandomClutter(clutter, static_cast<std::uint64_t>(seed));
    if (!s.ok()) return UsageError(kSimulateCmd, "--clutter: " + s.error().message);
    clutter_objects = layout.clutter();
  }

  const FloorEstimate mount =
      FloorEstimate::FromHeightPitchRoll(sensor_height, DegToRad(pitch_deg), DegToRad(roll_deg));
  const Intrinsics intrinsics = Intrinsics::KinectV1(width, height);
  Result<DepthRenderer> renderer = DepthRenderer::Create(intrinsics, mount);
  if (!renderer.ok()) return ReportError(kSimulateCmd, renderer.error());
  KinectNoiseOptions noise_options;
  noise_options.noise_enabled = !no_noise;
  Result<KinectNoiseModel> noise = KinectNoiseModel::Create(noise_options);
  if (!noise.ok()) return ReportError(kSimulateCmd, noise.error());

  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec || !std::filesystem::is_directory(out_dir)) {
    return ReportError(kSimulateCmd,
                       MakeError(ErrorCode::kInternal,
                                 "cannot create directory " + out_dir + ": " + ec.message()));
  }
  const std::filesystem::path dir(out_dir);

  SimTruth truth;
  truth.humanoid_preset = robot.label;
  truth.humanoid_height_m = robot.Bounds().max().z();
  truth.humanoid_pose = poses.front();
  for (const PlacedHumanoid& o : others) truth.other_humanoids.push_back({o.pose, o.preset});
  truth.sensor_height_m = sensor_height;
  truth.sensor_pitch_rad = DegToRad(pitch_deg);
  truth.sensor_roll_rad = DegToRad(roll_deg);
  truth.intrinsics = intrinsics;
  truth.noise_enabled = !no_noise;
  truth.seed = static_cast<std::uint64_t>(seed);
  truth.clutter_count = clutter;
  truth.clutter = clutter_objects;
  for (int i = 0; i < argc; ++i) truth.command += (i ? " " : "") + std::string(argv[i]);

  if (Status s = WriteIntrinsicsJson(intrinsics, (dir / "intrinsics.json").string()); !s.ok()) {
    return ReportError(kSimulateCmd, s.error());
  }
  double render_seconds = 0.0;
  for (int i = 0; i < frames; ++i) {
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
        static_cast<std::uint64_t>(seed) * 1000003ULL + static_cast<std::uint64_t>(i);
    frame.depth_file = FrameName("depth", ".png", i, frames);
    frame.cloud_file = no_cloud ? "" : FrameName("cloud", ".pcd", i, frames);

    const auto start = std::chrono::steady_clock::now();
    const DepthImage depth = renderer->Render(scene, &*noise, frame.noise_seed);
    render_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (Status s = WriteDepthPng(depth, (dir / frame.depth_file).string()); !s.ok()) {
      return ReportError(kSimulateCmd, s.error());
    }
    if (!no_cloud) {
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
  std::cout << "wrote " << frames << " frame(s), intrinsics.json and truth.json to " << out_dir
            << " (rendering " << Fixed(render_seconds * 1000.0 / frames, 0) << " ms per frame)\n";
  return kExitOk;
}

}  // namespace hpose::tools
