#include "bench/bench_frames.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>

#include "bench/bench_bodies.h"
#include "core/common/vector_level.h"
#include "core/depth/cluster_extractor.h"
#include "core/depth/depth_to_cloud.h"
#include "core/depth/floor_fitter.h"
#include "core/depth/range_image.h"
#include "core/scoring/free_space.h"
#include "core/search/vector_paths.h"
#include "core/sim/humanoid_model.h"
#include "core/sim/humanoid_template.h"
#include "core/templates/template_io.h"

namespace hpose::bench {

Result<std::vector<VoxelTemplate>> LoadShippedTemplates(const std::string& dir,
                                                        const std::vector<std::string>& names) {
  std::vector<VoxelTemplate> templates;
  for (const std::string& name : names) {
    Result<VoxelTemplate> t = LoadTemplate(dir + "/" + name + ".bt");
    if (!t.ok()) return t.error();
    templates.push_back(std::move(*t));
  }
  return templates;
}

Result<std::vector<VoxelTemplate>> BodyTemplates(const std::string& body,
                                                 const std::vector<std::string>& names) {
  std::vector<VoxelTemplate> templates;
  for (const std::string& name : names) {
    Result<VoxelTemplate> t = PoseTemplate(body, name);
    if (!t.ok()) return t.error();
    templates.push_back(std::move(*t));
  }
  return templates;
}

std::vector<FrameSpec> BenchFrameSpecs(int count, int clutter, double max_distance_m) {
  std::vector<FrameSpec> specs;
  for (int i = 0; i < count; ++i) {
    FrameSpec s;
    s.preset = i % 2 == 0 ? "standing" : "right_arm_raised";
    const double heading_deg = -180.0 + std::fmod(77.0 * i, 360.0);
    const double distance = 0.9 + (max_distance_m - 0.9) / 11.0 * (i % 12);
    const double lateral = 0.05 * ((i % 7) - 3);
    s.humanoid_pose = Pose2D{distance, lateral, NormalizeAngle(DegToRad(heading_deg))};
    s.clutter = clutter;
    s.seed = static_cast<std::uint64_t>(i + 1);
    specs.push_back(s);
  }
  return specs;
}

std::vector<FrameSpec> BenchSequenceSpecs(int count, int clutter, double far_m) {
  constexpr double kNear = 1.4;  // metres.
  const double centre = 0.5 * (kNear + far_m), radius = 0.5 * (far_m - kNear);
  std::vector<FrameSpec> specs;
  for (int i = 0; i < count; ++i) {
    FrameSpec s;
    s.preset = (i / 15) % 2 == 0 ? "standing" : "right_arm_raised";
    // Walking a circle around (centre, 0) from its nearest point, 2.5 degrees of arc a frame
    // (about 3.5 cm with the default 0.8 m radius), facing along the path: the farthest point
    // after 72 frames, every heading in 144.
    const double phi = kPi + DegToRad(2.5 * i);
    s.humanoid_pose = Pose2D{centre + radius * std::cos(phi), radius * std::sin(phi),
                             NormalizeAngle(phi + 0.5 * kPi)};
    s.clutter = clutter;
    s.seed = 1;  // the same clutter in every frame.
    specs.push_back(s);
  }
  return specs;
}

SearchProblem BenchProblem::Problem(bool with_min_value) const {
  SearchProblem p;
  p.cluster = &cluster;
  p.scorer = scorer.get();
  p.rotations = rotations;
  p.centre_ground = centre;
  p.free_space = &free_space;
  p.free_space_weight = free_space_weight;
  p.hit_weight = hit_weight;
  if (with_min_value) p.min_value = min_value;
  return p;
}

Status AppendProblems(const SimulatedFrame& frame, const Intrinsics& intrinsics,
                      const EstimatorOptions& options, const std::vector<VoxelTemplate>& templates,
                      const std::vector<std::unique_ptr<TemplateRotations>>& rotations,
                      const std::string& label, std::vector<BenchProblem>* out) {
  Result<PointCloud> cloud = DepthToCloud(frame.depth, intrinsics, options.cloud);
  if (!cloud.ok()) return cloud.error();
  Result<FloorEstimate> floor = FitFloor(*cloud, options.floor_fit);
  if (!floor.ok()) return floor.error();
  Result<std::vector<Cluster>> clusters = ExtractClusters(*cloud, *floor, options.clusters);
  if (!clusters.ok()) return clusters.error();

  // The same free-space set-up as Estimator::Run.
  const double res = options.lattice.resolution_m;
  const RangeImage range = RangeImage::FromCloud(*cloud, options.range_image_focal_px);
  const Eigen::Isometry3d sensor_from_ground = floor->ground_from_sensor.inverse();
  double reach = 0.0;
  int top_cell = 0;
  for (const VoxelTemplate& tpl : templates) {
    for (const Eigen::Vector3f& v : tpl.voxels) {
      reach = std::max(reach, static_cast<double>(v.head<2>().norm()));
      top_cell = std::max(top_cell, CellOf(v, res).z());
    }
  }
  reach += 2.0 * res;

  for (size_t i = 0; i < clusters->size(); ++i) {
    const Cluster& c = (*clusters)[i];
    for (const auto& rot : rotations) {
      if (options.max_height_ratio_error >= 0.0 &&
          std::abs(c.height() / rot->height_m() - 1.0) > options.max_height_ratio_error) {
        continue;
      }
      BenchProblem p;
      p.label = label + " cluster " + std::to_string(i) + " " + rot->name();
      p.cluster = VoxeliseCluster(c.points, res);
      p.scorer = MakePoseScorer(ScorerKind::kFast, p.cluster, options.lattice);
      const Eigen::Vector3f lo(c.min.x() - 2 * reach, c.min.y() - 2 * reach, 0.0f);
      const Eigen::Vector3f hi(c.max.x() + 2 * reach, c.max.y() + 2 * reach, 0.0f);
      Eigen::Vector3i cell_lo = CellOf(lo, res), cell_hi = CellOf(hi, res);
      cell_lo.z() = 0;
      cell_hi.z() = top_cell;
      p.free_space =
          FreeSpaceCells(range, sensor_from_ground, cell_lo, cell_hi, res, options.free_space);
      p.rotations = rot.get();
      p.centre = c.centroid.head<2>().cast<double>();
      p.free_space_weight = options.free_space_weight;
      p.hit_weight = options.hit_weight;
      p.min_value =
          static_cast<int>(std::ceil(options.score_threshold * options.hit_weight *
                                         static_cast<double>(p.cluster.cells.size()) / 100.0 -
                                     1e-9));
      out->push_back(std::move(p));
    }
  }
  return Status::Ok();
}

double Median(std::vector<double> v) { return Percentile(std::move(v), 50.0); }

double ThreadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t rank = static_cast<size_t>(std::ceil(p / 100.0 * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, rank == 0 ? 0 : rank - 1)];
}

bool PrintVectorPaths(const char* program) {
  const Status variable = CheckVectorLevelVariable();
  if (!variable.ok()) {
    std::fprintf(stderr, "%s: %s\n", program, variable.error().message.c_str());
    return false;
  }
  std::printf("Vector paths of this CPU: %s.\n", VectorPathsInUse().c_str());
  return true;
}

}  // namespace hpose::bench
