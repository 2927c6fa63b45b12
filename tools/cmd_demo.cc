// `hpose demo`: the embedded default. Simulates one Kinect frame (the paper's set-up plus some
// clutter), runs the estimator on it with the shipped templates and shows the result next to
// the truth, with a picture.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>

#include "core/io/atomic_file.h"
#include "core/search/estimator.h"
#include "core/search/humanoid_view.h"
#include "core/sim/frame_simulator.h"
#include "core/sim/triangle_mesh.h"
#include "core/templates/voxel_template.h"
#include "tools/cmd_demo_flags.h"
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
  DemoFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  f.spec.humanoid_pose.theta = NormalizeAngle(DegToRad(f.theta_deg));
  if (flags.Seen("robot") && f.robot_urdf.empty()) {
    return UsageError(cmd, "--robot needs a URDF file, got an empty path");
  }
  f.spec.seed = static_cast<std::uint64_t>(f.seed);
  const Status writable = CheckOutputPath(f.picture);  // before the work.
  if (!writable.ok()) return ReportError(cmd, writable.error());

  Result<std::vector<VoxelTemplate>> templates = std::vector<VoxelTemplate>{};
  if (f.robot_urdf.empty()) {
    templates = LoadTemplates({});
    if (!templates.ok()) return ReportError(cmd, templates.error());
  } else {
    Result<std::shared_ptr<const MeshBvh>> mesh =
        LoadPosedRobotMesh(f.robot_flags, f.robot_urdf, cmd, &f.spec.preset);
    if (!mesh.ok()) return ReportError(cmd, mesh.error());
    f.spec.robot_mesh = *mesh;
    const double resolution = 0.016;
    Result<VoxelTemplate> tpl = MakeMeshTemplate((*mesh)->mesh(), "robot", resolution, "robot",
                                                 "hpose demo --robot " + f.robot_urdf);
    if (!tpl.ok()) return ReportError(cmd, tpl.error());
    templates->push_back(*tpl);
  }
  Result<SimulatedFrame> frame = SimulateFrame(f.spec);
  if (!frame.ok()) return ReportError(cmd, frame.error());
  const EstimatorOptions options = DefaultEstimatorOptions();
  Result<std::unique_ptr<Estimator>> estimator = Estimator::Create(options, *templates);
  if (!estimator.ok()) return ReportError(cmd, estimator.error());
  Result<Estimate> estimate = (*estimator)->EstimateDepth(frame->depth, f.spec.intrinsics);
  if (!estimate.ok()) return ReportError(cmd, estimate.error());

  char truth[200];
  std::snprintf(truth, sizeof truth, "%s at x %.3f m, y %.3f m, theta %.1f deg",
                f.spec.preset.c_str(), f.spec.humanoid_pose.x, f.spec.humanoid_pose.y,
                RadToDeg(f.spec.humanoid_pose.theta));
  std::cout << "simulated 640x480 Kinect v1 frame: sensor 0.34 m high, level; " << f.spec.clutter
            << " clutter objects (seed " << f.spec.seed << ")\n"
            << "truth     " << truth << "\n"
            << EstimateToText(*estimate, &options);
  const HumanoidView humans = estimate->Humanoids();
  if (!humans.empty()) {
    const Candidate& c = humans.front().best;
    std::printf("error     x %+.0f mm, y %+.0f mm, theta %+.1f deg\n",
                1000 * (c.pose.x - f.spec.humanoid_pose.x),
                1000 * (c.pose.y - f.spec.humanoid_pose.y),
                RadToDeg(AngleDiff(c.pose.theta, f.spec.humanoid_pose.theta)));
  }
  Result<PointCloud> cloud = DepthToCloud(frame->depth, f.spec.intrinsics, options.cloud);
  if (cloud.ok()) {
    Status st = WriteMatchPicture(*estimate, *templates, *cloud, f.picture, &options);
    if (!st.ok()) return ReportError(cmd, st.error());
    std::cout << "picture   " << f.picture << "\n";
  }
  return humans.empty() ? kExitNoHumanoid : kExitOk;
}

}  // namespace hpose::tools
