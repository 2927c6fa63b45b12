#include "core/templates/capture_views.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include <Eigen/Eigenvalues>

#include "core/common/pose2d.h"

namespace hpose {
namespace {

std::string Mm(double m) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.0f mm", m * 1000.0);
  return buf;
}

std::string Deg(double rad) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f deg", rad * 180.0 / kPi);
  return buf;
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Plane with a unit normal pointing to the sensor side (d > 0).
Eigen::Vector4d Normalised(const Eigen::Vector4d& plane) {
  Eigen::Vector4d p = plane / plane.head<3>().norm();
  return p[3] < 0.0 ? Eigen::Vector4d(-p) : p;
}

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// Refits a floor plane (sensor frame, unit normal, d > 0) by weighted least squares over the
// points within a tight band of it: max(min_band, 3 sigma(z)) with the Kinect v1 noise
// sigma(z) = 1.425e-3 z^2 (SPEC 5), weights 1 / sigma^2. A turntable top a couple of
// centimetres above the floor, near the sensor where the band is narrow, no longer pulls the
// plane (FitFloor's wider refinement band lets it tilt the floor by a few tenths of a degree).
Eigen::Vector4d RefinePlane(const PointCloud& cloud, Eigen::Vector4d plane, double min_band) {
  for (int round = 0; round < 3; ++round) {
    Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
    double weight = 0.0;
    for (const Eigen::Vector3f& pf : cloud.points) {
      if (!pf.allFinite()) continue;
      const Eigen::Vector3d p = pf.cast<double>();
      const double sigma = 1.425e-3 * p.z() * p.z() + 1e-3;
      const double dist = plane.head<3>().dot(p) + plane[3];
      if (std::abs(dist) > std::max(min_band, 3.0 * sigma)) continue;
      const Eigen::Vector4d h(p.x(), p.y(), p.z(), 1.0);
      const double w = 1.0 / (sigma * sigma);
      a += w * h * h.transpose();
      weight += w;
    }
    if (weight <= 0.0) break;
    // The plane minimising sum w (n.p + d)^2 with |n| = 1: centre, then the smallest
    // eigenvector of the weighted scatter.
    const Eigen::Vector3d centre = a.block<3, 1>(0, 3) / a(3, 3);
    const Eigen::Matrix3d scatter = a.block<3, 3>(0, 0) / a(3, 3) - centre * centre.transpose();
    Eigen::Vector3d n =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
    if (n.dot(plane.head<3>()) < 0.0) n = -n;
    plane << n, -n.dot(centre);
  }
  return Normalised(plane);
}

// A view being processed: its fitted floor, or why it failed.
struct Pending {
  const CaptureView* capture = nullptr;
  std::optional<FloorEstimate> floor;
  std::string failure;
  std::vector<Cluster> clusters;
  int pick = -1;
};

}  // namespace

Result<CaptureViews> ExtractRobotViews(const std::vector<CaptureView>& captures,
                                       const CaptureViewOptions& options,
                                       const ProgressFn& progress) {
  if (captures.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, "no captures given");
  }
  if (!(options.table_height_m >= 0.0) || !(options.cut_above_table_m >= 0.0)) {
    return MakeError(ErrorCode::kInvalidArgument, "table height and cut above it must be >= 0 m");
  }
  auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };

  // 1. The floor of every view.
  std::vector<Pending> pending(captures.size());
  for (size_t i = 0; i < captures.size(); ++i) {
    pending[i].capture = &captures[i];
    Result<FloorEstimate> floor = FitFloor(captures[i].cloud_sensor, options.floor);
    if (floor.ok()) {
      pending[i].floor = FloorEstimate::FromPlane(
          RefinePlane(captures[i].cloud_sensor, floor->plane_sensor, options.floor_band_m));
      pending[i].floor->inliers = floor->inliers;
      pending[i].floor->fitted = true;
    } else {
      pending[i].failure = floor.error().message;
    }
  }

  // 2. One fixed sensor: a common floor, the median plane of the views that found one.
  std::vector<double> comps[4];
  for (const Pending& p : pending) {
    if (!p.floor) continue;
    const Eigen::Vector4d plane = Normalised(p.floor->plane_sensor);
    for (int k = 0; k < 4; ++k) comps[k].push_back(plane[k]);
  }
  auto fail_or_drop = [&](Pending* p, std::string reason) -> std::optional<Error> {
    p->failure = std::move(reason);
    if (options.drop_bad_views) return std::nullopt;
    return MakeError(ErrorCode::kFailedPrecondition,
                     "capture " + p->capture->name + ": " + p->failure);
  };
  for (Pending& p : pending) {
    if (!p.floor && !options.drop_bad_views) {
      return MakeError(ErrorCode::kFailedPrecondition,
                       "capture " + p.capture->name + ": " + p.failure);
    }
  }
  if (comps[0].empty()) {
    return MakeError(ErrorCode::kFailedPrecondition, "no floor found in any capture");
  }
  Eigen::Vector4d median_plane;
  for (int k = 0; k < 4; ++k) median_plane[k] = Median(comps[k]);
  median_plane = Normalised(median_plane);
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  int agreeing = 0;
  for (Pending& p : pending) {
    if (!p.floor) continue;
    const Eigen::Vector4d plane = Normalised(p.floor->plane_sensor);
    const double dh = plane[3] - median_plane[3];
    const double da = AngleBetween(plane.head<3>(), median_plane.head<3>());
    if (std::abs(dh) > options.max_floor_height_difference_m ||
        da > options.max_floor_angle_difference_rad) {
      if (auto e = fail_or_drop(&p, "its floor differs from the other captures' by " + Mm(dh) +
                                        " in height and " + Deg(da) +
                                        " in tilt: the sensor moved or this is another scene")) {
        return *e;
      }
      p.floor.reset();
      continue;
    }
    sum += plane;
    ++agreeing;
  }
  CaptureViews out;
  out.floor = FloorEstimate::FromPlane(sum / agreeing);
  out.floor.fitted = true;

  // 3. Clusters standing on the table top, and each view's robot candidate. Each view is cut on
  // its own floor, which agrees with the common one: a sensor nudged by a degree between
  // captures would otherwise lift part of that view's table top or floor above the cut.
  ClusterOptions cluster_options = options.clusters;
  cluster_options.min_height_above_floor_m = options.table_height_m + options.cut_above_table_m;
  const double min_top = options.table_height_m + options.min_robot_height_m;
  for (Pending& p : pending) {
    if (!p.floor) continue;
    Result<std::vector<Cluster>> clusters =
        ExtractClusters(p.capture->cloud_sensor, *p.floor, cluster_options);
    if (!clusters.ok()) return clusters.error();
    double best_bearing = 1e9;
    for (size_t c = 0; c < clusters->size(); ++c) {
      const Cluster& cl = (*clusters)[c];
      if (cl.max.z() < min_top) continue;
      const double bearing = std::abs(std::atan2(cl.centroid.y(), cl.centroid.x()));
      if (bearing < best_bearing - 1e-6) {
        best_bearing = bearing;
        p.pick = static_cast<int>(c);
      }
    }
    p.clusters = std::move(*clusters);
    if (p.pick < 0) {
      if (auto e = fail_or_drop(&p, "no object at least " + Mm(options.min_robot_height_m) +
                                        " tall stands on the table top (" +
                                        std::to_string(p.clusters.size()) + " clusters seen)")) {
        return *e;
      }
    }
  }

  // 4. The robot stands at about the same place in every view: re-assign outliers.
  std::vector<double> xs, ys;
  for (const Pending& p : pending) {
    if (p.pick < 0 || !p.floor) continue;
    xs.push_back(p.clusters[p.pick].centroid.x());
    ys.push_back(p.clusters[p.pick].centroid.y());
  }
  if (!xs.empty()) {
    const Eigen::Vector2f median(static_cast<float>(Median(xs)), static_cast<float>(Median(ys)));
    for (Pending& p : pending) {
      if (p.pick < 0 || !p.floor) continue;
      double best = 1e9;
      for (size_t c = 0; c < p.clusters.size(); ++c) {
        const Cluster& cl = p.clusters[c];
        if (cl.max.z() < min_top) continue;
        const double d = (cl.centroid.head<2>() - median).norm();
        if (d < best) {
          best = d;
          p.pick = static_cast<int>(c);
        }
      }
      if (best > options.max_robot_shift_m) {
        if (auto e = fail_or_drop(
                &p, "no robot-sized object within " + Mm(options.max_robot_shift_m) +
                        " of where the other captures see it (nearest " + Mm(best) + " away)")) {
          return *e;
        }
        p.pick = -1;
      }
    }
  }

  // 5. The kept views, z measured from the table top.
  for (Pending& p : pending) {
    if (p.pick < 0 || !p.floor) {
      out.dropped.push_back({p.capture->name, p.failure});
      say(p.capture->name + ": dropped: " + p.failure);
      continue;
    }
    const Cluster& cl = p.clusters[p.pick];
    RobotView view;
    view.name = p.capture->name;
    view.capture_index = static_cast<int>(p.capture - captures.data());
    view.own_floor = *p.floor;
    const Eigen::Vector4d own = Normalised(p.floor->plane_sensor);
    view.floor_height_difference_m = own[3] - out.floor.plane_sensor[3];
    view.floor_angle_difference_rad = AngleBetween(own.head<3>(), out.floor.plane_sensor.head<3>());
    view.clusters_seen = static_cast<int>(p.clusters.size());
    const float lift = static_cast<float>(options.table_height_m);
    view.points.reserve(cl.points.size());
    for (const Eigen::Vector3f& q : cl.points) view.points.emplace_back(q.x(), q.y(), q.z() - lift);
    view.centroid = cl.centroid - Eigen::Vector3f(0.0f, 0.0f, lift);
    char line[256];
    std::snprintf(line, sizeof(line),
                  "%s: floor %.0f mm below the sensor, robot %zu points at x %.0f y %.0f mm, "
                  "%.0f mm tall (%d clusters)",
                  view.name.c_str(), p.floor->height_m * 1000.0, view.points.size(),
                  view.centroid.x() * 1000.0, view.centroid.y() * 1000.0,
                  (cl.max.z() - lift) * 1000.0, view.clusters_seen);
    say(line);
    out.views.push_back(std::move(view));
  }
  if (out.views.size() < 2) {
    return MakeError(ErrorCode::kFailedPrecondition,
                     "only " + std::to_string(out.views.size()) + " of " +
                         std::to_string(captures.size()) +
                         " captures show the robot; at least 2 are needed");
  }
  return out;
}

}  // namespace hpose
