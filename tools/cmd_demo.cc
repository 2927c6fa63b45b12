// `hpose demo`: the embedded default. Simulates one Kinect frame (the paper's set-up plus some
// clutter), runs the estimator on it with the shipped templates and shows the result next to
// the truth, with a picture.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>

#include "core/io/atomic_file.h"
#include "core/search/estimator.h"
#include "core/sim/frame_simulator.h"
#include "core/sim/triangle_mesh.h"
#include "core/templates/voxel_template.h"
#include "tools/command.h"
#include "tools/estimate_report.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"
#include "tools/match_picture.h"
#include "tools/robot_flags.h"
#include "tools/template_paths.h"

namespace hpose::tools {

int RunDemo(int argc, char** argv) {
  const std::string cmd = "demo";
  FrameSpec spec;
  spec.preset = "right_arm_raised";
  spec.humanoid_pose = Pose2D{1.3, 0.15, DegToRad(-120.0)};
  spec.clutter = 4;
  spec.seed = 7;
  double theta_deg = RadToDeg(spec.humanoid_pose.theta);
  std::string picture = "hpose-demo.png";
  std::string robot_urdf;
  RobotFlags robot_flags;
  FlagParser flags(
      "hpose demo [--x M --y M --theta-deg D --pose NAME --clutter N --seed S]",
      "Simulates one 640x480 Kinect v1 frame of a humanoid among clutter (sensor 0.34 m\n"
      "above the floor, level), estimates the humanoid's pose with the shipped\n"
      "templates and prints the estimate beside the truth. No input needed. With --robot,\n"
      "the humanoid is that URDF robot and its template is made on the fly from the URDF.");
  flags.AddDouble("x", &spec.humanoid_pose.x, "humanoid x in the ground frame, metres", "M");
  flags.AddDouble("y", &spec.humanoid_pose.y, "humanoid y in the ground frame, metres", "M");
  flags.AddDouble("theta-deg", &theta_deg, "humanoid heading, degrees (0 = facing away)", "DEG");
  flags.AddString("pose", &spec.preset, "humanoid joint preset: standing or right_arm_raised",
                  "NAME");
  flags.AddString("body", &spec.body, "humanoid proportions: nao, long_legs or tall", "NAME");
  flags.AddString("robot", &robot_urdf,
                  "simulate and look for this URDF robot (template made from it, 16 mm voxels)",
                  "ROBOT.urdf");
  robot_flags.Register(&flags, /*one_set=*/true);
  flags.AddInt("clutter", &spec.clutter, "random objects on the floor");
  int seed = static_cast<int>(spec.seed);
  flags.AddInt("seed", &seed, "clutter and noise seed");
  flags.AddString("picture", &picture, "where to draw the match", "OUT.png");
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  spec.humanoid_pose.theta = NormalizeAngle(DegToRad(theta_deg));
  if (seed < 0 || spec.clutter < 0 || spec.clutter > 50) {
    std::cerr << "hpose demo: --seed must be >= 0 and --clutter within [0, 50]\n";
    return kExitUsage;
  }
  spec.seed = static_cast<std::uint64_t>(seed);
  const Status writable = CheckOutputPath(picture);  // before the work.
  if (!writable.ok()) return ReportError(cmd, writable.error());

  Result<std::vector<VoxelTemplate>> templates = std::vector<VoxelTemplate>{};
  if (robot_urdf.empty()) {
    templates = LoadTemplates({});
    if (!templates.ok()) return ReportError(cmd, templates.error());
  } else {
    Result<std::shared_ptr<const MeshBvh>> mesh =
        LoadPosedRobotMesh(robot_flags, robot_urdf, cmd, &spec.preset);
    if (!mesh.ok()) return ReportError(cmd, mesh.error());
    spec.robot_mesh = *mesh;
    const double resolution = 0.016;
    Result<VoxelTemplate> tpl = MakeMeshTemplate((*mesh)->mesh(), "robot", resolution, "robot",
                                                 "hpose demo --robot " + robot_urdf);
    if (!tpl.ok()) return ReportError(cmd, tpl.error());
    templates->push_back(*tpl);
  }
  Result<SimulatedFrame> frame = SimulateFrame(spec);
  if (!frame.ok()) return ReportError(cmd, frame.error());
  const EstimatorOptions options = DefaultEstimatorOptions();
  Result<std::unique_ptr<Estimator>> estimator = Estimator::Create(options, *templates);
  if (!estimator.ok()) return ReportError(cmd, estimator.error());
  Result<Estimate> estimate = (*estimator)->EstimateDepth(frame->depth, spec.intrinsics);
  if (!estimate.ok()) return ReportError(cmd, estimate.error());

  char truth[200];
  std::snprintf(truth, sizeof truth, "%s at x %.3f m, y %.3f m, theta %.1f deg",
                spec.preset.c_str(), spec.humanoid_pose.x, spec.humanoid_pose.y,
                RadToDeg(spec.humanoid_pose.theta));
  std::cout << "simulated 640x480 Kinect v1 frame: sensor 0.34 m high, level; " << spec.clutter
            << " clutter objects (seed " << spec.seed << ")\n"
            << "truth     " << truth << "\n"
            << EstimateToText(*estimate);
  const std::vector<Detection> humans = estimate->Humanoids();
  if (!humans.empty()) {
    const Candidate& c = humans.front().best;
    std::printf("error     x %+.0f mm, y %+.0f mm, theta %+.1f deg\n",
                1000 * (c.pose.x - spec.humanoid_pose.x), 1000 * (c.pose.y - spec.humanoid_pose.y),
                RadToDeg(AngleDiff(c.pose.theta, spec.humanoid_pose.theta)));
  }
  Result<PointCloud> cloud = DepthToCloud(frame->depth, spec.intrinsics, options.cloud);
  if (cloud.ok()) {
    Status st = WriteMatchPicture(*estimate, *templates, *cloud, picture);
    if (!st.ok()) return ReportError(cmd, st.error());
    std::cout << "picture   " << picture << "\n";
  }
  return humans.empty() ? kExitNoHumanoid : kExitOk;
}

}  // namespace hpose::tools
