#include "tools/estimate_report.h"

#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

namespace hpose::tools {
namespace {

using nlohmann::json;

json PoseJson(const Pose2D& p) { return {{"x", p.x}, {"y", p.y}, {"theta", p.theta}}; }

json CandidateJson(const Candidate& c) {
  json j = {{"template", c.template_name},
            {"cluster", c.cluster_index},
            {"x", c.pose.x},
            {"y", c.pose.y},
            {"theta", c.pose.theta},
            {"score", c.score},
            {"coverage", c.coverage},
            {"free_space_voxels", c.free_space_hits},
            {"hits", c.hits},
            {"cluster_voxels", c.cluster_voxels},
            {"poses_evaluated", c.poses_evaluated},
            {"bounds_evaluated", c.bounds_evaluated}};
  if (c.has_runner_up) {
    json r = PoseJson(c.runner_up_pose);
    r["score"] = c.runner_up_score;
    j["runner_up"] = r;
  } else {
    j["runner_up"] = nullptr;
  }
  return j;
}

std::string Fmt(const char* fmt, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, a);
  return buf;
}

}  // namespace

std::string EstimateToJson(const Estimate& e, const std::string& search_name,
                           const std::string& score_name, int indent) {
  json j;
  json detections = json::array();
  for (const Detection& d : e.detections) {
    if (!d.is_humanoid) continue;
    json dj = CandidateJson(d.best);
    dj["second_template"] = d.second_template.empty() ? json(nullptr) : json(d.second_template);
    dj["template_margin"] = d.template_margin;
    detections.push_back(dj);
  }
  j["humanoid_found"] = !detections.empty();
  j["detections"] = detections;
  json candidates = json::array();
  for (const Candidate& c : e.candidates) candidates.push_back(CandidateJson(c));
  j["candidates"] = candidates;
  j["search"] = search_name;
  j["score_kind"] = score_name;
  const FloorEstimate& f = e.floor;
  j["floor"] = {{"plane_sensor",
                 {f.plane_sensor[0], f.plane_sensor[1], f.plane_sensor[2], f.plane_sensor[3]}},
                {"height", f.height_m},
                {"pitch", f.pitch_rad},
                {"roll", f.roll_rad},
                {"inliers", f.inliers},
                {"fitted", f.fitted}};
  json clusters = json::array();
  for (const ClusterSummary& c : e.clusters) {
    clusters.push_back({{"index", c.index},
                        {"points", c.points},
                        {"centroid", {c.centroid.x(), c.centroid.y(), c.centroid.z()}},
                        {"min", {c.min.x(), c.min.y(), c.min.z()}},
                        {"max", {c.max.x(), c.max.y(), c.max.z()}},
                        {"searched", c.searched}});
  }
  j["clusters"] = clusters;
  j["cloud_points"] = e.cloud_points;
  j["timings_ms"] = {{"cloud", e.timings.cloud_ms},
                     {"floor", e.timings.floor_ms},
                     {"clustering", e.timings.cluster_ms},
                     {"search", e.timings.search_ms},
                     {"total", e.timings.total_ms}};
  return j.dump(indent);
}

std::string EstimateToText(const Estimate& e) {
  std::ostringstream os;
  const FloorEstimate& f = e.floor;
  os << "floor     sensor " << Fmt("%.3f", f.height_m) << " m above it, pitch "
     << Fmt("%.1f", RadToDeg(f.pitch_rad)) << " deg, roll " << Fmt("%.1f", RadToDeg(f.roll_rad))
     << " deg" << (f.fitted ? " (fitted, " + std::to_string(f.inliers) + " inliers)" : " (fixed)")
     << "\n";
  int searched = 0;
  for (const ClusterSummary& c : e.clusters) searched += c.searched;
  os << "clusters  " << e.clusters.size() << " on the floor, " << searched << " of humanoid size\n";
  const std::vector<Detection> humans = e.Humanoids();
  if (humans.empty()) {
    os << "humanoid  none found";
    if (!e.detections.empty()) {
      os << " (best: " << e.detections.front().best.template_name << " score "
         << Fmt("%.1f", e.detections.front().best.score) << ", below the threshold)";
    }
    os << "\n";
  }
  for (const Detection& d : humans) {
    const Candidate& c = d.best;
    os << "humanoid  " << c.template_name << " at x " << Fmt("%.3f", c.pose.x) << " m, y "
       << Fmt("%.3f", c.pose.y) << " m, theta " << Fmt("%.1f", RadToDeg(c.pose.theta))
       << " deg, score " << Fmt("%.1f", c.score) << " (cluster " << c.cluster_index << ")\n";
    if (c.has_runner_up) {
      os << "          runner-up theta " << Fmt("%.1f", RadToDeg(c.runner_up_pose.theta))
         << " deg, score " << Fmt("%.1f", c.runner_up_score) << "\n";
    }
    if (!d.second_template.empty()) {
      os << "          " << d.second_template << " scored " << Fmt("%.1f", d.template_margin)
         << " lower\n";
    }
  }
  os << "timings   cloud " << Fmt("%.1f", e.timings.cloud_ms) << " ms, floor "
     << Fmt("%.1f", e.timings.floor_ms) << " ms, clustering " << Fmt("%.1f", e.timings.cluster_ms)
     << " ms, search " << Fmt("%.1f", e.timings.search_ms) << " ms, total "
     << Fmt("%.1f", e.timings.total_ms) << " ms\n";
  return os.str();
}

}  // namespace hpose::tools
