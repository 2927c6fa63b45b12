// `hpose estimate`: the depth-template estimator on one depth frame or cloud.
#include <chrono>
#include <cmath>
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
#include "tools/cmd_estimate_flags.h"
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
  EstimateFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  if (const int code = TakePositionalFrame(flags.positional(), &f.depth_path, &f.cloud_path);
      code >= 0) {
    return code;
  }
  const bool have_depth = !f.depth_path.empty();
  const bool have_cloud = !f.cloud_path.empty();
  if (have_depth == have_cloud) {
    std::cerr << "hpose estimate: give either --depth (with --intrinsics) or --cloud\n";
    return kExitUsage;
  }
  if (have_cloud && !f.intrinsics_path.empty()) {
    std::cerr << "hpose estimate: --intrinsics goes with --depth, not --cloud\n";
    return kExitUsage;
  }
  if (f.options.max_height_voxels != 0 &&
      (f.options.max_height_voxels < 8 || f.options.max_height_voxels > 1024)) {
    return UsageError(cmd, "--max-height-voxels must be 0 (off) or within [8, 1024], got " +
                               std::to_string(f.options.max_height_voxels));
  }
  if (!flags.Seen("floor-height") &&
      (flags.Seen("floor-pitch-deg") || flags.Seen("floor-roll-deg"))) {
    return UsageError(cmd, std::string("--floor-") +
                               (flags.Seen("floor-pitch-deg") ? "pitch" : "roll") +
                               "-deg goes with --floor-height (a fixed floor); without it the "
                               "floor is fitted to each frame");
  }
  if (!f.picture.empty()) {  // before the work: a picture that cannot be written is an error.
    const Status writable = CheckOutputPath(f.picture);
    if (!writable.ok()) return ReportError(cmd, writable.error());
  }
  f.options.cloud.stride = f.stride;
  Result<SearchKind> kind = ParseSearchKind(f.search);
  if (!kind.ok()) return UsageError(cmd, "--search: " + kind.error().message);
  f.options.search = *kind;
  Result<ScoreKind> score_kind = ParseScoreKind(f.score);
  if (!score_kind.ok()) return UsageError(cmd, "--score: " + score_kind.error().message);
  f.options.score = *score_kind;
  if (flags.Seen("floor-max-tilt-deg")) {
    // As hposed's floor.max_tilt_rad: within 1.5 rad, as a fixed floor's pitch.
    if (!(f.floor_max_tilt_deg > 0.0 && f.floor_max_tilt_deg <= 85.9)) {
      std::cerr << "hpose estimate: --floor-max-tilt-deg must be within (0, 85.9] degrees\n";
      return kExitUsage;
    }
    f.options.floor_fit.max_tilt_rad = DegToRad(f.floor_max_tilt_deg);
  }
  if (flags.Seen("floor-height")) {
    if (!(f.floor_height > 0.0 && f.floor_height < 10.0)) {
      std::cerr << "hpose estimate: --floor-height must be within (0, 10) m\n";
      return kExitUsage;
    }
    // As hposed's floor.pitch_rad and roll_rad: within 1.5 rad, short of looking straight down.
    if (!(std::abs(f.floor_pitch_deg) < 85.9 && std::abs(f.floor_roll_deg) < 85.9)) {
      std::cerr << "hpose estimate: --floor-pitch-deg and --floor-roll-deg must be within +-85.9 "
                   "degrees\n";
      return kExitUsage;
    }
    f.options.use_fixed_floor = true;
    f.options.fixed_floor = FloorEstimate::FromHeightPitchRoll(
        f.floor_height, DegToRad(f.floor_pitch_deg), DegToRad(f.floor_roll_deg));
  }

  Result<std::vector<VoxelTemplate>> templates = LoadTemplates(f.template_paths);
  if (!templates.ok()) return ReportError(cmd, templates.error());
  Result<std::unique_ptr<Estimator>> estimator = Estimator::Create(f.options, *templates);
  if (!estimator.ok()) return ReportError(cmd, estimator.error());
  if (const std::string note = SearchVoxelsNote(**estimator); !note.empty()) {
    std::cerr << "hpose estimate: note: " << note << "\n";
  }

  PointCloud cloud;
  Result<Estimate> estimate = MakeError(ErrorCode::kInternal, "not run");
  if (have_depth) {
    Result<DepthFrameFile> frame = ReadDepthFrame(f.depth_path);
    if (!frame.ok()) return ReportError(cmd, frame.error());
    const DepthImage* depth = &frame->depth;
    Intrinsics intrinsics = frame->intrinsics;  // a pclzf's own .xml, when it has one.
    // --intrinsics, else the intrinsics.json beside the frame (as replay and hposed read it).
    std::string intrinsics_file = f.intrinsics_path;
    std::error_code ec;
    const bool beside = intrinsics_file.empty() &&
                        std::filesystem::is_regular_file(IntrinsicsJsonBeside(f.depth_path), ec);
    if (beside) intrinsics_file = IntrinsicsJsonBeside(f.depth_path);
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
                             std::to_string(intrinsics.height) + " but " + f.depth_path + " is " +
                             std::to_string(depth->width) + "x" + std::to_string(depth->height)));
    }
    estimate = (*estimator)->EstimateDepth(*depth, intrinsics);
    if (!f.picture.empty()) {
      Result<PointCloud> c = DepthToCloud(*depth, intrinsics, f.options.cloud);
      if (c.ok()) cloud = std::move(c).value();
    }
  } else {
    Result<PointCloud> read = ReadCloud(f.cloud_path);
    if (!read.ok()) return ReportError(cmd, read.error());
    cloud = std::move(read).value();
    estimate = (*estimator)->EstimateCloud(cloud);
  }
  if (f.json) {  // the schema of `hpose replay` (docs/API.md), also when the frame failed.
    v1::PoseEstimate msg;
    const std::string& input = have_depth ? f.depth_path : f.cloud_path;
    server::FillPoseEstimate(
        1, TimeFromFrameFileName(input).value_or(0.0), std::chrono::system_clock::now(), input,
        estimate.ok() ? &*estimate : nullptr, estimate.ok() ? nullptr : &estimate.error(), &msg);
    std::cout << server::MessageToJsonLine(msg) << "\n";
  }
  if (!estimate.ok()) {
    // The floor fitter names its option; which flag sets it.
    if (estimate.error().message.find("max_tilt_rad") != std::string::npos) {
      std::cerr << "hpose estimate: note: --floor-max-tilt-deg sets max_tilt_rad (up to 85.9 "
                   "degrees); --floor-height and --floor-pitch-deg give a fixed floor\n";
    }
    return ReportError(cmd, estimate.error());
  }
  if (!f.json) {
    std::cout << EstimateToText(*estimate, &f.options);
  }
  if (!f.picture.empty()) {
    Status st = WriteMatchPicture(*estimate, *templates, cloud, f.picture, &f.options);
    if (!st.ok()) return ReportError(cmd, st.error());
    if (!f.json) std::cout << "picture   " << f.picture << "\n";
  }
  return estimate->Humanoids().empty() ? kExitNoHumanoid : kExitOk;
}

}  // namespace hpose::tools
