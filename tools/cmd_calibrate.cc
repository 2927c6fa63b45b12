// `hpose calibrate stereo`: a stereo pair's calibration from chessboard views, written as the
// file the stereo-marker estimator reads. `hpose calibrate world-from-ground`: where the depth
// sensor's ground frame sits in the landmarks' world frame, from poses both estimators reported.
#include <dirent.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "core/common/pose2d.h"
#include "core/io/intrinsics_file.h"
#include "core/search/estimator.h"
#include "core/search/humanoid_view.h"
#include "core/stereo/rgb_image_io.h"
#include "core/stereo/stereo_calibration.h"
#include "core/stereo/stereo_calibrator.h"
#include "core/stereo/stereo_estimator.h"
#include "core/stereo/stereo_marker_options.h"
#include "core/stereo/stereo_sequence.h"
#include "core/stereo/world_from_ground_fit.h"
#include "server/daemon_config.h"
#include "server/frame_source.h"
#include "tools/cmd_calibrate_flags.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"
#include "tools/template_paths.h"

namespace hpose::tools {
namespace {

// Pairs DIR/left<N><EXT> with DIR/right<N><EXT> (N: one or more digits, e.g. left01.jpg).
std::vector<std::pair<std::string, std::string>> PairsInDirectory(const std::string& dir) {
  std::vector<std::pair<std::string, std::string>> pairs;
  DIR* d = opendir(dir.c_str());
  if (d == nullptr) return pairs;
  std::vector<std::string> names;
  while (const dirent* e = readdir(d)) names.push_back(e->d_name);
  closedir(d);
  std::sort(names.begin(), names.end());
  for (const std::string& n : names) {
    if (n.rfind("left", 0) != 0 || n.size() < 5 ||
        !std::isdigit(static_cast<unsigned char>(n[4]))) {
      continue;
    }
    const std::string right = "right" + n.substr(4);
    if (std::find(names.begin(), names.end(), right) != names.end()) {
      pairs.emplace_back(dir + "/" + n, dir + "/" + right);
    }
  }
  return pairs;
}

std::string Base(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

int RunCalibrateStereo(int argc, char** argv) {
  CalibrateStereoFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  const std::string cmd = "calibrate stereo";
  if (f.out.empty()) {
    std::cerr << "hpose " << cmd << ": --out is required\n";
    return kExitUsage;
  }
  if (f.lefts.size() != f.rights.size()) {
    std::cerr << "hpose " << cmd << ": give as many --left as --right images\n";
    return kExitUsage;
  }
  std::vector<std::pair<std::string, std::string>> files;
  if (!f.dir.empty()) {
    files = PairsInDirectory(f.dir);
    if (files.empty()) {
      std::cerr << "hpose " << cmd << ": " << f.dir
                << ": no left<N>/right<N> image pairs (or not a directory)\n";
      return kExitError;
    }
  }
  for (size_t i = 0; i < f.lefts.size(); ++i) files.emplace_back(f.lefts[i], f.rights[i]);
  if (files.empty()) {
    std::cerr << "hpose " << cmd << ": give --dir or --left/--right pairs (see --help)\n";
    return kExitUsage;
  }
  std::vector<StereoCalibrationView> views;
  for (const auto& [l, r] : files) {
    StereoCalibrationView v;
    v.name = Base(l) + " " + Base(r);
    auto li = ReadRgbImage(l);
    if (!li.ok()) return ReportError(cmd, li.error());
    auto ri = ReadRgbImage(r);
    if (!ri.ok()) return ReportError(cmd, ri.error());
    v.left = std::move(li).value();
    v.right = std::move(ri).value();
    views.push_back(std::move(v));
  }
  size_t searched = 0;
  auto report = CalibrateStereo(views, f.board, [&](const StereoCalibrationReport::View& v) {
    std::cerr << "\r  corners: " << ++searched << "/" << views.size() << " pairs" << std::flush;
    (void)v;
  });
  std::cerr << "\n";
  if (!report.ok()) return ReportError(cmd, report.error());
  Status s = WriteStereoCalibrationReport(*report, f.out);
  if (!s.ok()) return ReportError(cmd, s.error());
  char line[256];
  std::cout << "| pair | board found | left RMS (px) | right RMS (px) |\n|---|---|---|---|\n";
  int used = 0;
  for (const auto& v : report->views) {
    if (v.used) {
      ++used;
      std::snprintf(line, sizeof(line), "| %s | yes | %.3f | %.3f |\n", v.name.c_str(),
                    v.left_rms_px, v.right_rms_px);
    } else {
      std::snprintf(line, sizeof(line), "| %s | no: %s | | |\n", v.name.c_str(), v.reason.c_str());
    }
    std::cout << line;
  }
  const StereoCalibration& c = report->calibration;
  std::snprintf(line, sizeof(line),
                "\nstereo RMS reprojection error %.3f px over %d of %zu pairs (left alone %.3f, "
                "right alone %.3f); baseline %.1f mm; fx %.1f / %.1f px; %dx%d\n",
                report->rms_px, used, report->views.size(), report->left_rms_px,
                report->right_rms_px, c.BaselineM() * 1e3, c.left.camera_matrix(0, 0),
                c.right.camera_matrix(0, 0), c.image_width, c.image_height);
  std::cout << line << "wrote " << f.out << "\n";
  return kExitOk;
}

// One CSV row: timestamp_s, ground x y theta, world x y theta.
Result<std::vector<GroundWorldPair>> ReadPairs(const std::string& path) {
  std::ifstream in(path);
  if (!in) return MakeError(ErrorCode::kNotFound, path + ": cannot open");
  std::vector<GroundWorldPair> pairs;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#' || std::isalpha(static_cast<unsigned char>(line[0]))) {
      continue;  // comment or header.
    }
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    GroundWorldPair p;
    if (!(fields >> p.timestamp_s >> p.ground.x >> p.ground.y >> p.ground.theta >> p.world.x >>
          p.world.y >> p.world.theta)) {
      return MakeError(ErrorCode::kInvalidArgument,
                       path + ":" + std::to_string(number) +
                           ": expected 7 numbers: timestamp_s, ground_x_m, ground_y_m, "
                           "ground_theta_rad, world_x_m, world_y_m, world_theta_rad");
    }
    pairs.push_back(p);
  }
  return pairs;
}

// The depth estimator's robot poses (ground frame) over the whole depth recording.
Result<std::vector<TimedPose>> DepthPoses(const std::string& depth,
                                          const server::DaemonConfig& config, int* frames) {
  std::vector<std::string> paths = config.templates;
  if (paths.empty()) paths = DefaultTemplatePaths();
  Result<std::vector<VoxelTemplate>> templates = LoadTemplates(paths);
  if (!templates.ok()) return templates.error();
  Result<std::unique_ptr<Estimator>> estimator =
      Estimator::Create(server::EffectiveEstimatorOptions(config), std::move(*templates));
  if (!estimator.ok()) return estimator.error();
  server::ReplayOptions replay;
  replay.realtime = false;
  replay.fps = config.source.fps;
  if (!config.source.intrinsics.empty()) {
    Result<Intrinsics> k = ReadIntrinsicsFile(config.source.intrinsics);
    if (!k.ok()) return k.error();
    replay.has_intrinsics = true;
    replay.intrinsics = *k;
  }
  Result<std::unique_ptr<server::FrameSource>> source = server::MakeFrameSource(depth, replay);
  if (!source.ok()) return source.error();
  if ((*source)->live()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     depth + ": a live device; record it first (hpose record)");
  }
  if (Status s = (*source)->Open(); !s.ok()) return s.error();
  const long total = (*source)->frame_count();
  std::vector<TimedPose> poses;
  *frames = 0;
  while (true) {
    Result<server::Frame> frame = (*source)->Next();
    if (!frame.ok()) {
      if (frame.error().code == ErrorCode::kOutOfRange) break;
      return frame.error();
    }
    ++*frames;
    Result<Estimate> e = frame->is_cloud
                             ? (*estimator)->EstimateCloud(frame->cloud)
                             : (*estimator)->EstimateDepth(frame->depth, frame->intrinsics);
    if (!e.ok()) return Error{e.error().code, frame->origin + ": " + e.error().message};
    const HumanoidView humanoids = e->Humanoids();
    if (!humanoids.empty()) poses.push_back({frame->source_time_s, humanoids.front().best.pose});
    std::cerr << "\r  depth: " << *frames << "/" << total << " frames, robot in " << poses.size()
              << std::flush;
  }
  std::cerr << "\n";
  return poses;
}

// The stereo estimator's robot poses (world frame) over the whole stereo sequence.
Result<std::vector<TimedPose>> StereoPoses(const std::string& stereo, double time_offset_s,
                                           const server::DaemonConfig& config, int* frames) {
  Result<StereoSequence> seq = StereoSequence::Open(stereo, config.stereo.fps);
  if (!seq.ok()) return seq.error();
  std::string calibration = config.stereo.calibration;
  if (calibration.empty()) calibration = seq->calibration_path();
  if (calibration.empty()) {
    return MakeError(ErrorCode::kNotFound,
                     stereo + " holds no calibration.yaml; give --stereo-calibration FILE");
  }
  StereoCalibrationReadOptions read;
  read.translation_unit_m = config.stereo.calibration_unit == "mm" ? 0.001 : 1.0;
  Result<StereoCalibration> cal = ReadStereoCalibration({calibration}, read);
  if (!cal.ok()) return cal.error();
  StereoMarkerOptions options;
  if (!config.stereo.options.empty()) {
    Result<StereoMarkerOptions> loaded = LoadStereoMarkerOptions(config.stereo.options);
    if (!loaded.ok()) return loaded.error();
    options = *loaded;
  }
  Result<std::unique_ptr<StereoEstimator>> estimator = StereoEstimator::Create(*cal, options);
  if (!estimator.ok()) return estimator.error();
  std::vector<TimedPose> poses;
  *frames = static_cast<int>(seq->size());
  for (size_t i = 0; i < seq->size(); ++i) {
    Result<std::pair<RgbImage, RgbImage>> pair = seq->Load(i);
    if (!pair.ok()) return pair.error();
    const double t = seq->frame(i).timestamp_s + time_offset_s;
    Result<StereoFrameResult> r = (*estimator)->Process(pair->first, pair->second, t);
    if (!r.ok()) return Error{r.error().code, seq->frame(i).left_path + ": " + r.error().message};
    if (r->ok()) poses.push_back({t, r->robot});
    std::cerr << "\r  stereo: " << i + 1 << "/" << seq->size() << " pairs, robot in "
              << poses.size() << std::flush;
  }
  std::cerr << "\n";
  return poses;
}

Status WritePairs(const std::vector<GroundWorldPair>& pairs, const std::string& path) {
  std::ofstream out(path);
  out << "timestamp_s,ground_x_m,ground_y_m,ground_theta_rad,world_x_m,world_y_m,"
         "world_theta_rad\n";
  char line[256];
  for (const GroundWorldPair& p : pairs) {
    std::snprintf(line, sizeof(line), "%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n", p.timestamp_s,
                  p.ground.x, p.ground.y, p.ground.theta, p.world.x, p.world.y, p.world.theta);
    out << line;
  }
  out.close();
  if (!out) return MakeError(ErrorCode::kInternal, path + ": cannot write");
  return Status::Ok();
}

int RunCalibrateWorldFromGround(int argc, char** argv) {
  WorldFromGroundFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  const std::string cmd = "calibrate world-from-ground";
  if (!f.recording.empty()) {
    if (!f.depth.empty() || !f.stereo.empty()) {
      std::cerr << "hpose " << cmd << ": --recording or --depth/--stereo, not both\n";
      return kExitUsage;
    }
    f.depth = f.recording + "/depth";
    f.stereo = f.recording + "/stereo";
  }
  const bool from_recording = !f.depth.empty() || !f.stereo.empty();
  if (from_recording == !f.pairs_path.empty() ||
      (from_recording && (f.depth.empty() || f.stereo.empty()))) {
    std::cerr << "hpose " << cmd
              << ": give --pairs, or --recording, or both --depth and --stereo (see --help)\n";
    return kExitUsage;
  }
  if (!(f.max_dt_s > 0.0 && f.max_dt_s <= 10.0)) {
    std::cerr << "hpose " << cmd << ": --max-dt must be in (0, 10] seconds\n";
    return kExitUsage;
  }
  Result<std::vector<GroundWorldPair>> pairs = std::vector<GroundWorldPair>();
  std::string origin = f.pairs_path;
  if (!from_recording) {
    pairs = ReadPairs(f.pairs_path);
    if (!pairs.ok()) return ReportError(cmd, pairs.error());
  } else {
    server::DaemonConfig config;  // hposed's config keys: how to estimate the two halves.
    if (!f.config_path.empty()) {
      Result<server::DaemonConfig> loaded = server::LoadDaemonConfig(f.config_path);
      if (!loaded.ok()) return ReportError(cmd, loaded.error());
      config = std::move(*loaded);
    }
    if (!f.templates.empty()) config.templates = f.templates;
    if (!f.stereo_calibration.empty()) config.stereo.calibration = f.stereo_calibration;
    if (!f.stereo_options.empty()) config.stereo.options = f.stereo_options;
    int depth_frames = 0, stereo_frames = 0;
    Result<std::vector<TimedPose>> ground = DepthPoses(f.depth, config, &depth_frames);
    if (!ground.ok()) return ReportError(cmd, ground.error());
    Result<std::vector<TimedPose>> world =
        StereoPoses(f.stereo, f.stereo_time_offset_s, config, &stereo_frames);
    if (!world.ok()) return ReportError(cmd, world.error());
    *pairs = PairPosesByTime(*ground, *world, f.max_dt_s);
    std::cout << "depth: robot found in " << ground->size() << " of " << depth_frames
              << " frames; stereo: robot pose in " << world->size() << " of " << stereo_frames
              << " pairs; " << pairs->size() << " pairs within " << f.max_dt_s * 1e3 << " ms\n";
    if (pairs->size() < 3) {
      std::cerr << "hpose " << cmd << ": " << f.depth << " and " << f.stereo
                << ": fewer than 3 pose pairs within --max-dt " << f.max_dt_s
                << " s (do the two clocks agree? see --stereo-time-offset)\n";
      return kExitError;
    }
    if (!f.pairs_out.empty()) {
      if (Status s = WritePairs(*pairs, f.pairs_out); !s.ok()) return ReportError(cmd, s.error());
      std::cout << "wrote " << f.pairs_out << "\n";
    }
    origin = f.recording.empty() ? f.depth + " + " + f.stereo : f.recording;
  }
  auto fit = FitWorldFromGround(*pairs, f.options);
  if (!fit.ok()) {
    Error e = fit.error();
    e.message = origin + ": " + e.message;
    return ReportError(cmd, e);
  }
  char line[512];
  std::snprintf(line, sizeof(line),
                "world_from_ground: x %.4f m, y %.4f m, yaw %.4f rad (%.2f deg)\n"
                "pairs used %d of %d; position residual RMS %.1f mm, max %.1f mm; heading "
                "residual RMS %.2f deg\n",
                fit->world_from_ground.x, fit->world_from_ground.y, fit->world_from_ground.theta,
                RadToDeg(fit->world_from_ground.theta), fit->inliers, fit->pairs, fit->rms_m * 1e3,
                fit->max_m * 1e3, RadToDeg(fit->heading_rms_rad));
  std::cout << line << "observable: " << fit->observability << "\n";
  for (size_t i = 0; i < fit->inlier.size(); ++i) {
    if (!fit->inlier[i]) {
      std::snprintf(line, sizeof(line), "  dropped pair at t=%.3f s: residual %.1f mm\n",
                    (*pairs)[i].timestamp_s, fit->residuals_m[i] * 1e3);
      std::cout << line;
    }
  }
  std::snprintf(line, sizeof(line),
                "hposed config:\n  world_from_ground: {x_m: %.4f, y_m: %.4f, yaw_rad: %.4f}\n",
                fit->world_from_ground.x, fit->world_from_ground.y, fit->world_from_ground.theta);
  std::cout << line;
  return kExitOk;
}

}  // namespace

int RunCalibrate(int argc, char** argv) {
  return RunCalibrateSubcommand({RunCalibrateStereo, RunCalibrateWorldFromGround}, argc, argv);
}

}  // namespace hpose::tools
