// `hpose estimate`: the depth-template estimator on one depth frame or cloud.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "core/io/atomic_file.h"
#include "core/io/cloud_io.h"
#include "core/io/depth_frame_io.h"
#include "core/io/frame_file_time.h"
#include "core/io/intrinsics_file.h"
#include "core/io/intrinsics_json.h"
#include "core/search/estimator.h"
#include "server/message_json.h"
#include "server/proto_convert.h"
#include "tools/command.h"
#include "tools/estimate_report.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"
#include "tools/match_picture.h"
#include "tools/template_paths.h"

namespace hpose::tools {
namespace {

// A FRAME given without a flag becomes --depth or --cloud by its extension. Returns an exit code
// for a usage error, or -1.
int TakePositionalFrame(const std::vector<std::string>& positional, std::string* depth_path,
                        std::string* cloud_path) {
  if (positional.empty()) return -1;
  auto usage = [](const std::string& message) {
    std::cerr << "hpose estimate: " << message << " (see --help)\n";
    return kExitUsage;
  };
  if (positional.size() > 1) {
    return usage("one frame at a time, got " + std::to_string(positional.size()) +
                 " (`hpose replay` takes a directory or a recording)");
  }
  const std::string& frame = positional.front();
  if (!depth_path->empty() || !cloud_path->empty()) {
    return usage("give the frame once: '" + frame + "' and --" +
                 (depth_path->empty() ? "cloud" : "depth"));
  }
  if (IsDepthFrameFile(frame)) {
    *depth_path = frame;
  } else if (IsCloudFile(frame)) {
    *cloud_path = frame;
  } else {
    return usage("cannot tell what '" + frame +
                 "' is from its name: a depth frame ends in .png, .tif, .tiff or .pclzf, a "
                 "cloud in .pcd or .ply (or say which with --depth or --cloud)");
  }
  return -1;
}

}  // namespace

int RunEstimate(int argc, char** argv) {
  const std::string cmd = "estimate";
  std::string depth_path, intrinsics_path, cloud_path, picture;
  std::vector<std::string> template_paths;
  bool json = false;
  EstimatorOptions options = DefaultEstimatorOptions();
  options.threads = 0;  // every usable core: one frame, as soon as possible.
  std::string search = SearchKindName(options.search);
  std::string score = ScoreKindName(options.score);
  double floor_height = -1.0, floor_pitch_deg = 0.0, floor_roll_deg = 0.0;
  int stride = options.cloud.stride;

  FlagParser flags(
      "hpose estimate (FRAME | --depth FRAME [--intrinsics CAM.json] | --cloud FRAME.pcd) "
      "[--template FILE.bt ...] [--json]",
      "Finds the humanoid in one depth frame: builds the point cloud, fits the floor, clusters\n"
      "what stands on it and matches every template against every cluster by a search over\n"
      "(x, y, theta). Poses are in the ground frame: origin on the floor below the sensor, x the\n"
      "optical axis projected on the floor, y left, theta counter-clockwise (0 = facing away).\n"
      "FRAME alone is read by its extension: .png, .tif, .tiff or .pclzf as --depth, .pcd or\n"
      ".ply as --cloud.");
  flags.AllowPositional("FRAME");
  flags.AddString("depth", &depth_path,
                  "depth frame in millimetres (0 = no reading): 16-bit PNG or TIFF, or PCL's "
                  ".pclzf (with its .xml camera parameters beside it)",
                  "FRAME");
  flags.AddString("intrinsics", &intrinsics_path,
                  "the depth camera's intrinsics: hpose's JSON {\"width\",\"height\",\"fx\","
                  "\"fy\",\"cx\",\"cy\"} or a ROS camera_info YAML; default: intrinsics.json "
                  "beside the frame (as `hpose replay` and hposed read it), a .pclzf's own, else "
                  "Kinect v1 for the frame's size (a note says which)",
                  "CAM.json|CAM.yaml");
  flags.AddString("cloud", &cloud_path,
                  "point cloud (.pcd or .ply) in the sensor frame (x right, y down, z forward), "
                  "metres",
                  "FRAME.pcd");
  flags.AddStrings("template", &template_paths,
                   "humanoid template (.bt with its .json sidecar); default: the shipped "
                   "standing and right_arm_raised",
                   "FILE.bt");
  flags.AddString("search", &search,
                  "pose search: 'exact' (global optimum on a 1 deg x 4 mm lattice) or 'paper' "
                  "(the paper's two coarse-to-fine passes)",
                  "KIND");
  flags.AddString("score", &score,
                  "pose value: 'free-space' (the paper's voxel overlap minus template voxels where "
                  "the sensor saw through) or 'paper' (the overlap alone)",
                  "KIND");
  flags.AddDouble("threshold", &options.score_threshold,
                  "score (0-100) a cluster needs to count as the humanoid");
  flags.AddDouble("min-fit", &options.min_humanoid_fit,
                  "refined fit (0-100) a cluster's pose also needs to count as the humanoid: the "
                  "share of its points on the template times the share of the template not seen "
                  "through (0: the score alone)");
  flags.AddInt("stride", &stride,
               "use every N-th depth pixel (2: 640x480 -> 320x240 like the paper)");
  flags.AddDouble("floor-height", &floor_height,
                  "fixed floor calibration: sensor height above the floor in metres (skips the "
                  "per-frame floor fit)",
                  "M");
  flags.AddDouble("floor-pitch-deg", &floor_pitch_deg,
                  "with --floor-height: optical axis below the horizon, degrees", "DEG");
  flags.AddDouble("floor-roll-deg", &floor_roll_deg, "with --floor-height: roll, degrees", "DEG");
  flags.AddDouble("floor-min-width", &options.floor_fit.min_width_m,
                  "a fitted floor's inliers must spread at least this wide, metres (narrower "
                  "planes are strips through objects when no floor is in view; 0: no check)",
                  "M");
  flags.AddString("picture", &picture, "also draw the match (top and front views) to a PNG",
                  "OUT.png");
  flags.AddInt("threads", &options.threads,
               "threads for the frame's (cluster, template) searches, 0 = one per core this "
               "process may use; the result does not depend on it",
               "N");
  flags.AddBool("json", &json, "print one JSON object instead of text");
  flags.SetEpilog(
      "exit status: 0 humanoid found, 3 no humanoid passed the threshold, 4 no floor found,\n"
      "             1 bad input (the message names it), 2 usage\n\n"
      "examples:\n"
      "  hpose simulate --out /tmp/frame && hpose estimate /tmp/frame/depth.png\n"
      "  hpose estimate --depth frame.tif --intrinsics camera_info.yaml\n"
      "  hpose estimate --cloud scan.pcd --template my_robot.bt --json");
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  if (const int code = TakePositionalFrame(flags.positional(), &depth_path, &cloud_path);
      code >= 0) {
    return code;
  }
  const bool have_depth = !depth_path.empty();
  const bool have_cloud = !cloud_path.empty();
  if (have_depth == have_cloud) {
    std::cerr << "hpose estimate: give either --depth (with --intrinsics) or --cloud\n";
    return kExitUsage;
  }
  if (have_cloud && !intrinsics_path.empty()) {
    std::cerr << "hpose estimate: --intrinsics goes with --depth, not --cloud\n";
    return kExitUsage;
  }
  if (stride < 1 || stride > 16) {
    std::cerr << "hpose estimate: --stride must be within [1, 16]\n";
    return kExitUsage;
  }
  if (options.threads < 0 || options.threads > 256) {
    std::cerr << "hpose estimate: --threads must be within [0, 256] (0: one per core)\n";
    return kExitUsage;
  }
  if (!picture.empty()) {  // before the work: a picture that cannot be written is an error.
    const Status writable = CheckOutputPath(picture);
    if (!writable.ok()) return ReportError(cmd, writable.error());
  }
  options.cloud.stride = stride;
  Result<SearchKind> kind = ParseSearchKind(search);
  if (!kind.ok()) return ReportError(cmd, kind.error());
  options.search = *kind;
  Result<ScoreKind> score_kind = ParseScoreKind(score);
  if (!score_kind.ok()) return ReportError(cmd, score_kind.error());
  options.score = *score_kind;
  if (!(options.floor_fit.min_width_m >= 0.0 && options.floor_fit.min_width_m < 100.0)) {
    std::cerr << "hpose estimate: --floor-min-width must be within [0, 100) m\n";
    return kExitUsage;
  }
  if (flags.Seen("floor-height")) {
    if (!(floor_height > 0.0 && floor_height < 10.0)) {
      std::cerr << "hpose estimate: --floor-height must be within (0, 10) m\n";
      return kExitUsage;
    }
    options.use_fixed_floor = true;
    options.fixed_floor = FloorEstimate::FromHeightPitchRoll(
        floor_height, DegToRad(floor_pitch_deg), DegToRad(floor_roll_deg));
  }

  Result<std::vector<VoxelTemplate>> templates = LoadTemplates(template_paths);
  if (!templates.ok()) return ReportError(cmd, templates.error());
  Result<std::unique_ptr<Estimator>> estimator = Estimator::Create(options, *templates);
  if (!estimator.ok()) return ReportError(cmd, estimator.error());

  PointCloud cloud;
  Result<Estimate> estimate = MakeError(ErrorCode::kInternal, "not run");
  if (have_depth) {
    Result<DepthFrameFile> frame = ReadDepthFrame(depth_path);
    if (!frame.ok()) return ReportError(cmd, frame.error());
    const DepthImage* depth = &frame->depth;
    Intrinsics intrinsics = frame->intrinsics;  // a pclzf's own .xml, when it has one.
    // --intrinsics, else the intrinsics.json beside the frame (as replay and hposed read it).
    std::string intrinsics_file = intrinsics_path;
    std::error_code ec;
    const bool beside = intrinsics_file.empty() &&
                        std::filesystem::is_regular_file(IntrinsicsJsonBeside(depth_path), ec);
    if (beside) intrinsics_file = IntrinsicsJsonBeside(depth_path);
    if (!intrinsics_file.empty()) {
      Result<Intrinsics> read = ReadIntrinsicsFile(intrinsics_file);
      if (!read.ok()) return ReportError(cmd, read.error());
      intrinsics = *read;
      if (beside) {
        std::cerr << "hpose estimate: note: using the intrinsics beside the frame, "
                  << intrinsics_file << "\n";
      }
    } else if (!frame->has_intrinsics) {
      intrinsics = Intrinsics::KinectV1(depth->width, depth->height);
      std::cerr << "hpose estimate: note: no --intrinsics given; assuming Kinect v1 intrinsics "
                << "for " << depth->width << "x" << depth->height << " (fx " << intrinsics.fx
                << ", fy " << intrinsics.fy << ", cx " << intrinsics.cx << ", cy " << intrinsics.cy
                << " px)\n";
    }
    if (intrinsics.width != depth->width || intrinsics.height != depth->height) {
      return ReportError(
          cmd, MakeError(ErrorCode::kInvalidArgument,
                         "the intrinsics are for " + std::to_string(intrinsics.width) + "x" +
                             std::to_string(intrinsics.height) + " but " + depth_path + " is " +
                             std::to_string(depth->width) + "x" + std::to_string(depth->height)));
    }
    estimate = (*estimator)->EstimateDepth(*depth, intrinsics);
    if (!picture.empty()) {
      Result<PointCloud> c = DepthToCloud(*depth, intrinsics, options.cloud);
      if (c.ok()) cloud = std::move(c).value();
    }
  } else {
    Result<PointCloud> read = ReadCloud(cloud_path);
    if (!read.ok()) return ReportError(cmd, read.error());
    cloud = std::move(read).value();
    estimate = (*estimator)->EstimateCloud(cloud);
  }
  if (json) {  // the schema of `hpose replay` (docs/API.md), also when the frame failed.
    v1::PoseEstimate msg;
    const std::string& input = have_depth ? depth_path : cloud_path;
    server::FillPoseEstimate(
        1, TimeFromFrameFileName(input).value_or(0.0), std::chrono::system_clock::now(), input,
        estimate.ok() ? &*estimate : nullptr, estimate.ok() ? nullptr : &estimate.error(), &msg);
    std::cout << server::MessageToJsonLine(msg) << "\n";
  }
  if (!estimate.ok()) return ReportError(cmd, estimate.error());
  if (!json) {
    std::cout << EstimateToText(*estimate);
  }
  if (!picture.empty()) {
    Status st = WriteMatchPicture(*estimate, *templates, cloud, picture);
    if (!st.ok()) return ReportError(cmd, st.error());
    if (!json) std::cout << "picture   " << picture << "\n";
  }
  return estimate->Humanoids().empty() ? kExitNoHumanoid : kExitOk;
}

}  // namespace hpose::tools
