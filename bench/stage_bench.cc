// Cost of a frame's stages outside the pose search: depth to cloud, floor (a fit on every frame
// and FloorTracker, which reuses the last floor while it still fits), clustering (bucket grid and
// PCL's kd-tree, the reference), the range image of the free-space score and the free-space cells
// around every cluster (FreeSpaceCells, its four-height form and its reference). Runs on the
// simulated 640x480 frames of frame_bench (a sequence from one fixed sensor mount) and on any
// real clouds given with --cloud (each replayed --repeat times as a still sequence). Every
// variant runs on every frame in turn, so drift on a shared machine hits all alike. It also
// checks that the fast paths agree with the references (same clusters; tracked floor within
// 1 cm and 1 degree of a fresh fit; the same free-space cells) and says so.
// Pin it to one core for the documented numbers:
//   taskset -c 0 stage_bench [--frames N] [--clutter N] [--repeat N] [--cloud FILE]...
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "bench/bench_frames.h"
#include "core/depth/cloud_validation.h"
#include "core/depth/cluster_extractor.h"
#include "core/depth/depth_to_cloud.h"
#include "core/depth/floor_fitter.h"
#include "core/depth/floor_tracker.h"
#include "core/depth/ground_band.h"
#include "core/depth/range_image.h"
#include "core/depth/veil_filter.h"
#include "core/io/cloud_io.h"
#include "core/scoring/free_space.h"
#include "core/scoring/pose_scorer.h"

namespace hpose::bench {
namespace {

// Runs `fn` and returns the CPU time (ms) this thread spent in it: on a shared, loaded machine
// this is far steadier than wall time (the stages are single-threaded).
double TimeMs(const std::function<void()>& fn) {
  const double t0 = ThreadCpuMs();
  fn();
  return ThreadCpuMs() - t0;
}

struct Column {
  std::string name;
  std::vector<double> ms;
};

// Times of one input set (simulated frames or a real cloud), one column per stage variant.
struct Table {
  std::string title;
  std::vector<Column> columns;
  int frames = 0;
  int refits = 0;
  int cluster_mismatches = 0;
  int cluster_count = 0;
  int free_mismatches = 0;
  int veil_mismatches = 0;
  double worst_floor_angle_deg = 0.0;
  double worst_floor_height_mm = 0.0;
  // Simulated frames only: per frame, the error against the true mount of a fit on every frame
  // and of the tracked floor (angle in degrees, height in mm).
  bool has_truth = false;
  std::vector<double> fit_truth_deg, fit_truth_mm, tracked_truth_deg, tracked_truth_mm;

  std::vector<double>& At(const std::string& name) {
    for (Column& c : columns) {
      if (c.name == name) return c.ms;
    }
    columns.push_back({name, {}});
    return columns.back().ms;
  }
};

double Max(const std::vector<double>& v) {
  return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
}

double AngleDeg(const FloorEstimate& a, const FloorEstimate& b) {
  const double c = std::clamp(a.plane_sensor.head<3>().dot(b.plane_sensor.head<3>()), -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

// Worst-so-far angle (deg) and height (mm) between two floors.
void Worst(const FloorEstimate& a, const FloorEstimate& b, double* deg, double* mm) {
  *deg = std::max(*deg, AngleDeg(a, b));
  *mm = std::max(*mm, 1e3 * std::abs(a.height_m - b.height_m));
}

bool SameClusters(const std::vector<Cluster>& a, const std::vector<Cluster>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].points != b[i].points) return false;
  }
  return true;
}

// One frame through every stage variant; `cloud_ms` is the depth-to-cloud time (0 for a
// cloud read from a file); `truth` the true floor when known.
Status RunFrame(const PointCloud& cloud, double cloud_ms, const FloorEstimate* truth,
                const EstimatorOptions& options, FloorTracker* tracker, Table* table) {
  ++table->frames;
  table->At("cloud").push_back(cloud_ms);
  std::size_t finite = 0, finite_reference = 0;
  table->At("cloud check").push_back(TimeMs([&] { (void)ValidateCloud(cloud, {}, &finite); }));
  table->At("cloud check (scalar reference)").push_back(TimeMs([&] {
    (void)ValidateCloudScalar(cloud, {}, &finite_reference);
  }));
  if (finite != finite_reference) {
    return MakeError(ErrorCode::kInternal, "the cloud checks count different finite points");
  }
  Result<FloorEstimate> fitted = MakeError(ErrorCode::kInternal, "not run");
  table->At("floor: fit every frame").push_back(TimeMs([&] {
    fitted = FitFloor(cloud, options.floor_fit);
  }));
  if (!fitted.ok()) return fitted.error();
  Result<FloorEstimate> tracked = MakeError(ErrorCode::kInternal, "not run");
  const double track_ms = TimeMs([&] { tracked = tracker->Update(cloud); });
  table->At("floor: FloorTracker").push_back(track_ms);
  if (!tracked.ok()) return tracked.error();
  table->refits += tracker->refitted() ? 1 : 0;
  Worst(*tracked, *fitted, &table->worst_floor_angle_deg, &table->worst_floor_height_mm);
  if (truth != nullptr) {
    table->has_truth = true;
    table->fit_truth_deg.push_back(AngleDeg(*fitted, *truth));
    table->fit_truth_mm.push_back(1e3 * std::abs(fitted->height_m - truth->height_m));
    table->tracked_truth_deg.push_back(AngleDeg(*tracked, *truth));
    table->tracked_truth_mm.push_back(1e3 * std::abs(tracked->height_m - truth->height_m));
  }

  ClusterOptions grid = options.clusters;
  grid.method = ClusterOptions::Method::kGrid;
  ClusterOptions pcl = options.clusters;
  pcl.method = ClusterOptions::Method::kPcl;
  Result<std::vector<Cluster>> fast = MakeError(ErrorCode::kInternal, "not run");
  Result<std::vector<Cluster>> reference = MakeError(ErrorCode::kInternal, "not run");
  const double cluster_ms = TimeMs([&] { fast = ExtractClusters(cloud, *tracked, grid); });
  table->At("clustering: grid").push_back(cluster_ms);
  table->At("clustering: PCL (reference)").push_back(TimeMs([&] {
    reference = ExtractClusters(cloud, *tracked, pcl);
  }));
  if (!fast.ok()) return fast.error();
  if (!reference.ok()) return reference.error();
  table->cluster_count += static_cast<int>(fast->size());
  table->cluster_mismatches += SameClusters(*fast, *reference) ? 0 : 1;

  // The clustering's veil filter alone, on the pixels it tests (the height band's), and its
  // reference.
  if (cloud.organised() && options.clusters.veil_max_angle_rad > 0.0) {
    std::vector<Eigen::Vector3f> band;
    std::vector<int> index;
    SelectGroundBand(cloud, ClusterGroundBand(*tracked, options.clusters), &band, &index);
    std::vector<Eigen::Vector3f> band_reference = band;
    std::vector<int> index_reference = index;
    const float cos_veil = static_cast<float>(std::cos(options.clusters.veil_max_angle_rad));
    table->At("veil filter (in clustering)").push_back(TimeMs([&] {
      DropVeilPoints(cloud, cos_veil * cos_veil, &band, &index);
    }));
    table->At("veil filter (reference)").push_back(TimeMs([&] {
      DropVeilPointsScalar(cloud, cos_veil * cos_veil, &band_reference, &index_reference);
    }));
    table->veil_mismatches += index == index_reference ? 0 : 1;
  }

  RangeImage range;
  const double range_ms =
      TimeMs([&] { range = RangeImage::FromCloud(cloud, options.range_image_focal_px); });
  table->At("range image").push_back(range_ms);
  RangeImage range_four;
  table->At("range image (four lanes, reference)").push_back(TimeMs([&] {
    range_four = RangeImage::FromCloudFourLanes(cloud, options.range_image_focal_px);
  }));
  const size_t bins = static_cast<size_t>(range.width()) * range.height();
  if (range_four.width() != range.width() || range_four.height() != range.height() ||
      !std::equal(range.depth_data(), range.depth_data() + bins, range_four.depth_data())) {
    return MakeError(ErrorCode::kInternal, "the range image differs from its four-lane reference");
  }
  table->At("total: cloud + FloorTracker + grid + range image")
      .push_back(cloud_ms + track_ms + cluster_ms + range_ms);

  // Free space around every cluster, as the estimator asks for it: the cluster's columns grown
  // by kFreeGrowCells on every side (about a Nao's reach: the search's origin margin), every
  // layer from the floor to two above the cluster's top.
  constexpr int kFreeGrowCells = 16;
  const double res = options.lattice.resolution_m;
  const Eigen::Isometry3d sensor_from_ground = tracked->ground_from_sensor.inverse();
  double free_ms = 0.0, free_four_ms = 0.0, free_reference_ms = 0.0;
  double voxels_ms = 0.0, two_point_voxels_ms = 0.0;
  bool same = true;
  for (const Cluster& c : *fast) {
    ClusterVoxels voxels;
    voxels_ms += TimeMs([&] { voxels = VoxeliseCluster(c.points, res); });
    // The voxels of two or more points (EstimatorOptions::two_points_a_voxel_within_m).
    ClusterVoxels two_point;
    two_point_voxels_ms += TimeMs([&] { two_point = VoxeliseCluster(c.points, res, true); });
    same = same && two_point.cells.size() <= voxels.cells.size();
    if (voxels.cells.empty()) continue;
    int top = 0;
    for (const Eigen::Vector3i& v : voxels.cells) top = std::max(top, v.z());
    const FreeSpaceRegion region =
        FreeSpaceRegionAround(voxels, std::vector<int>(top + 3, kFreeGrowCells));
    ClusterVoxels free, reference_free;
    free_ms += TimeMs(
        [&] { free = FreeSpaceCells(range, sensor_from_ground, region, res, options.free_space); });
    // The four-height form side by side (what FreeSpaceCells ran before the eight-height forms).
    ClusterVoxels four;
    free_four_ms += TimeMs([&] {
      four = FreeSpaceCellsFourLanes(range, sensor_from_ground, region, res, options.free_space);
    });
    free_reference_ms += TimeMs([&] {
      reference_free =
          FreeSpaceCellsReference(range, sensor_from_ground, region, res, options.free_space);
    });
    same = same && free.cells == reference_free.cells && four.cells == reference_free.cells;
  }
  table->At("cluster voxels, every cluster").push_back(voxels_ms);
  table->At("cluster voxels of two points or more, every cluster").push_back(two_point_voxels_ms);
  table->At("free-space cells, every cluster").push_back(free_ms);
  table->At("free-space cells, four heights a step").push_back(free_four_ms);
  table->At("free-space cells (reference)").push_back(free_reference_ms);
  table->free_mismatches += same ? 0 : 1;
  return Status::Ok();
}

void Print(const Table& t) {
  std::printf("\n%s: %d frames, median / p90 / p99 of thread CPU time in ms\n\n", t.title.c_str(),
              t.frames);
  std::printf("| stage | median | p90 | p99 |\n|---|---|---|---|\n");
  for (const Column& c : t.columns) {
    std::printf("| %s | %.2f | %.2f | %.2f |\n", c.name.c_str(), Median(c.ms),
                Percentile(c.ms, 90.0), Percentile(c.ms, 99.0));
  }
  std::printf(
      "\nFloorTracker refitted on %d of %d frames; tracked floor vs a fresh fit: worst %.2f deg, "
      "%.1f mm. Clusters: %d, grid vs PCL differ on %d frame(s). Free-space cells differ from "
      "the reference's on %d frame(s). The veil filter drops other pixels than its reference "
      "on %d frame(s).\n",
      t.refits, t.frames, t.worst_floor_angle_deg, t.worst_floor_height_mm, t.cluster_count,
      t.cluster_mismatches, t.free_mismatches, t.veil_mismatches);
  if (t.has_truth) {
    std::printf(
        "Against the true mount, median / worst over the frames: fit every frame %.2f / %.2f deg, "
        "%.1f / %.1f mm; FloorTracker %.2f / %.2f deg, %.1f / %.1f mm.\n",
        Median(t.fit_truth_deg), Max(t.fit_truth_deg), Median(t.fit_truth_mm), Max(t.fit_truth_mm),
        Median(t.tracked_truth_deg), Max(t.tracked_truth_deg), Median(t.tracked_truth_mm),
        Max(t.tracked_truth_mm));
  }
}

int Run(int argc, char** argv) {
  int frames = 30;
  int clutter = 4;
  int repeat = 10;
  std::vector<std::string> clouds;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--frames" && has_value) {
      frames = std::atoi(argv[++i]);
    } else if (a == "--clutter" && has_value) {
      clutter = std::atoi(argv[++i]);
    } else if (a == "--repeat" && has_value) {
      repeat = std::atoi(argv[++i]);
    } else if (a == "--cloud" && has_value) {
      clouds.push_back(argv[++i]);
    } else {
      std::printf(
          "usage: stage_bench [--frames N] [--clutter N] [--repeat N] [--cloud FILE]...\n"
          "Times the non-search stages of a frame (cloud, floor, clustering, range image,\n"
          "free-space cells).\n"
          "  --frames N   simulated 640x480 frames (30); 0 runs only the --cloud files\n"
          "  --clutter N  clutter objects per simulated frame (4)\n"
          "  --repeat N   times each --cloud file is replayed as a still sequence (10)\n"
          "  --cloud FILE a real cloud (.pcd/.ply, sensor frame); may be repeated\n");
      return a == "--help" ? 0 : 2;
    }
  }
  if (frames < 0 || clutter < 0 || repeat < 1) {
    std::fprintf(stderr, "stage_bench: --frames and --clutter must be >= 0, --repeat >= 1\n");
    return 2;
  }
  const EstimatorOptions options = DefaultEstimatorOptions();
  std::vector<Table> tables;
  if (frames > 0) {
    Table t;
    t.title = "simulated 640x480 frames, " + std::to_string(clutter) + " clutter objects";
    FloorTracker tracker(FloorTrackerOptions{options.floor_fit});
    for (const FrameSpec& spec : BenchFrameSpecs(frames, clutter)) {
      Result<SimulatedFrame> sim = SimulateFrame(spec);
      if (!sim.ok()) {
        std::fprintf(stderr, "stage_bench: %s\n", sim.error().message.c_str());
        return 1;
      }
      Result<PointCloud> cloud = MakeError(ErrorCode::kInternal, "not run");
      const double cloud_ms =
          TimeMs([&] { cloud = DepthToCloud(sim->depth, spec.intrinsics, options.cloud); });
      if (!cloud.ok()) {
        std::fprintf(stderr, "stage_bench: %s\n", cloud.error().message.c_str());
        return 1;
      }
      const Status st = RunFrame(*cloud, cloud_ms, &sim->sensor_mount, options, &tracker, &t);
      if (!st.ok()) {
        std::fprintf(stderr, "stage_bench: simulated frame: %s\n", st.error().message.c_str());
        return 1;
      }
    }
    tables.push_back(std::move(t));
  }
  for (const std::string& path : clouds) {
    Result<PointCloud> cloud = ReadCloud(path);
    if (!cloud.ok()) {
      std::fprintf(stderr, "stage_bench: %s: %s\n", path.c_str(), cloud.error().message.c_str());
      return 1;
    }
    Table t;
    t.title = path.substr(path.find_last_of('/') + 1) + " (" + std::to_string(cloud->size()) +
              " points" + (cloud->organised() ? ", organised" : "") + ")";
    FloorTracker tracker(FloorTrackerOptions{options.floor_fit});
    for (int r = 0; r < repeat; ++r) {
      const Status st = RunFrame(*cloud, 0.0, nullptr, options, &tracker, &t);
      if (!st.ok()) {
        std::fprintf(stderr, "stage_bench: %s: %s\n", path.c_str(), st.error().message.c_str());
        return 1;
      }
    }
    tables.push_back(std::move(t));
  }
  for (const Table& t : tables) Print(t);
  return 0;
}

}  // namespace
}  // namespace hpose::bench

int main(int argc, char** argv) { return hpose::bench::Run(argc, argv); }
