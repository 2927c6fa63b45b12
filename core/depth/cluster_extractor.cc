// PCL's reference clustering (Method::kPcl) is compiled here from PCL's headers instead of being
// linked from libpcl_segmentation, which loads libpcl_features, libpcl_filters and more: every
// program that clusters would pay for them at start-up (docs/BENCHMARKS.md, "Start-up").
#define PCL_NO_PRECOMPILE

#include "core/depth/cluster_extractor.h"

#include "core/depth/cluster_merge.h"
#include "core/depth/occluded_piece_merge.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include "core/depth/cloud_validation.h"
#include "core/depth/floor_plane.h"
#include "core/depth/grid_euclidean_clusters.h"
#include "core/depth/ground_band.h"
#include "core/depth/veil_filter.h"
#include "core/depth/voxel_downsample.h"

namespace hpose {
namespace {

using PclCloud = pcl::PointCloud<pcl::PointXYZ>;

}  // namespace

Status ValidateClusterOptions(const ClusterOptions& o) {
  auto bad = [](const std::string& what) {
    return Status(MakeError(ErrorCode::kInvalidArgument, "cluster options: " + what));
  };
  const double values[] = {o.min_height_above_floor_m,
                           o.max_height_above_floor_m,
                           o.max_range_m,
                           o.downsample_leaf_m,
                           o.tolerance_m,
                           o.min_height_m,
                           o.max_height_m,
                           o.max_footprint_m};
  for (const double v : values) {
    if (!std::isfinite(v)) return bad("all lengths must be finite");
  }
  if (!(o.max_height_above_floor_m > o.min_height_above_floor_m)) {
    return bad("max_height_above_floor_m must exceed min_height_above_floor_m");
  }
  if (!std::isfinite(o.floor_noise_sigmas) || o.floor_noise_sigmas < 0.0) {
    return bad("floor_noise_sigmas must be finite and >= 0");
  }
  if (!(o.max_range_m > 0.0)) return bad("max_range_m must be > 0");
  if (o.downsample_leaf_m < 0.0) return bad("downsample_leaf_m must be >= 0");
  if (!(o.tolerance_m > 0.0)) return bad("tolerance_m must be > 0");
  if (o.min_points < 1) return bad("min_points must be >= 1");
  if (o.max_points < o.min_points) return bad("max_points must be >= min_points");
  if (o.max_height_m < o.min_height_m) return bad("max_height_m must be >= min_height_m");
  if (!(o.max_footprint_m > 0.0)) return bad("max_footprint_m must be > 0");
  if (!std::isfinite(o.veil_max_angle_rad) || o.veil_max_angle_rad < 0.0 ||
      o.veil_max_angle_rad >= M_PI / 2.0) {
    return bad("veil_max_angle_rad must be in [0, pi/2)");
  }
  if (!std::isfinite(o.merge_hidden_max_depth_gap_m) || o.merge_hidden_max_depth_gap_m < 0.0 ||
      !std::isfinite(o.merge_hidden_max_fraction) || o.merge_hidden_max_fraction < 0.0 ||
      !std::isfinite(o.merge_hidden_min_lift_m) || o.merge_hidden_min_lift_m < 0.0) {
    return bad(
        "merge_hidden_max_depth_gap_m, merge_hidden_max_fraction and merge_hidden_min_lift_m must "
        "be finite and >= 0");
  }
  if (!std::isfinite(o.split_min_top_separation_m) || o.split_min_top_separation_m < 0.0) {
    return bad("split_min_top_separation_m must be finite and >= 0");
  }
  return Status::Ok();
}

namespace {

// The reference path: pcl::EuclideanClusterExtraction (kd-tree radius searches) on `points`;
// labels per point, clusters numbered in PCL's order.
std::vector<int> PclEuclideanClusterLabels(const std::vector<Eigen::Vector3f>& points,
                                           double tolerance_m, int* cluster_count) {
  auto pcl_cloud = std::make_shared<PclCloud>();
  pcl_cloud->resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    (*pcl_cloud)[i].x = points[i].x();
    (*pcl_cloud)[i].y = points[i].y();
    (*pcl_cloud)[i].z = points[i].z();
  }
  // What pcl::EuclideanClusterExtraction::extract does with a kd-tree given, called directly: its
  // class also instantiates PCL's organized-cloud search, which doubled this file's compile time.
  auto tree = std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>(/*sorted=*/false);
  tree->setInputCloud(pcl_cloud);
  std::vector<pcl::PointIndices> found;
  // Sizes are checked on the fine points: no limits here.
  pcl::extractEuclideanClusters(*pcl_cloud, tree, static_cast<float>(tolerance_m), found, 1,
                                std::numeric_limits<int>::max());
  std::sort(found.rbegin(), found.rend(), pcl::comparePointClusters);  // largest first.
  std::vector<int> labels(points.size(), -1);
  for (size_t c = 0; c < found.size(); ++c) {
    for (const int i : found[c].indices) labels[i] = static_cast<int>(c);
  }
  *cluster_count = static_cast<int>(found.size());
  return labels;
}

// Minimum distance (m) from the range and height limits for a cluster to count as complete.
constexpr double kCutMarginM = 0.1;
// Height-map cell (m) used to find the tops of a cluster.
constexpr double kTopCellM = 0.05;
// A top must reach this fraction of the cluster's highest point.
constexpr double kTopMinRelativeHeight = 0.5;
// Two tops are distinct objects only if the height map between them dips by this fraction of
// the lower one (people's shoulders between their heads).
constexpr double kMinValleyFraction = 0.1;
// Every part of a split must hold at least this fraction of the cluster's points: a raised arm
// or a hand is never split off a body.
constexpr double kSplitMinFraction = 0.2;

// Splits `cluster` (points only) into parts around its tops: cells of a floor height map that are
// the highest within split_min_top_separation_m and reach kTopMinRelativeHeight of the cluster's
// height. Each point goes to the horizontally nearest top. Tops whose part would be too small
// (kSplitMinFraction, min_points) are dropped, smallest first. Appends the parts to `out`.
void SplitByTops(Cluster cluster, const ClusterOptions& options, std::vector<Cluster>* out) {
  const std::vector<Eigen::Vector3f>& points = cluster.points;
  if (points.size() < 2 * static_cast<size_t>(options.min_points)) {
    out->push_back(std::move(cluster));
    return;
  }
  Eigen::Vector3f lo = points.front(), hi = points.front();
  for (const Eigen::Vector3f& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double separation = options.split_min_top_separation_m;
  if (std::max(hi.x() - lo.x(), hi.y() - lo.y()) < separation) {
    out->push_back(std::move(cluster));
    return;
  }
  const float cell = static_cast<float>(kTopCellM);
  const int nx = static_cast<int>((hi.x() - lo.x()) / cell) + 1;
  const int ny = static_cast<int>((hi.y() - lo.y()) / cell) + 1;
  const float none = -std::numeric_limits<float>::infinity();
  std::vector<float> top_z(static_cast<size_t>(nx) * ny, none);
  std::vector<Eigen::Vector2f> top_xy(top_z.size());
  for (const Eigen::Vector3f& p : points) {
    const int ix = std::min(nx - 1, static_cast<int>((p.x() - lo.x()) / cell));
    const int iy = std::min(ny - 1, static_cast<int>((p.y() - lo.y()) / cell));
    const size_t c = static_cast<size_t>(iy) * nx + ix;
    if (p.z() > top_z[c]) {
      top_z[c] = p.z();
      top_xy[c] = p.head<2>();
    }
  }
  // Local maxima over a disc of radius `separation`; ties broken by cell index.
  const int reach = static_cast<int>(std::ceil(separation / cell));
  const float min_top = static_cast<float>(kTopMinRelativeHeight) * hi.z();
  std::vector<size_t> candidates;
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      const size_t c = static_cast<size_t>(iy) * nx + ix;
      const float z = top_z[c];
      if (z < min_top) continue;
      bool is_max = true;
      for (int dy = -reach; dy <= reach && is_max; ++dy) {
        for (int dx = -reach; dx <= reach; ++dx) {
          const int jx = ix + dx, jy = iy + dy;
          if ((dx == 0 && dy == 0) || jx < 0 || jy < 0 || jx >= nx || jy >= ny) continue;
          if ((dx * dx + dy * dy) * cell * cell > separation * separation) continue;
          const size_t d = static_cast<size_t>(jy) * nx + jx;
          if (top_z[d] > z || (top_z[d] == z && d < c)) {
            is_max = false;
            break;
          }
        }
      }
      if (is_max) candidates.push_back(c);
    }
  }
  // Keep a top only if the height map dips between it and every higher kept top (two people)
  // rather than staying level (the long flat top of a bench or a wall).
  std::sort(candidates.begin(), candidates.end(),
            [&](size_t a, size_t b) { return top_z[a] > top_z[b]; });
  std::vector<size_t> kept;
  for (const size_t c : candidates) {
    bool distinct = true;
    for (const size_t k : kept) {
      const float lower = std::min(top_z[c], top_z[k]);
      const int cx = static_cast<int>(c % nx), cy = static_cast<int>(c / nx);
      const int kx = static_cast<int>(k % nx), ky = static_cast<int>(k / nx);
      const int steps = std::max(std::abs(cx - kx), std::abs(cy - ky));
      float valley = lower;
      for (int i = 1; i < steps; ++i) {
        const int x = cx + (kx - cx) * i / steps;
        const int y = cy + (ky - cy) * i / steps;
        valley = std::min(valley, top_z[static_cast<size_t>(y) * nx + x]);  // empty: -inf.
      }
      if (lower - valley < static_cast<float>(kMinValleyFraction) * lower) {
        distinct = false;
        break;
      }
    }
    if (distinct) kept.push_back(c);
  }
  std::vector<Eigen::Vector2f> tops;
  for (const size_t c : kept) tops.push_back(top_xy[c]);
  const int min_part =
      std::max(options.min_points, static_cast<int>(kSplitMinFraction * points.size()));
  std::vector<int> owner(points.size());
  while (tops.size() >= 2) {
    std::vector<int> count(tops.size(), 0);
    for (size_t i = 0; i < points.size(); ++i) {
      int best = 0;
      float best_d2 = std::numeric_limits<float>::max();
      for (size_t t = 0; t < tops.size(); ++t) {
        const float d2 = (points[i].head<2>() - tops[t]).squaredNorm();
        if (d2 < best_d2) {
          best_d2 = d2;
          best = static_cast<int>(t);
        }
      }
      owner[i] = best;
      ++count[best];
    }
    const auto smallest = std::min_element(count.begin(), count.end());
    if (*smallest >= min_part) {
      std::vector<Cluster> parts(tops.size());
      for (size_t t = 0; t < tops.size(); ++t) parts[t].points.reserve(count[t]);
      for (size_t i = 0; i < points.size(); ++i) parts[owner[i]].points.push_back(points[i]);
      for (Cluster& part : parts) out->push_back(std::move(part));
      return;
    }
    tops.erase(tops.begin() + (smallest - count.begin()));
  }
  out->push_back(std::move(cluster));
}

// Drops the band's points lower than `sigmas` standard deviations of the vertical part of
// their depth noise (ClusterOptions::floor_noise_sigmas), keeping `index` in step when given. A
// point at depth z seen from a sensor h above the floor moves along its ray by sigma_z =
// k z^2, of which k z^2 (h - height) / z upwards; for points near the floor that is k z h. Does
// nothing (and reads no point) when no point the band can hold reaches slab.z_min this way.
void DropFloorNoise(const GroundBand& slab, double sigmas, std::vector<Eigen::Vector3f>* band,
                    std::vector<int>* index) {
  const float sensor_height = slab.translation.z();
  const float per_depth =
      static_cast<float>(sigmas) * DepthNoiseInHeight(1.0f, std::max(sensor_height, 0.0f));
  const float rise = std::max(sensor_height - slab.z_min, slab.z_max - sensor_height);
  const float deepest = std::sqrt(slab.range2 + rise * rise);
  if (!(per_depth * deepest > slab.z_min)) return;
  // Depth along the optical axis: the sensor frame's z of g, (R^T (g - t)).z.
  const Eigen::Vector3f axis = slab.rotation.col(2);
  size_t kept = 0;
  for (size_t i = 0; i < band->size(); ++i) {
    const Eigen::Vector3f& g = (*band)[i];
    if (g.z() < per_depth * axis.dot(g - slab.translation)) continue;
    (*band)[kept] = g;
    if (index != nullptr) (*index)[kept] = (*index)[i];
    ++kept;
  }
  band->resize(kept);
  if (index != nullptr) index->resize(kept);
}

}  // namespace

GroundBand ClusterGroundBand(const FloorEstimate& floor, const ClusterOptions& options) {
  GroundBand slab;
  slab.rotation = floor.ground_from_sensor.linear().cast<float>();
  slab.translation = floor.ground_from_sensor.translation().cast<float>();
  slab.z_min = static_cast<float>(options.min_height_above_floor_m);
  slab.z_max = static_cast<float>(options.max_height_above_floor_m);
  slab.range2 = static_cast<float>(options.max_range_m * options.max_range_m);
  return slab;
}

Result<std::vector<Cluster>> ExtractClusters(const PointCloud& cloud_sensor,
                                             const FloorEstimate& floor,
                                             const ClusterOptions& options) {
  const Status valid = ValidateClusterOptions(options);
  if (!valid.ok()) return valid.error();
  const Status valid_floor = ValidateFloor(floor);
  if (!valid_floor.ok()) return valid_floor.error();

  // 1. Ground frame, height band and range.
  const GroundBand slab = ClusterGroundBand(floor, options);
  const bool drop_veils = cloud_sensor.organised() && options.veil_max_angle_rad > 0.0;
  std::vector<Eigen::Vector3f> band;
  std::vector<int> band_index;
  SelectGroundBand(cloud_sensor, slab, &band, drop_veils ? &band_index : nullptr);
  DropFloorNoise(slab, options.floor_noise_sigmas, &band, drop_veils ? &band_index : nullptr);
  if (drop_veils) {
    const float cos_veil = static_cast<float>(std::cos(options.veil_max_angle_rad));
    DropVeilPoints(cloud_sensor, cos_veil * cos_veil, &band, &band_index);
  }
  std::vector<Cluster> clusters;
  if (band.empty()) return clusters;

  // 2. Voxel grid: the output resolution of the clusters. It also evens out the near/far
  // density of a depth camera.
  std::vector<Eigen::Vector3f> fine;
  if (options.downsample_leaf_m > 0.0) {
    VoxelDownsample(band, static_cast<float>(options.downsample_leaf_m), &fine);
  } else {
    fine.swap(band);
  }
  if (static_cast<int>(fine.size()) < options.min_points) return clusters;

  // 3. Euclidean clusters (bucket grid, or PCL's kd-tree radius searches: the same clusters) on
  // a coarser grid of half the tolerance: neighbouring cells of one surface stay within the
  // tolerance of each other, and the neighbour tests touch a handful of points instead of dozens (a
  // 640x480 frame of people would otherwise spend ~150 ms here). Every fine point takes the label
  // of its coarse cell.
  const double coarse_leaf = std::max(options.downsample_leaf_m, 0.5 * options.tolerance_m);
  std::vector<Eigen::Vector3f> coarse;
  std::vector<int> coarse_of_fine;
  VoxelDownsample(fine, static_cast<float>(coarse_leaf), &coarse, &coarse_of_fine);
  int cluster_count = 0;
  std::vector<int> label_of_coarse;
  if (options.method == ClusterOptions::Method::kGrid) {
    label_of_coarse = GridEuclideanClusterLabels(coarse, options.tolerance_m, &cluster_count);
    // PCL orders its clusters by size, largest first, with std::sort (not stable): the same
    // sort over the same sizes in the same initial order (lowest index first) gives the same
    // permutation, so equal-sized clusters come out in PCL's order too.
    std::vector<std::pair<int, int>> size_label(cluster_count);  // (coarse points, label).
    for (int c = 0; c < cluster_count; ++c) size_label[c] = {0, c};
    for (const int label : label_of_coarse) ++size_label[label].first;
    std::sort(size_label.rbegin(), size_label.rend(),
              [](const std::pair<int, int>& a, const std::pair<int, int>& b) {
                return a.first < b.first;
              });
    std::vector<int> rank(cluster_count);
    for (int r = 0; r < cluster_count; ++r) rank[size_label[r].second] = r;
    for (int& label : label_of_coarse) label = rank[label];
  } else {
    label_of_coarse = PclEuclideanClusterLabels(coarse, options.tolerance_m, &cluster_count);
  }
  std::vector<Cluster> raw(cluster_count);
  std::vector<int> fine_count(cluster_count, 0);
  for (const int coarse_index : coarse_of_fine) {
    const int label = label_of_coarse[coarse_index];
    if (label >= 0) ++fine_count[label];
  }
  for (int c = 0; c < cluster_count; ++c) raw[c].points.reserve(fine_count[c]);
  for (size_t i = 0; i < fine.size(); ++i) {
    const int label = label_of_coarse[coarse_of_fine[i]];
    if (label >= 0) raw[label].points.push_back(fine[i]);
  }

  // 3b. One object split by a depth edge inside it (an arm in front of a torso, its mixed pixels
  // removed by the veil filter) leaves pieces stacked over one footprint: merge them.
  MergePiecesAlongSight(options.merge_min_bearing_overlap, options.merge_max_range_gap_m, &raw);
  // 3c. A limb behind the body's silhouette (its joint hidden): merge it with the body.
  OccludedPieceOptions hidden;
  hidden.max_depth_gap_m = options.merge_hidden_max_depth_gap_m;
  hidden.max_point_fraction = options.merge_hidden_max_fraction;
  hidden.min_lift_m = options.merge_hidden_min_lift_m;
  hidden.leaf_m = options.downsample_leaf_m;
  MergeOccludedPieces(floor.ground_from_sensor.translation().cast<float>(), hidden, &raw);

  // 4. Objects in contact (people side by side, a robot touching a box) share one Euclidean
  // cluster; split those with several well separated tops.
  if (options.split_min_top_separation_m > 0.0) {
    std::vector<Cluster> split;
    split.reserve(raw.size());
    for (Cluster& cluster : raw) SplitByTops(std::move(cluster), options, &split);
    raw.swap(split);
  }

  // 5. Size, height and footprint filters; centroid and bounds.
  for (Cluster& cluster : raw) {
    const int count = static_cast<int>(cluster.points.size());
    if (count < options.min_points || count > options.max_points) continue;
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
    Eigen::Vector3f hi = -lo;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3f& p : cluster.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
      sum += p.cast<double>();
    }
    const double top = hi.z();
    const double footprint = std::max(hi.x() - lo.x(), hi.y() - lo.y());
    if (top < options.min_height_m || top > options.max_height_m) continue;
    if (footprint > options.max_footprint_m) continue;
    // Clusters cut by the range or the upper band limit are pieces of walls and furniture
    // beyond the working volume (or objects only partly inside it): incomplete shapes. The
    // margin allows for the sparse, noisy points near the range limit.
    const double margin = std::max(2.0 * options.tolerance_m, kCutMarginM);
    if (top > options.max_height_above_floor_m - margin) continue;
    float max_range2 = 0.0f;
    for (const Eigen::Vector3f& p : cluster.points) {
      max_range2 = std::max(max_range2, p.head<2>().squaredNorm());
    }
    const double edge = std::max(0.0, options.max_range_m - margin);
    if (max_range2 > edge * edge) continue;
    cluster.min = lo;
    cluster.max = hi;
    cluster.centroid = (sum / static_cast<double>(count)).cast<float>();
    clusters.push_back(std::move(cluster));
  }
  // Largest first; stable so equal sizes keep PCL's order.
  std::stable_sort(clusters.begin(), clusters.end(), [](const Cluster& a, const Cluster& b) {
    return a.points.size() > b.points.size();
  });
  return clusters;
}

}  // namespace hpose
