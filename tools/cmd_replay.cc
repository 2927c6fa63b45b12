// `hpose replay`: runs the estimator over a recording and writes every frame's estimate.
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "core/common/clock_limits.h"
#include "core/common/pose2d.h"
#include "core/io/atomic_file.h"
#include "core/io/intrinsics_file.h"
#include "core/search/estimator.h"
#include "core/search/pose_tracker.h"
#include "core/sim/sim_truth.h"
#include "core/sim/truth_comparison.h"
#include "core/templates/template_io.h"
#include "server/daemon_config.h"
#include "server/frame_source.h"
#include "server/message_json.h"
#include "server/proto_convert.h"
#include "tools/cmd_replay_flags.h"
#include "tools/command.h"
#include "tools/estimate_report.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"
#include "tools/template_paths.h"

namespace hpose::tools {

namespace {

const char kCsvHeader[] =
    "sequence,source_time_s,origin,ok,error,clusters,template,is_humanoid,x_m,y_m,theta_rad,"
    "score,template_margin,has_runner_up,runner_up_theta_rad,runner_up_score,floor_height_m,"
    "total_s,refused_by,template_margin_kind\n";

// An enum value's name without its prefix, in lower case ("REFUSAL_FIT" -> "fit").
std::string EnumWord(const std::string& name, const std::string& prefix) {
  std::string word = name.substr(name.rfind(prefix, 0) == 0 ? prefix.size() : 0);
  std::transform(word.begin(), word.end(), word.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return word;
}

// The rule that refused the best detection as the humanoid, in lower case ("fit", "score", ...);
// empty for a humanoid.
std::string RefusalWord(v1::Refusal r) {
  return r == v1::REFUSAL_NONE ? "" : EnumWord(v1::Refusal_Name(r), "REFUSAL_");
}

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
    std::snprintf(
        buf, sizeof(buf), "%s,%d,%.6f,%.6f,%.6f,%.3f,%.3f,%d,%.6f,%.3f,%.6f,%.6f,%s,%s",
        CsvField(c.template_name()).c_str(), d.is_humanoid() ? 1 : 0, c.pose().x(), c.pose().y(),
        c.pose().theta(), c.score(), d.template_margin(), c.has_runner_up() ? 1 : 0,
        c.runner_up_pose().theta(), c.runner_up_score(), r.floor().height(), e.timings().total(),
        RefusalWord(d.is_humanoid() ? v1::REFUSAL_NONE : d.refused_by()).c_str(),
        EnumWord(v1::TemplateMarginKind_Name(d.template_margin_kind()), "TEMPLATE_MARGIN_")
            .c_str());
  } else {
    std::snprintf(buf, sizeof(buf), ",0,,,,,,0,,,%s,%.6f,,",
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
  bool progress = isatty(STDERR_FILENO) != 0;
  ReplayFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  if (flags.positional().size() != 1) {
    std::cerr << flags.Help() << "\nerror: expected exactly one RECORDING\n";
    return kExitUsage;
  }
  if (f.format.empty()) {
    f.format = f.out_path.size() > 4 && f.out_path.compare(f.out_path.size() - 4, 4, ".csv") == 0
                   ? "csv"
                   : "jsonl";
  }
  if (f.format != "jsonl" && f.format != "csv") {
    std::cerr << "hpose replay: --format: expected jsonl or csv, got '" << f.format << "'\n";
    return kExitUsage;
  }
  Pose2D start_pose;
  const bool has_start = !f.initial_pose.empty();
  if (has_start && !ParsePoseTriple(f.initial_pose, &start_pose)) {
    std::cerr << "hpose replay: --initial-pose: expected X,Y,DEG (e.g. 3.2,0.4,90), got '"
              << f.initial_pose << "'\n";
    return kExitUsage;
  }
  if (f.rate != "fast" && f.rate != "recorded") {
    std::cerr << "hpose replay: --rate: expected fast or recorded, got '" << f.rate << "'\n";
    return kExitUsage;
  }
  if (f.no_progress) progress = false;
  if (!FrameRateInRange(f.fps)) {  // as hposed's source.fps.
    std::cerr << "hpose replay: --fps: the frame rate must be in [0.01, 10000] frames per "
                 "second, got "
              << f.fps << "\n";
    return kExitUsage;
  }
  if (!f.out_path.empty()) {  // before the work: results that cannot be written are an error.
    const Status writable = CheckOutputPath(f.out_path);
    if (!writable.ok()) return ReportError("replay", writable.error());
  }

  std::unique_ptr<SimTruth> truth;
  if (!f.truth_path.empty()) {  // before the work, as the output.
    Result<SimTruth> parsed = LoadSimTruth(f.truth_path);
    if (!parsed.ok()) return ReportError("replay", parsed.error());
    truth = std::make_unique<SimTruth>(std::move(*parsed));
  }

  server::DaemonConfig config;
  if (!f.config_path.empty()) {
    Result<server::DaemonConfig> loaded = server::LoadDaemonConfig(f.config_path);
    if (!loaded.ok()) return ReportError("replay", loaded.error());
    config = std::move(*loaded);
    const Status valid = server::ValidateEstimationConfig(config, f.config_path);
    if (!valid.ok()) return ReportError("replay", valid.error());
  }
  if (!f.templates.empty()) config.templates = f.templates;
  if (config.templates.empty()) config.templates = DefaultTemplatePaths();
  if (f.intrinsics_path.empty()) f.intrinsics_path = config.source.intrinsics;
  Result<std::vector<VoxelTemplate>> loaded = LoadTemplates(config.templates);
  if (!loaded.ok()) return ReportError("replay", loaded.error());
  EstimatorOptions options = server::EffectiveEstimatorOptions(config);
  Result<std::unique_ptr<Estimator>> estimator = Estimator::Create(options, std::move(*loaded));
  if (!estimator.ok()) return ReportError("replay", estimator.error());
  if (const std::string note = SearchVoxelsNote(**estimator); !note.empty()) {
    std::cerr << "hpose replay: note: " << note << "\n";
  }
  PoseTracker tracker(estimator->get());
  if (has_start) {
    tracker.SetInitialPose(start_pose);
  } else if (config.source.has_initial_pose) {
    tracker.SetInitialPose(config.source.initial_pose);
  }

  server::ReplayOptions replay;
  replay.realtime = f.rate == "recorded";
  replay.loop = false;
  replay.fps = f.fps;
  if (!f.intrinsics_path.empty()) {
    Result<Intrinsics> k = ReadIntrinsicsFile(f.intrinsics_path);
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
  if (!f.out_path.empty()) {
    file.open(f.out_path, std::ios::binary | std::ios::trunc);
    if (!file) {
      return ReportError("replay", MakeError(ErrorCode::kInternal, f.out_path + ": cannot write"));
    }
  }
  std::ostream& out = f.out_path.empty() ? std::cout : file;
  if (f.format == "csv") out << kCsvHeader;

  long total = (*source)->frame_count();
  if (f.max_frames > 0 && (total < 0 || total > f.max_frames)) total = f.max_frames;
  long frames = 0, estimated = 0, failed = 0, unreadable = 0, humanoids = 0;
  std::string first_failure;  // "FRAME: why", said after the summary.
  std::vector<double> times_ms;
  TruthComparer comparer;
  long without_truth = 0;  // frames that --truth does not name.
  const auto start = std::chrono::steady_clock::now();
  while (f.max_frames <= 0 || frames < f.max_frames) {
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
    std::vector<Pose2D> found;  // the humanoids' poses.
    if (result.ok()) {
      ++estimated;
      times_ms.push_back(result->timings.total_ms);
      for (const Detection& d : result->Humanoids()) found.push_back(d.best.pose);
      if (!found.empty()) ++humanoids;
    } else {
      if (failed++ == 0) first_failure = frame->origin + ": " + result.error().message;
    }
    if (truth != nullptr) {
      const SimFrameTruth* stood = FindFrameTruth(*truth, frame->origin);
      if (stood == nullptr) {
        ++without_truth;
      } else {
        comparer.Add(stood->humanoid_pose, found);
      }
    }
    if (f.format == "csv") {
      out << CsvRow(msg);
    } else {
      out << server::MessageToJsonLine(msg) << "\n";
    }
    if (!out) {  // a full disk or a closed pipe: stop instead of estimating for nothing.
      return ReportError("replay", MakeError(ErrorCode::kInternal,
                                             (f.out_path.empty() ? "standard output" : f.out_path) +
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
  if (failed > 0) std::cerr << "hpose replay: the first that failed, " << first_failure << "\n";
  const TruthComparison c = comparer.Summary();
  if (truth != nullptr && c.frames > 0) {
    std::cerr << "hpose replay: against " << f.truth_path << ": " << DescribeTruthComparison(c);
    if (without_truth > 0) std::cerr << "; " << without_truth << " frame(s) not in it";
    std::cerr << "\n";
  }
  if (!f.out_path.empty()) file.close();
  if (!out || (!f.out_path.empty() && file.fail())) {
    return ReportError("replay", MakeError(ErrorCode::kInternal,
                                           (f.out_path.empty() ? "standard output" : f.out_path) +
                                               ": write failed: " + std::strerror(errno)));
  }
  if (truth != nullptr && c.frames == 0) {  // after the estimates are safely written.
    std::cerr << "hpose replay: --truth " << f.truth_path
              << ": names none of the recording's frames (they are matched by file name)\n";
    return kExitError;
  }
  return frames > 0 ? kExitOk : kExitError;
}

}  // namespace hpose::tools
