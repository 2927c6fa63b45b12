// `hpose replay`: runs the estimator over a recording and writes every frame's estimate.
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "core/common/pose2d.h"
#include "core/io/atomic_file.h"
#include "core/io/intrinsics_file.h"
#include "core/search/estimator.h"
#include "core/search/pose_tracker.h"
#include "core/templates/template_io.h"
#include "server/daemon_config.h"
#include "server/frame_source.h"
#include "server/message_json.h"
#include "server/proto_convert.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"
#include "tools/template_paths.h"

namespace hpose::tools {

namespace {

const char kCsvHeader[] =
    "sequence,source_time_s,origin,ok,error,clusters,template,is_humanoid,x_m,y_m,theta_rad,"
    "score,template_margin,has_runner_up,runner_up_theta_rad,runner_up_score,floor_height_m,"
    "total_s\n";

std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string CsvRow(const v1::PoseEstimate& e) {
  char buf[512];
  std::string row = std::to_string(e.sequence()) + ",";
  std::snprintf(buf, sizeof(buf), "%.6f", e.source_time());
  row += std::string(buf) + "," + CsvField(e.source()) + ",";
  const bool ok = e.error().code().empty();
  row += std::string(ok ? "1" : "0") + "," + CsvField(e.error().message()) + ",";
  const v1::DepthTemplateResult& r = e.depth_template();
  row += std::to_string(r.clusters_size()) + ",";
  if (ok && r.detections_size() > 0) {
    const v1::Detection& d = r.best();
    const v1::Candidate& c = d.best();
    std::snprintf(buf, sizeof(buf), "%s,%d,%.6f,%.6f,%.6f,%.3f,%.3f,%d,%.6f,%.3f,%.6f,%.6f",
                  CsvField(c.template_name()).c_str(), d.is_humanoid() ? 1 : 0, c.pose().x(),
                  c.pose().y(), c.pose().theta(), c.score(), d.template_margin(),
                  c.has_runner_up() ? 1 : 0, c.runner_up_pose().theta(), c.runner_up_score(),
                  r.floor().height(), e.timings().total());
  } else {
    std::snprintf(buf, sizeof(buf), ",0,,,,,,0,,,%s,%.6f",
                  ok ? std::to_string(r.floor().height()).c_str() : "", e.timings().total());
  }
  return row + buf + "\n";
}

void DrawProgress(long done, long total, double elapsed_s) {
  const int width = 30;
  const double frac = total > 0 ? std::min(1.0, static_cast<double>(done) / total) : 0.0;
  const int filled = static_cast<int>(frac * width);
  std::fprintf(stderr, "\r[%s%s] %ld/%ld frames  %.1f frames/s ", std::string(filled, '#').c_str(),
               std::string(width - filled, '.').c_str(), done, total,
               elapsed_s > 0 ? done / elapsed_s : 0.0);
  std::fflush(stderr);
}

}  // namespace

int RunReplay(int argc, char** argv) {
  std::string out_path, format, config_path, intrinsics_path, rate = "fast", initial_pose;
  std::vector<std::string> templates;
  int max_frames = 0;
  double fps = 30.0;
  bool progress = isatty(STDERR_FILENO) != 0, no_progress = false;
  FlagParser flags(
      "hpose replay RECORDING [--template FILE.bt ...] [--out FILE] [--format jsonl|csv]",
      "Estimates the humanoid's pose in every frame of a recording and writes one record per "
      "frame: JSON Lines (hpose.v1.PoseEstimate in the schema of docs/API.md, every field "
      "present, SI units) or CSV. A recording is an .oni file; a directory of 16-bit depth "
      "frames (PNG with intrinsics.json, TIFF, or PCL's *_depth.pclzf with their .xml) or of PCD "
      "clouds; or a single frame file of one of these formats. Frame times come from the file "
      "names when they record one (frame_20121214T142255.814212.pcd, 1355495775.81.png), else "
      "from --fps. Prints a progress bar and a summary on stderr.");
  flags.AddStrings(
      "template", &templates,
      "humanoid template: a .bt file or a shipped template's name (default: the shipped templates)",
      "FILE.bt");
  flags.AddString("out", &out_path, "output file (default: standard output)", "FILE");
  flags.AddString("format", &format, "jsonl or csv (default: from --out's extension, else jsonl)",
                  "FMT");
  flags.AddString("config", &config_path, "hposed YAML config for search and floor settings",
                  "FILE");
  flags.AddString("rate", &rate, "fast (as fast as possible) or recorded", "RATE");
  flags.AddDouble("fps", &fps, "frame rate of files whose names record no time (source_time)",
                  "HZ");
  flags.AddString("intrinsics", &intrinsics_path,
                  "depth camera intrinsics for every frame: hpose's intrinsics.json or a ROS "
                  "camera_info YAML (default: intrinsics.json beside the frames, a pclzf's .xml, "
                  "else Kinect v1 for TIFF)",
                  "FILE");
  flags.AddInt("max-frames", &max_frames, "stop after N frames (0 = all)", "N");
  flags.AddString("initial-pose", &initial_pose,
                  "where the robot stands at the start, ground frame (metres, degrees): until "
                  "it is first found, frames are searched as if the one before had seen it there, "
                  "so a robot too far to pass the score threshold cold is found "
                  "(search.tracked_score_threshold); default: source.initial_pose of --config",
                  "X,Y,DEG");
  flags.AddBool("no-progress", &no_progress, "no progress bar");
  flags.AllowPositional("RECORDING");
  flags.SetEpilog(
      "examples:\n  hpose replay walk.oni --template templates/standing.bt --out walk.jsonl\n"
      "  hpose replay grabber_sequences/tiff/ --out poses.jsonl\n"
      "  hpose replay frame_20121214T142255.814212.pcd\n"
      "  hpose replay frames/ --template templates/standing.bt --format csv > poses.csv\n");
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  if (flags.positional().size() != 1) {
    std::cerr << flags.Help() << "\nerror: expected exactly one RECORDING\n";
    return kExitUsage;
  }
  if (format.empty()) {
    format = out_path.size() > 4 && out_path.compare(out_path.size() - 4, 4, ".csv") == 0 ? "csv"
                                                                                          : "jsonl";
  }
  if (format != "jsonl" && format != "csv") {
    std::cerr << "hpose replay: --format: expected jsonl or csv, got '" << format << "'\n";
    return kExitUsage;
  }
  Pose2D start_pose;
  const bool has_start = !initial_pose.empty();
  if (has_start && !ParsePoseTriple(initial_pose, &start_pose)) {
    std::cerr << "hpose replay: --initial-pose: expected X,Y,DEG (e.g. 3.2,0.4,90), got '"
              << initial_pose << "'\n";
    return kExitUsage;
  }
  if (rate != "fast" && rate != "recorded") {
    std::cerr << "hpose replay: --rate: expected fast or recorded, got '" << rate << "'\n";
    return kExitUsage;
  }
  if (no_progress) progress = false;
  if (!(fps > 0.0 && fps <= 10000.0)) {
    std::cerr
        << "hpose replay: --fps: the frame rate must be more than 0 and at most 10000 frames per "
           "second, got "
        << fps << "\n";
    return kExitUsage;
  }
  if (!out_path.empty()) {  // before the work: results that cannot be written are an error.
    const Status writable = CheckOutputPath(out_path);
    if (!writable.ok()) return ReportError("replay", writable.error());
  }

  server::DaemonConfig config;
  if (!config_path.empty()) {
    Result<server::DaemonConfig> loaded = server::LoadDaemonConfig(config_path);
    if (!loaded.ok()) return ReportError("replay", loaded.error());
    config = std::move(*loaded);
  }
  if (!templates.empty()) config.templates = templates;
  if (config.templates.empty()) config.templates = DefaultTemplatePaths();
  config.templates = ResolveTemplateNames(config.templates);
  if (intrinsics_path.empty()) intrinsics_path = config.source.intrinsics;
  std::vector<VoxelTemplate> loaded;
  for (const std::string& path : config.templates) {
    Result<VoxelTemplate> t = LoadTemplate(path);
    if (!t.ok()) return ReportError("replay", t.error());
    loaded.push_back(std::move(*t));
  }
  EstimatorOptions options = server::EffectiveEstimatorOptions(config);
  Result<std::unique_ptr<Estimator>> estimator = Estimator::Create(options, std::move(loaded));
  if (!estimator.ok()) return ReportError("replay", estimator.error());
  PoseTracker tracker(estimator->get());
  if (has_start) {
    tracker.SetInitialPose(start_pose);
  } else if (config.source.has_initial_pose) {
    tracker.SetInitialPose(config.source.initial_pose);
  }

  server::ReplayOptions replay;
  replay.realtime = rate == "recorded";
  replay.loop = false;
  replay.fps = fps;
  if (!intrinsics_path.empty()) {
    Result<Intrinsics> k = ReadIntrinsicsFile(intrinsics_path);
    if (!k.ok()) return ReportError("replay", k.error());
    replay.has_intrinsics = true;
    replay.intrinsics = *k;
  }
  Result<std::unique_ptr<server::FrameSource>> source =
      server::MakeFrameSource(flags.positional()[0], replay);
  if (!source.ok()) return ReportError("replay", source.error());
  if ((*source)->live()) {
    std::cerr << "hpose replay: " << flags.positional()[0]
              << " is a live device; record it first (hpose record)\n";
    return kExitUsage;
  }
  Status opened = (*source)->Open();
  if (!opened.ok()) return ReportError("replay", opened.error());

  std::ofstream file;
  if (!out_path.empty()) {
    file.open(out_path, std::ios::binary | std::ios::trunc);
    if (!file) {
      return ReportError("replay", MakeError(ErrorCode::kInternal, out_path + ": cannot write"));
    }
  }
  std::ostream& out = out_path.empty() ? std::cout : file;
  if (format == "csv") out << kCsvHeader;

  long total = (*source)->frame_count();
  if (max_frames > 0 && (total < 0 || total > max_frames)) total = max_frames;
  long frames = 0, estimated = 0, failed = 0, unreadable = 0, humanoids = 0;
  std::vector<double> times_ms;
  const auto start = std::chrono::steady_clock::now();
  while (max_frames <= 0 || frames < max_frames) {
    Result<server::Frame> frame = (*source)->Next();
    if (!frame.ok()) {
      if (frame.error().code == ErrorCode::kOutOfRange) break;
      if (frame.error().code == ErrorCode::kUnavailable) {
        return ReportError("replay", frame.error());
      }
      ++unreadable;
      std::cerr << (progress ? "\n" : "")
                << "hpose replay: skipping a frame: " << frame.error().message << "\n";
      if (unreadable > 100) return ReportError("replay", frame.error());
      continue;
    }
    ++frames;
    // Like hposed: with source.tracking (the default) each frame starts from the last pose and
    // the floor is kept while it fits.
    Result<Estimate> result =
        config.source.tracking
            ? (frame->is_cloud ? tracker.EstimateCloud(frame->cloud)
                               : tracker.EstimateDepth(frame->depth, frame->intrinsics))
            : (frame->is_cloud ? (*estimator)->EstimateCloud(frame->cloud)
                               : (*estimator)->EstimateDepth(frame->depth, frame->intrinsics));
    v1::PoseEstimate msg;
    server::FillPoseEstimate(frame->sequence, frame->source_time_s, frame->received, frame->origin,
                             result.ok() ? &*result : nullptr,
                             result.ok() ? nullptr : &result.error(), &msg);
    if (result.ok()) {
      ++estimated;
      times_ms.push_back(result->timings.total_ms);
      if (!result->Humanoids().empty()) ++humanoids;
    } else {
      ++failed;
    }
    if (format == "csv") {
      out << CsvRow(msg);
    } else {
      out << server::MessageToJsonLine(msg) << "\n";
    }
    if (!out) {  // a full disk or a closed pipe: stop instead of estimating for nothing.
      return ReportError("replay", MakeError(ErrorCode::kInternal,
                                             (out_path.empty() ? "standard output" : out_path) +
                                                 ": write failed: " + std::strerror(errno)));
    }
    if (progress) {
      DrawProgress(frames, std::max(total, frames),
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
  }
  out.flush();
  if (progress) std::fprintf(stderr, "\n");
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::sort(times_ms.begin(), times_ms.end());
  const double median = times_ms.empty() ? 0.0 : times_ms[times_ms.size() / 2];
  std::fprintf(stderr,
               "hpose replay: %ld frame(s) in %.2f s (%.1f frames/s): %ld estimated, %ld failed "
               "(e.g. no floor), %ld unreadable; humanoid found in %ld; median estimate %.1f ms\n",
               frames, wall, wall > 0 ? frames / wall : 0.0, estimated, failed, unreadable,
               humanoids, median);
  if (!out_path.empty()) file.close();
  if (!out || (!out_path.empty() && file.fail())) {
    return ReportError("replay", MakeError(ErrorCode::kInternal,
                                           (out_path.empty() ? "standard output" : out_path) +
                                               ": write failed: " + std::strerror(errno)));
  }
  return frames > 0 ? kExitOk : kExitError;
}

}  // namespace hpose::tools
