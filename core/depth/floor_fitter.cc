#include "core/depth/floor_fitter.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/depth/floor_plane.h"
#include "core/depth/local_plane_ransac.h"
#include "core/depth/voxel_downsample.h"
#include "core/depth/voxel_key_set.h"

namespace hpose {
namespace {

// At most this many near-horizontal planes are extracted one after another (floor, table tops,
// box tops, seats ...) before the floor is chosen among them.
constexpr int kMaxCandidatePlanes = 6;
// A candidate with more points beneath it than this fraction of its inliers (or of all points)
// is not the floor.
constexpr double kMaxBelowFraction = 0.1;
constexpr double kMaxBelowFractionOfAll = 0.01;
// Fewer (downsampled) points than this cannot give a trustworthy floor.
constexpr int kMinPoints = 50;
// No depth sensor's optical centre sits closer than this to the floor below it (its own housing
// is taller), and a floor that close would be seen only at grazing angles, where structured light
// returns nothing. Planes passing nearer run through objects beside the sensor.
constexpr double kMinSensorHeightM = 0.05;
// Two candidate planes within this angle are "parallel": the higher one is a table or box top.
constexpr double kParallelRad = 15.0 * M_PI / 180.0;
// The steepest floor SteepFloorNote points out (1.5 rad, 85.9 degrees: the most the daemon's and
// the command line's max tilt accept). Steeper planes are walls as often as floors.
constexpr double kMaxSteepTiltRad = 1.5;
// A floor means a sensor rolled (about its optical axis) at most this much: planes that would
// mean more are walls beside it (see FitFloor).
constexpr double kMaxFloorRollRad = 45.0 * M_PI / 180.0;
// Larger inputs are thinned to about this many points before the voxel grid.
constexpr size_t kMaxInputPoints = 20000;
// RANSAC hypotheses are scored on at most this many points per round.
constexpr int kMaxRansacPoints = 2000;
// Radius (m) within which the points of one RANSAC hypothesis are drawn.
constexpr double kSampleRadiusM = 0.4;
// Least-squares refinement rounds (re-selecting inliers with the refined plane each time).
constexpr int kRefineRounds = 3;

// The feet of objects (FloorFitterOptions::skip_object_feet): a point with a point in the
// kFootCellM cell kFootProbeLowM, or that and kFootCellM more, above it, both raised by
// kFootProbeNoiseSigmas standard deviations of the floor's depth noise in height there. The
// cells are coarse so that a probe finds a surface that curves away (a ball's) or stands back
// (a leg above a foot); 9 cm up, no point of the cell lies within 3.8 cm of the floor, and the
// noise's share keeps the floor's own speckle out of it (else the points the noise put low
// would find it more often, and the fit would rise).
constexpr float kFootCellM = 0.06f;
constexpr float kFootProbeLowM = 0.09f;
constexpr float kFootProbeNoiseSigmas = 6.0f;

struct Candidate {
  Eigen::Vector4d plane;  // unit normal towards the sensor, d > 0.
  int inliers = 0;
};

std::string Percent(double fraction) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f%%", 100.0 * fraction);
  return text;
}

std::string Degrees(double rad) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.0f deg", rad * 180.0 / M_PI);
  return text;
}

// The angle (rad) between a plane's normal, turned towards the sensor, and the sensor's up
// guess: 0 for a floor seen by a level sensor, above pi/2 when the sensor is below the plane.
double TiltFromUp(const Eigen::Vector4d& plane, const Eigen::Vector3d& up) {
  return std::acos(std::clamp(plane.head<3>().dot(up), -1.0, 1.0));
}

// Why no floor was found when the sensor may look down more steeply than max_tilt_rad allows (a
// mount high up, near the ceiling): the largest plane among all the points whatever its tilt, if
// the sensor stands above it, it is tilted past the limit and it holds at least min_support of
// them, described for the error ("the largest plane, 2.50 m below the sensor, is tilted 75 deg
// ..."); "" otherwise.
std::string SteepFloorNote(const std::vector<Eigen::Vector3f>& points, const FloorFitterOptions& o,
                           int min_support, const Eigen::Vector3d& up) {
  if (o.max_tilt_rad >= kMaxSteepTiltRad) return "";  // no steeper floor to point out.
  LocalPlaneRansacOptions ransac;
  ransac.distance_threshold_m = o.distance_threshold_m;
  ransac.sample_radius_m = kSampleRadiusM;
  ransac.axis = up.cast<float>();
  ransac.max_axis_angle_rad = 0.5 * M_PI;  // every plane.
  ransac.max_iterations = o.max_iterations;
  ransac.seed = static_cast<unsigned>(o.random_seed);
  const int step = (static_cast<int>(points.size()) + kMaxRansacPoints - 1) / kMaxRansacPoints;
  std::vector<Eigen::Vector3f> subset;
  for (size_t i = 0; i < points.size(); i += static_cast<size_t>(step)) subset.push_back(points[i]);
  const LocalPlaneRansacResult fit = FitPlaneLocalRansac(subset, ransac);
  if (!fit.found || fit.inliers * step < min_support) return "";
  Eigen::Vector4d plane = fit.plane.cast<double>();
  const double norm = plane.head<3>().norm();
  if (!(norm > 0.0)) return "";
  plane /= norm;
  if (plane[3] < 0.0) plane = -plane;  // the normal towards the sensor.
  const double tilt = TiltFromUp(plane, up);
  if (plane[3] < kMinSensorHeightM || tilt <= o.max_tilt_rad || tilt > kMaxSteepTiltRad) return "";
  char text[256];
  std::snprintf(text, sizeof(text),
                "; the largest plane in view (%s of the points, %.2f m below the sensor) is "
                "tilted %.0f deg: a sensor looking down that steeply needs a larger "
                "max_tilt_rad, or a fixed floor",
                Percent(static_cast<double>(fit.inliers) / subset.size()).c_str(), plane[3],
                tilt * 180.0 / M_PI);
  return text;
}

// The roll about the optical axis (rad, absolute) a floor on `plane` (normal towards the
// sensor) means.
double FloorRoll(const Eigen::Vector4d& plane) {
  return std::abs(std::atan2(-plane[0], -plane[1]));
}

// `height_m`: the sensor's above the plane whose normal (towards the sensor) is `up`.
bool IsObjectFoot(const Eigen::Vector3f& p, const Eigen::Vector3f& up, float height_m,
                  const VoxelKeySet& cells) {
  const float low =
      kFootProbeLowM + kFootProbeNoiseSigmas * DepthNoiseInHeight(std::abs(p.z()), height_m);
  return cells.Contains(p + low * up) || cells.Contains(p + (low + kFootCellM) * up);
}

// Leaves out of `indices` the points of `points` that are the feet of objects standing on
// `plane` (IsObjectFoot); nothing when `cells` is empty.
void DropObjectFeet(const std::vector<Eigen::Vector3f>& points, const VoxelKeySet& cells,
                    const Eigen::Vector4d& plane, std::vector<int>* indices) {
  if (cells.size() == 0) return;
  const Eigen::Vector3f up = plane.head<3>().cast<float>();
  const float height = static_cast<float>(plane[3]);
  size_t kept = 0;
  for (const int i : *indices) {
    if (!IsObjectFoot(points[i], up, height, cells)) (*indices)[kept++] = i;
  }
  indices->resize(kept);
}

}  // namespace

Status ValidateFloorFitterOptions(const FloorFitterOptions& o) {
  auto bad = [](const std::string& what) {
    return Status(MakeError(ErrorCode::kInvalidArgument, "floor fitter options: " + what));
  };
  if (!(o.distance_threshold_m > 0.0) || !std::isfinite(o.distance_threshold_m)) {
    return bad("distance_threshold_m must be finite and > 0");
  }
  if (o.max_iterations < 1) return bad("max_iterations must be >= 1");
  if (!(o.max_tilt_rad > 0.0) || !(o.max_tilt_rad < M_PI / 2.0)) {
    return bad("max_tilt_rad must be in (0, pi/2)");
  }
  if (!(o.min_inlier_fraction >= 0.0) || !(o.min_inlier_fraction <= 1.0)) {
    return bad("min_inlier_fraction must be in [0, 1]");
  }
  if (!(o.downsample_leaf_m >= 0.0) || !std::isfinite(o.downsample_leaf_m)) {
    return bad("downsample_leaf_m must be finite and >= 0");
  }
  if (!(o.min_width_m >= 0.0) || !std::isfinite(o.min_width_m)) {
    return bad("min_width_m must be finite and >= 0");
  }
  return Status::Ok();
}

Result<FloorEstimate> FitFloor(const PointCloud& cloud_sensor, const FloorFitterOptions& options) {
  const Status valid = ValidateFloorFitterOptions(options);
  if (!valid.ok()) return valid.error();
  if (cloud_sensor.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, "floor fitter: the cloud is empty");
  }

  // Finite points only (organised clouds carry NaN for missing readings).
  // Big clouds are thinned first (every k-th point): the voxel grid that follows keeps a few
  // points per voxel anyway, and a full 640x480 frame would make the downsampling dominate.
  // Organised clouds are thinned on a square pixel lattice, others by index.
  std::vector<Eigen::Vector3f> finite;
  const size_t ratio = (cloud_sensor.size() + kMaxInputPoints - 1) / kMaxInputPoints;
  if (cloud_sensor.organised() && ratio > 1) {
    const int stride = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(ratio))));
    finite.reserve(cloud_sensor.size() / (stride * stride) + cloud_sensor.width + 1);
    for (int v = 0; v < cloud_sensor.height; v += stride) {
      const Eigen::Vector3f* row = cloud_sensor.points.data() + size_t(v) * cloud_sensor.width;
      for (int u = 0; u < cloud_sensor.width; u += stride) {
        if (row[u].allFinite()) finite.push_back(row[u]);
      }
    }
  } else {
    finite.reserve(cloud_sensor.size() / ratio + 1);
    for (size_t i = 0; i < cloud_sensor.size(); i += ratio) {
      const Eigen::Vector3f& p = cloud_sensor.points[i];
      if (p.allFinite()) finite.push_back(p);
    }
  }
  std::vector<Eigen::Vector3f> sampled;
  std::vector<int> voxel_of_finite;  // with the voxel grid: each finite point's centroid.
  if (options.downsample_leaf_m > 0.0) {
    VoxelDownsample(finite, static_cast<float>(options.downsample_leaf_m), &sampled,
                    options.skip_object_feet ? &voxel_of_finite : nullptr);
  } else {
    sampled.swap(finite);
  }
  const int n = static_cast<int>(sampled.size());
  VoxelKeySet foot_cells;  // empty: no point is a foot.
  if (options.skip_object_feet) foot_cells.Build(sampled, kFootCellM);
  std::vector<int> fit_on;
  if (n < kMinPoints) {
    return MakeError(ErrorCode::kFailedPrecondition,
                     "no floor: only " + std::to_string(n) + (n == 1 ? " point" : " points") +
                         (options.downsample_leaf_m > 0.0 ? " after downsampling" : "") +
                         " (need " + std::to_string(kMinPoints) + ")");
  }

  const int min_support = std::max(3, static_cast<int>(std::ceil(options.min_inlier_fraction * n)));
  const Eigen::Vector3d up_guess(0.0, -1.0, 0.0);  // sensor frame: y points down.
  const double cos_max_tilt = std::cos(options.max_tilt_rad);

  std::vector<Candidate> candidates;
  std::vector<char> taken(n, 0);
  int best_support_seen = 0;
  // Planes found with support but not acceptable as a floor, by reason.
  int sensor_below = 0, too_tilted = 0, rolled = 0, points_beneath = 0, narrow = 0, at_sensor = 0;
  double widest_narrow = 0.0, most_tilted = 0.0, most_rolled = 0.0;
  std::vector<int> inliers;
  for (int round = 0; round < kMaxCandidatePlanes; ++round) {
    int remaining_count = 0;
    for (int i = 0; i < n; ++i) remaining_count += taken[i] ? 0 : 1;
    if (remaining_count < min_support) break;
    // RANSAC scores hypotheses on an evenly spread subset (the estimate of a fraction from a
    // couple of thousand points is good enough); the refinement below uses every point.
    const int step = (remaining_count + kMaxRansacPoints - 1) / kMaxRansacPoints;
    std::vector<Eigen::Vector3f> round_points;
    round_points.reserve(remaining_count / step + 1);
    for (int i = 0, k = 0; i < n; ++i) {
      if (taken[i]) continue;
      if (k++ % step == 0) round_points.push_back(sampled[i]);
    }
    if (round_points.size() < 3) break;

    // Local sampling: the 2nd and 3rd points of a hypothesis lie within kSampleRadius of the
    // 1st, so a hypothesis is all-floor with probability ~w (floor fraction) instead of w^3.
    // That keeps a floor that is a minority of the points (people, walls, furniture) findable
    // within a few hundred iterations.
    LocalPlaneRansacOptions ransac;
    ransac.distance_threshold_m = options.distance_threshold_m;
    ransac.sample_radius_m = kSampleRadiusM;
    ransac.axis = Eigen::Vector3f(0.0f, -1.0f, 0.0f);
    ransac.max_axis_angle_rad = options.max_tilt_rad;
    ransac.max_iterations = options.max_iterations;
    ransac.seed = static_cast<unsigned>(options.random_seed) + round;
    const LocalPlaneRansacResult fit = FitPlaneLocalRansac(round_points, ransac);
    if (!fit.found) break;
    // Support as a count of all (downsampled) points, extrapolated from the subset.
    const int support = static_cast<int>(static_cast<double>(fit.inliers) * step);
    best_support_seen = std::max(best_support_seen, support);
    if (support < min_support || fit.inliers < 3) break;
    Eigen::Vector4d plane = fit.plane.cast<double>();
    const double norm = plane.head<3>().norm();
    if (!(norm > 0.0)) break;
    plane /= norm;
    // Claim the RANSAC plane's points so the next round looks for another plane.
    SelectFloorInliers(sampled, plane, options.distance_threshold_m, &inliers);
    for (const int i : inliers) taken[i] = 1;

    // Refine by least squares on the inliers, re-selecting them with the refined plane.
    bool ok = true;
    for (int r = 0; r < kRefineRounds && ok; ++r) {
      fit_on = inliers;
      // Only planes that may be the floor have feet on them (a wall's foot is the floor).
      if (plane.head<3>().dot(up_guess) >= cos_max_tilt && FloorRoll(plane) <= kMaxFloorRollRad) {
        DropObjectFeet(sampled, foot_cells, plane, &fit_on);
      }
      if (fit_on.size() < 3) fit_on = inliers;  // all feet: no floor, as later tests find.
      ok = FitFloorPlaneLeastSquares(sampled, fit_on, options.distance_threshold_m, &plane);
      if (!ok) break;
      SelectFloorInliers(sampled, plane, options.distance_threshold_m, &inliers);
    }
    if (!ok || inliers.size() < 3) continue;  // degenerate.
    if (plane[3] < kMinSensorHeightM) {
      ++at_sensor;
      continue;
    }
    // The sensor must be above the plane, i.e. its normal towards the sensor points "up":
    // this rejects ceilings and the sides of objects facing the sensor, which the sign-blind
    // axis test of the RANSAC lets through. A plane the least squares leaned past the tilt
    // limit is counted apart.
    if (plane.head<3>().dot(up_guess) < cos_max_tilt) {
      if (plane.head<3>().dot(up_guess) < 0.0) {
        ++sensor_below;
      } else {
        ++too_tilted;
        most_tilted = std::max(most_tilted, TiltFromUp(plane, up_guess));
      }
      continue;
    }
    for (const int i : inliers) taken[i] = 1;
    // A side wall passes the tilt test when the sensor is rolled towards it (by more than 90
    // degrees less max_tilt_rad; with the limit raised for a steep mount, by a little) and may
    // outnumber a floor seen at a grazing angle; taken for the floor it would mean a roll of
    // about 90 degrees less the true one.
    const double roll = FloorRoll(plane);
    if (roll > kMaxFloorRollRad) {
      ++rolled;
      most_rolled = std::max(most_rolled, roll);
      continue;
    }
    // Nothing lies below a floor. Points well below a candidate mean it is a table top or a
    // slanted plane cutting through walls and people.
    if (CountBelowFloorPlane(sampled, plane, options.distance_threshold_m) >
        std::max(kMaxBelowFraction * inliers.size(), kMaxBelowFractionOfAll * n)) {
      ++points_beneath;
      continue;
    }
    if (options.min_width_m > 0.0) {
      const double width = FloorInlierWidth(sampled, inliers, plane);
      if (width < options.min_width_m) {
        ++narrow;
        widest_narrow = std::max(widest_narrow, width);
        continue;
      }
    }
    candidates.push_back(Candidate{plane, static_cast<int>(inliers.size())});
  }

  if (candidates.empty()) {
    const std::string steep = SteepFloorNote(sampled, options, min_support, up_guess);
    const int refused = sensor_below + too_tilted + rolled + points_beneath + narrow + at_sensor;
    if (refused > 0) {
      std::string why;
      auto add = [&why](int count, const std::string& what) {
        if (count == 0) return;
        why += (why.empty() ? "" : ", ") + std::to_string(count) + " " + what;
      };
      add(sensor_below, "with the sensor below it");
      add(too_tilted, "leaning up to " + Degrees(most_tilted) +
                          " from the sensor's up direction, "
                          "past max_tilt_rad (" +
                          Degrees(options.max_tilt_rad) + ")");
      add(rolled, "meaning a sensor rolled up to " + Degrees(most_rolled) + " (more than " +
                      Degrees(kMaxFloorRollRad) + ": walls beside it)");
      add(points_beneath, "with many points beneath it");
      char text[96];
      std::snprintf(text, sizeof(text), "passing within %.2f m of the sensor", kMinSensorHeightM);
      add(at_sensor, text);
      std::snprintf(text, sizeof(text), "in strips up to %.2f m wide (need %.2f m)", widest_narrow,
                    options.min_width_m);
      add(narrow, text);
      return MakeError(ErrorCode::kFailedPrecondition,
                       "no floor: " + std::to_string(refused) +
                           " near-horizontal plane(s) found, none a floor: " + why + steep);
    }
    if (best_support_seen == 0) {
      return MakeError(ErrorCode::kFailedPrecondition,
                       "no floor: no plane within " + Degrees(options.max_tilt_rad) +
                           " of the sensor's up direction (-y) among " + std::to_string(n) +
                           " points" + steep);
    }
    return MakeError(ErrorCode::kFailedPrecondition,
                     "no floor: best plane has " +
                         Percent(static_cast<double>(best_support_seen) / n) + " inliers (need " +
                         Percent(options.min_inlier_fraction) + ")" + steep);
  }

  // A candidate with a parallel candidate clearly below it (larger d) is a table or box top.
  // Among the remaining (e.g. the floor and a wall seen from a steep pitch) the best supported
  // one is the floor.
  const double below_margin = std::max(3.0 * options.distance_threshold_m, 0.05);
  const double cos_parallel = std::cos(kParallelRad);
  const Candidate* best = nullptr;
  for (const Candidate& c : candidates) {
    bool above_another = false;
    for (const Candidate& other : candidates) {
      if (&other == &c) continue;
      if (other.plane.head<3>().dot(c.plane.head<3>()) >= cos_parallel &&
          other.plane[3] > c.plane[3] + below_margin) {
        above_another = true;
        break;
      }
    }
    if (above_another) continue;
    if (best == nullptr || c.inliers > best->inliers) best = &c;
  }
  // The lowest parallel candidate always survives, so best is set.
  // A last least-squares fit on the thinned pixels rather than the voxel centroids: every 3 cm
  // of floor weighs the same among the centroids, so the far floor, noisy and quantised, weighs
  // as much as the near one; among pixels the near floor has more points. On simulated Kinect
  // frames this halves the fit's error against the true mount (bench/stage_bench.cc).
  Eigen::Vector4d plane = best->plane;
  if (options.downsample_leaf_m > 0.0) {  // else the candidates were fitted on these points.
    std::vector<int> pixel_inliers;
    SelectFloorInliers(finite, plane, options.distance_threshold_m, &pixel_inliers);
    if (options.skip_object_feet) {
      // A pixel is a foot when its voxel's centroid is (within 2.6 cm of it: the same cells).
      const Eigen::Vector3f up = plane.head<3>().cast<float>();
      const float height = static_cast<float>(plane[3]);
      std::vector<signed char> foot(sampled.size(), -1);  // -1: not asked yet.
      size_t kept = 0;
      for (const int i : pixel_inliers) {
        signed char& f = foot[voxel_of_finite[i]];
        if (f < 0) f = IsObjectFoot(sampled[voxel_of_finite[i]], up, height, foot_cells) ? 1 : 0;
        if (f == 0) pixel_inliers[kept++] = i;
      }
      pixel_inliers.resize(kept);
    }
    Eigen::Vector4d refined;
    // Kept only within the tilt and height the candidates were held to: the pixels' fit can
    // lean a plane at the limit past it.
    if (FitFloorPlaneLeastSquares(finite, pixel_inliers, options.distance_threshold_m, &refined) &&
        refined.head<3>().dot(up_guess) >= cos_max_tilt && refined[3] >= kMinSensorHeightM) {
      plane = refined;
    }
  }
  FloorEstimate floor = FloorEstimate::FromPlane(plane);
  floor.inliers = best->inliers;
  floor.fitted = true;
  return floor;
}

}  // namespace hpose
