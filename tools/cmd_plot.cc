// `hpose plot`: a picture of a track of depth estimates (JSON Lines of hpose.v1.PoseEstimate).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/io/atomic_file.h"
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

// One estimate line as a point of the track; false for a line of the stereo estimator.
bool ParseLine(const std::string& line, TrackPoint* point) {
  const nlohmann::json e = nlohmann::json::parse(line);
  if (!e.is_object()) throw std::runtime_error("not a JSON object");
  if (e.value("estimator", std::string()) != kDepthEstimator) return false;
  *point = TrackPoint();
  point->time_s = Number(e, "source_time", 0.0);
  const auto depth = e.find("depth_template");
  if (depth == e.end() || depth->is_null()) return true;  // a frame that failed (e.g. no floor).
  const auto best = depth->find("best");
  if (best == depth->end() || best->is_null() || !best->value("is_humanoid", false)) return true;
  const nlohmann::json& c = best->at("best");
  const nlohmann::json& pose = c.at("pose");
  point->found = true;
  point->pose = Pose2D{pose.at("x").get<double>(), pose.at("y").get<double>(),
                       pose.at("theta").get<double>()};
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
  long line_number = 0, other = 0;
  std::string line;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    TrackPoint point;
    try {
      if (!ParseLine(line, &point)) {
        ++other;
        continue;
      }
    } catch (const std::exception& e) {
      return ReportError("plot", MakeError(ErrorCode::kInvalidArgument,
                                           name + ": line " + std::to_string(line_number) +
                                               " is not a PoseEstimate in JSON: " + e.what()));
    }
    // Times as frame files may carry them, poses within the 10 km a ground frame is given in.
    if (!(std::abs(point.time_s) <= 1e11 && std::abs(point.pose.x) <= 1e4 &&
          std::abs(point.pose.y) <= 1e4 && std::abs(point.pose.theta) <= 4 * kPi)) {
      return ReportError("plot", MakeError(ErrorCode::kInvalidArgument,
                                           name + ": line " + std::to_string(line_number) +
                                               " has a time beyond 1e11 s or a pose beyond 10 km "
                                               "or two turns"));
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
  if (const Status drawn = WriteTrackPicture(track, f.title.empty() ? name : f.title, f.out);
      !drawn.ok()) {
    return ReportError("plot", drawn.error());
  }
  int found = 0;
  for (const TrackPoint& p : track) found += p.found ? 1 : 0;
  std::cout << "drew " << track.size() << " estimates (humanoid in " << found << ") to " << f.out
            << "\n";
  return kExitOk;
}

}  // namespace hpose::tools
