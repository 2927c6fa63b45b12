// `hpose plot`: a picture of a track of depth estimates (JSON Lines of hpose.v1.PoseEstimate).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/io/atomic_file.h"
#include "core/sim/sim_truth.h"
#include "core/sim/truth_comparison.h"
#include "tools/cmd_plot_flags.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/track_picture.h"

namespace hpose::tools {
namespace {

constexpr const char* kDepthEstimator = "ESTIMATOR_KIND_DEPTH_TEMPLATE";

// The number at `key` of `j`, or `fallback` when it is absent or null.
double Number(const nlohmann::json& j, const char* key, double fallback) {
  const auto it = j.find(key);
  if (it == j.end() || it->is_null()) return fallback;
  return it->get<double>();  // throws for a value of another type.
}

Pose2D PoseOf(const nlohmann::json& pose) {
  return Pose2D{pose.at("x").get<double>(), pose.at("y").get<double>(),
                pose.at("theta").get<double>()};
}

// One estimate line as a point of the track, with its frame's source and the poses of every
// humanoid found in it; false for a line of the stereo estimator.
bool ParseLine(const std::string& line, TrackPoint* point, std::string* source,
               std::vector<Pose2D>* humanoids) {
  const nlohmann::json e = nlohmann::json::parse(line);
  if (!e.is_object()) throw std::runtime_error("not a JSON object");
  if (e.value("estimator", std::string()) != kDepthEstimator) return false;
  *point = TrackPoint();
  point->time_s = Number(e, "source_time", 0.0);
  *source = e.value("source", std::string());
  humanoids->clear();
  const auto depth = e.find("depth_template");
  if (depth == e.end() || depth->is_null()) return true;  // a frame that failed (e.g. no floor).
  if (const auto all = depth->find("detections"); all != depth->end() && all->is_array()) {
    for (const nlohmann::json& d : *all) {
      if (d.value("is_humanoid", false)) humanoids->push_back(PoseOf(d.at("best").at("pose")));
    }
  }
  const auto best = depth->find("best");
  if (best == depth->end() || best->is_null() || !best->value("is_humanoid", false)) return true;
  const nlohmann::json& c = best->at("best");
  const nlohmann::json& pose = c.at("pose");
  point->found = true;
  point->pose = PoseOf(pose);
  point->score = Number(c, "score", 0.0);
  point->heading_ambiguous = c.value("heading_ambiguous", false);
  return true;
}

}  // namespace

int RunPlot(int argc, char** argv) {
  PlotFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  if (flags.positional().size() != 1 || f.out.empty()) {
    std::cerr << flags.Help() << "\nerror: give one POSES.jsonl and --out TRACK.png\n";
    return kExitUsage;
  }
  const std::string input = flags.positional().front();
  if (const Status writable = CheckOutputPath(f.out); !writable.ok()) {
    return ReportError("plot", writable.error());
  }
  std::unique_ptr<SimTruth> truth;
  if (!f.truth_path.empty()) {  // before the input is read.
    Result<SimTruth> loaded = LoadSimTruth(f.truth_path);
    if (!loaded.ok()) return ReportError("plot", loaded.error());
    truth = std::make_unique<SimTruth>(std::move(*loaded));
  }
  std::ifstream file;
  if (input != "-") {
    file.open(input);
    if (!file) {
      return ReportError("plot", MakeError(ErrorCode::kNotFound, input + ": cannot be read"));
    }
  }
  std::istream& in = input == "-" ? std::cin : file;
  const std::string name =
      input == "-" ? "standard input" : std::filesystem::path(input).filename().string();
  std::vector<TrackPoint> track;
  TruthComparer comparer;
  long line_number = 0, other = 0;
  std::string line, source;
  std::vector<Pose2D> humanoids;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    TrackPoint point;
    try {
      if (!ParseLine(line, &point, &source, &humanoids)) {
        ++other;
        continue;
      }
    } catch (const std::exception& e) {
      return ReportError("plot", MakeError(ErrorCode::kInvalidArgument,
                                           name + ": line " + std::to_string(line_number) +
                                               " is not a PoseEstimate in JSON: " + e.what()));
    }
    // Times as frame files may carry them, poses within the 10 km a ground frame is given in.
    const auto near = [](const Pose2D& p) {
      return std::abs(p.x) <= 1e4 && std::abs(p.y) <= 1e4 && std::abs(p.theta) <= 4 * kPi;
    };
    if (!(std::abs(point.time_s) <= 1e11 && near(point.pose) &&
          std::all_of(humanoids.begin(), humanoids.end(), near))) {
      return ReportError("plot", MakeError(ErrorCode::kInvalidArgument,
                                           name + ": line " + std::to_string(line_number) +
                                               " has a time beyond 1e11 s or a pose beyond 10 km "
                                               "or two turns"));
    }
    if (truth != nullptr) {
      if (const SimFrameTruth* stood = FindFrameTruth(*truth, source); stood != nullptr) {
        point.has_truth = true;
        point.truth = stood->humanoid_pose;
        comparer.Add(stood->humanoid_pose, humanoids);
      }
    }
    track.push_back(point);
  }
  if (in.bad()) {
    return ReportError("plot", MakeError(ErrorCode::kInternal, name + ": read failed"));
  }
  if (track.empty()) {
    return ReportError(
        "plot", MakeError(ErrorCode::kInvalidArgument,
                          name + ": no depth estimates (" + std::to_string(line_number) +
                              " lines, " + std::to_string(other) + " of another estimator)"));
  }
  const TruthComparison compared = comparer.Summary();
  if (truth != nullptr && compared.frames == 0) {
    return ReportError("plot", MakeError(ErrorCode::kInvalidArgument,
                                         "--truth " + f.truth_path + ": names none of " + name +
                                             "'s frames (matched by the file name in each "
                                             "line's source)"));
  }
  if (const Status drawn = WriteTrackPicture(track, f.title.empty() ? name : f.title, f.out);
      !drawn.ok()) {
    return ReportError("plot", drawn.error());
  }
  int found = 0;
  for (const TrackPoint& p : track) found += p.found ? 1 : 0;
  std::cout << "drew " << track.size() << " estimates (humanoid in " << found << ") to " << f.out
            << "\n";
  if (truth != nullptr) {
    std::cout << "against " << f.truth_path << ": " << DescribeTruthComparison(compared);
    if (compared.frames < static_cast<int>(track.size())) {
      std::cout << "; " << track.size() - compared.frames << " estimate(s) not in it";
    }
    std::cout << "\n";
  }
  return kExitOk;
}

}  // namespace hpose::tools
