#include "core/templates/capture_registration.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <unordered_set>

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <Eigen/Dense>

namespace hpose {
namespace {

// One view prepared for registration, in its own ground frame.
struct ViewData {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  std::unordered_set<std::int64_t> occupied;  // coarse cells, dilated by one cell.
  std::vector<int> sample;                    // a few hundred points for the coarse searches.
  double angle = 0.0;                         // given table angle / heading.
};

constexpr double kCoarseCell = 0.02;

std::int64_t CellKey(const Eigen::Vector3d& p) {
  const auto c = [](double v) {
    return static_cast<std::int64_t>(std::floor(v / kCoarseCell)) + (1 << 20);
  };
  return (c(p.x()) << 42) | (c(p.y()) << 21) | c(p.z());
}

// q = R(theta) p + (x, y): table_from_ground of a view.
Eigen::Vector3d Apply(const Pose2D& t, const Eigen::Vector3d& p) {
  const double c = std::cos(t.theta), s = std::sin(t.theta);
  return {c * p.x() - s * p.y() + t.x, s * p.x() + c * p.y() + t.y, p.z()};
}
Eigen::Vector3d ApplyInverse(const Pose2D& t, const Eigen::Vector3d& q) {
  const double c = std::cos(t.theta), s = std::sin(t.theta);
  const double x = q.x() - t.x, y = q.y() - t.y;
  return {c * x + s * y, -s * x + c * y, q.z()};
}
Eigen::Vector3d Rotate(double theta, const Eigen::Vector3d& v) {
  const double c = std::cos(theta), s = std::sin(theta);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y(), v.z()};
}

// Turntable: view at table angle phi (relative), axis at c: q = R(-phi) (p - c).
Pose2D TurntablePose(double phi, const Eigen::Vector2d& c) {
  const Eigen::Vector3d t = Rotate(-phi, Eigen::Vector3d(-c.x(), -c.y(), 0.0));
  return Pose2D{t.x(), t.y(), -phi};
}

std::unique_ptr<ViewData> Prepare(const RobotView& view, double normal_radius) {
  auto d = std::make_unique<ViewData>();
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const Eigen::Vector3f& p : view.points) {
    d->points.push_back(p.cast<double>());
    cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  }
  d->tree.setInputCloud(cloud);
  pcl::Indices idx;
  std::vector<float> dist;
  for (const Eigen::Vector3d& p : d->points) {
    Eigen::Vector3d n = Eigen::Vector3d(-p.x(), -p.y(), 0.0).normalized();  // towards the sensor.
    if (d->tree.radiusSearch(pcl::PointXYZ(p.x(), p.y(), p.z()), normal_radius, idx, dist) >= 5) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (const int k : idx) mean += d->points[k];
      mean /= static_cast<double>(idx.size());
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (const int k : idx) {
        const Eigen::Vector3d e = d->points[k] - mean;
        cov += e * e.transpose();
      }
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
      n = eig.eigenvectors().col(0);
    }
    d->normals.push_back(n);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          d->occupied.insert(CellKey(p + kCoarseCell * Eigen::Vector3d(dx, dy, dz)));
        }
      }
    }
  }
  const int n = static_cast<int>(d->points.size());
  const int step = std::max(1, n / 250);
  for (int k = 0; k < n; k += step) d->sample.push_back(k);
  return d;
}

// Up to two views on each side by angle, within max_angle.
std::vector<std::vector<int>> Partners(const std::vector<double>& angles, double max_angle) {
  const int n = static_cast<int>(angles.size());
  std::vector<std::vector<int>> out(n);
  for (int i = 0; i < n; ++i) {
    std::vector<std::pair<double, int>> left, right;
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      const double d = AngleDiff(angles[j], angles[i]);
      if (std::abs(d) > max_angle) continue;
      (d >= 0.0 ? right : left).push_back({std::abs(d), j});
    }
    std::sort(left.begin(), left.end());
    std::sort(right.begin(), right.end());
    for (size_t k = 0; k < std::min<size_t>(2, left.size()); ++k) out[i].push_back(left[k].second);
    for (size_t k = 0; k < std::min<size_t>(2, right.size()); ++k) {
      if (std::find(out[i].begin(), out[i].end(), right[k].second) == out[i].end()) {
        out[i].push_back(right[k].second);
      }
    }
  }
  return out;
}

// How many sample points of view i, placed by t_i, fall in the occupied cells of the partners.
int Overlap(const std::vector<std::unique_ptr<ViewData>>& data, int i, const Pose2D& t_i,
            const std::vector<int>& partners, const std::vector<Pose2D>& poses) {
  int hits = 0;
  for (const int j : partners) {
    for (const int k : data[i]->sample) {
      const Eigen::Vector3d pj = ApplyInverse(poses[j], Apply(t_i, data[i]->points[k]));
      hits += data[j]->occupied.count(CellKey(pj)) ? 1 : 0;
    }
  }
  return hits;
}

// A point of view i matched to a point of view j: table-frame positions and j's normal.
struct Match {
  int i, j;
  Eigen::Vector3d qi, qj, n;
  double residual;  // n . (qi - qj)
};

std::vector<Match> FindMatches(const std::vector<std::unique_ptr<ViewData>>& data,
                               const std::vector<Pose2D>& poses,
                               const std::vector<std::vector<int>>& partners, double max_dist,
                               int stride) {
  std::vector<Match> out;
  pcl::Indices idx(1);
  std::vector<float> d2(1);
  const double max2 = max_dist * max_dist;
  for (size_t i = 0; i < data.size(); ++i) {
    for (const int j : partners[i]) {
      for (size_t k = 0; k < data[i]->points.size(); k += stride) {
        const Eigen::Vector3d q = Apply(poses[i], data[i]->points[k]);
        const Eigen::Vector3d pj = ApplyInverse(poses[j], q);
        if (data[j]->tree.nearestKSearch(pcl::PointXYZ(pj.x(), pj.y(), pj.z()), 1, idx, d2) < 1 ||
            d2[0] > max2) {
          continue;
        }
        Match m{static_cast<int>(i),
                j,
                q,
                Apply(poses[j], data[j]->points[idx[0]]),
                Rotate(poses[j].theta, data[j]->normals[idx[0]]),
                0.0};
        m.residual = m.n.dot(m.qi - m.qj);
        out.push_back(m);
      }
    }
  }
  return out;
}

double HuberWeight(double r, double k) { return std::abs(r) <= k ? 1.0 : k / std::abs(r); }

// Per view: inlier fraction and point-to-plane RMS against its partners.
void Residuals(const std::vector<std::unique_ptr<ViewData>>& data, const std::vector<Pose2D>& poses,
               const std::vector<std::vector<int>>& partners, double max_dist,
               std::vector<ViewResidual>* out) {
  pcl::Indices idx(1);
  std::vector<float> d2(1);
  for (size_t i = 0; i < data.size(); ++i) {
    int inliers = 0;
    double sum2 = 0.0;
    for (const Eigen::Vector3d& p : data[i]->points) {
      const Eigen::Vector3d q = Apply(poses[i], p);
      double best = max_dist * max_dist, best_r = 0.0;
      bool found = false;
      for (const int j : partners[i]) {
        const Eigen::Vector3d pj = ApplyInverse(poses[j], q);
        if (data[j]->tree.nearestKSearch(pcl::PointXYZ(pj.x(), pj.y(), pj.z()), 1, idx, d2) < 1 ||
            d2[0] > best) {
          continue;
        }
        best = d2[0];
        best_r = data[j]->normals[idx[0]].dot(pj - data[j]->points[idx[0]]);
        found = true;
      }
      if (!found) continue;
      ++inliers;
      sum2 += best_r * best_r;
    }
    ViewResidual& r = (*out)[i];
    r.points = static_cast<int>(data[i]->points.size());
    r.inlier_fraction = r.points > 0 ? static_cast<double>(inliers) / r.points : 0.0;
    r.rms_m = inliers > 0 ? std::sqrt(sum2 / inliers) : 0.0;
  }
}

// The correspondence distance of iteration `it`: 3x, then 2x, then 1x the final one.
double Schedule(int it, int iterations, double final_dist) {
  if (it < iterations / 3) return 3.0 * final_dist;
  if (it < 2 * iterations / 3) return 2.0 * final_dist;
  return final_dist;
}

// Turntable: coarse grid, then the linear least squares in the axis position, iterated.
Eigen::Vector2d SolveTurntable(const std::vector<std::unique_ptr<ViewData>>& data,
                               const std::vector<double>& phi,
                               const std::vector<std::vector<int>>& partners,
                               const Eigen::Vector2d& guess, const CaptureRegistrationOptions& o,
                               double* conditioning, int* iterations_run) {
  const int n = static_cast<int>(data.size());
  auto poses_for = [&](const Eigen::Vector2d& c) {
    std::vector<Pose2D> poses;
    for (int i = 0; i < n; ++i) poses.push_back(TurntablePose(phi[i], c));
    return poses;
  };
  auto score = [&](const Eigen::Vector2d& c) {
    const std::vector<Pose2D> poses = poses_for(c);
    int s = 0;
    for (int i = 0; i < n; ++i) s += Overlap(data, i, poses[i], partners[i], poses);
    return s;
  };
  Eigen::Vector2d best = guess;
  int best_score = -1;
  for (const double step : {o.coarse_step_m * 2.0, o.coarse_step_m * 0.5}) {
    const double radius = step > o.coarse_step_m ? o.axis_search_radius_m : 3.0 * o.coarse_step_m;
    const Eigen::Vector2d centre = best;
    const int k = static_cast<int>(std::ceil(radius / step));
    for (int a = -k; a <= k; ++a) {
      for (int b = -k; b <= k; ++b) {
        const Eigen::Vector2d c = centre + step * Eigen::Vector2d(a, b);
        if ((c - guess).norm() > o.axis_search_radius_m + 1e-9) continue;
        const int s = score(c);
        if (s > best_score) {
          best_score = s;
          best = c;
        }
      }
    }
  }

  Eigen::Vector2d c = best;
  int it = 0;
  for (; it < o.iterations; ++it) {
    const double dist = Schedule(it, o.iterations, o.max_correspondence_m);
    const std::vector<Match> matches = FindMatches(data, poses_for(c), partners, dist, 2);
    Eigen::Matrix2d h = Eigen::Matrix2d::Zero();
    Eigen::Vector2d g = Eigen::Vector2d::Zero();
    for (const Match& m : matches) {
      // r(c) = n . (qi - qj) is linear in c: dr/dc = -n^T (R(-phi_i) - R(-phi_j)).
      const Eigen::Vector3d ex =
          Rotate(-phi[m.i], Eigen::Vector3d::UnitX()) - Rotate(-phi[m.j], Eigen::Vector3d::UnitX());
      const Eigen::Vector3d ey =
          Rotate(-phi[m.i], Eigen::Vector3d::UnitY()) - Rotate(-phi[m.j], Eigen::Vector3d::UnitY());
      const Eigen::Vector2d jac(-m.n.dot(ex), -m.n.dot(ey));
      const double w = HuberWeight(m.residual, 0.5 * o.max_correspondence_m);
      h += w * jac * jac.transpose();
      g += w * jac * m.residual;
    }
    if (matches.size() < 10) break;
    const Eigen::Vector2d delta = -h.ldlt().solve(g);
    const Eigen::JacobiSVD<Eigen::Matrix2d> svd(h);
    *conditioning = svd.singularValues()(1) / std::max(1e-300, svd.singularValues()(0));
    c += delta;
    if (delta.norm() < 1e-6 && dist == o.max_correspondence_m) {
      ++it;
      break;
    }
  }
  *iterations_run = it;
  return c;
}

// Hand-turned: each view placed by a coarse search against those already placed, then joint
// Gauss-Newton over (x, y, theta) of every view but the first.
std::vector<Pose2D> SolveHandTurned(const std::vector<std::unique_ptr<ViewData>>& data,
                                    const std::vector<double>& headings,
                                    const std::vector<Eigen::Vector3d>& centroids,
                                    const CaptureRegistrationOptions& o, int* iterations_run) {
  const int n = static_cast<int>(data.size());
  std::vector<Pose2D> poses(n);
  // View 0 defines the frame: q = R(-h0) p.
  poses[0] = Pose2D{0.0, 0.0, -headings[0]};
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin() + 1, order.end(), [&](int a, int b) {
    return std::abs(AngleDiff(headings[a], headings[0])) <
           std::abs(AngleDiff(headings[b], headings[0]));
  });
  std::vector<int> placed{0};
  const Eigen::Vector3d anchor = Apply(poses[0], centroids[0]);
  for (int oi = 1; oi < n; ++oi) {
    const int i = order[oi];
    // Partners: the placed views nearest in heading (up to 3).
    std::vector<int> partners = placed;
    std::sort(partners.begin(), partners.end(), [&](int a, int b) {
      return std::abs(AngleDiff(headings[a], headings[i])) <
             std::abs(AngleDiff(headings[b], headings[i]));
    });
    if (partners.size() > 3) partners.resize(3);
    Pose2D best;
    int best_score = -1;
    const double angle_step = DegToRad(2.0);
    const int ka = static_cast<int>(std::ceil(o.heading_search_rad / angle_step));
    for (int a = -ka; a <= ka; ++a) {
      const double theta = -headings[i] + a * angle_step;
      // Seed: centroids on top of each other (the views' centroids differ by the visible side,
      // a few centimetres, which the search covers).
      const Eigen::Vector3d rc = Rotate(theta, centroids[i]);
      const Pose2D seed{anchor.x() - rc.x(), anchor.y() - rc.y(), theta};
      for (const double step : {0.02, 0.005}) {
        const double radius = step > 0.01 ? o.heading_search_translation_m : 0.015;
        const Pose2D centre = step > 0.01 ? seed : best;
        if (step < 0.01 && std::abs(AngleDiff(best.theta, theta)) > 1e-9) continue;
        const int k = static_cast<int>(std::ceil(radius / step));
        for (int bx = -k; bx <= k; ++bx) {
          for (int by = -k; by <= k; ++by) {
            const Pose2D t{centre.x + step * bx, centre.y + step * by, theta};
            const int s = Overlap(data, i, t, partners, poses);
            if (s > best_score) {
              best_score = s;
              best = t;
            }
          }
        }
      }
    }
    poses[i] = best;
    placed.push_back(i);
  }

  // Joint refinement.
  std::vector<double> current(n);
  int it = 0;
  const int m = 3 * (n - 1);
  for (; it < o.iterations; ++it) {
    for (int i = 0; i < n; ++i) current[i] = -poses[i].theta;
    const std::vector<std::vector<int>> partners = Partners(current, o.max_pair_angle_rad);
    const double dist = Schedule(it, o.iterations, o.max_correspondence_m);
    const std::vector<Match> matches = FindMatches(data, poses, partners, dist, 2);
    if (matches.size() < 10) break;
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(m, m);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(m);
    for (const Match& mt : matches) {
      const double w = HuberWeight(mt.residual, 0.5 * o.max_correspondence_m);
      Eigen::VectorXd jac = Eigen::VectorXd::Zero(m);
      auto add = [&](int view, const Eigen::Vector3d& q, double sign) {
        if (view == 0) return;
        const int b = 3 * (view - 1);
        jac[b] += sign * mt.n.x();
        jac[b + 1] += sign * mt.n.y();
        jac[b + 2] += sign * (mt.n.y() * q.x() - mt.n.x() * q.y());
      };
      add(mt.i, mt.qi, 1.0);
      add(mt.j, mt.qj, -1.0);
      // Sparse rank-one update: at most 6 non-zeros.
      for (int a = 0; a < m; ++a) {
        if (jac[a] == 0.0) continue;
        g[a] += w * jac[a] * mt.residual;
        for (int b = 0; b < m; ++b) {
          if (jac[b] != 0.0) h(a, b) += w * jac[a] * jac[b];
        }
      }
    }
    h.diagonal().array() += 1e-6;
    const Eigen::VectorXd delta = -h.ldlt().solve(g);
    double largest = 0.0;
    for (int i = 1; i < n; ++i) {
      const Eigen::Vector3d d = delta.segment<3>(3 * (i - 1));
      const Eigen::Vector3d t = Rotate(d.z(), Eigen::Vector3d(poses[i].x, poses[i].y, 0.0));
      poses[i] = Pose2D{t.x() + d.x(), t.y() + d.y(), NormalizeAngle(poses[i].theta + d.z())};
      largest = std::max(largest, std::max(d.head<2>().norm(), 0.3 * std::abs(d.z())));
    }
    if (largest < 1e-6 && dist == o.max_correspondence_m) {
      ++it;
      break;
    }
  }
  *iterations_run = it;
  return poses;
}

std::string Format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string Format(const char* fmt, ...) {
  char buf[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof(buf), fmt, args);
  va_end(args);
  return buf;
}

}  // namespace

Result<CaptureRegistration> RegisterCaptureViews(const CaptureViews& views,
                                                 const CaptureRegistrationOptions& options,
                                                 const ProgressFn& progress) {
  auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };
  if (views.views.size() < 2) {
    return MakeError(ErrorCode::kInvalidArgument, "registration needs at least 2 views");
  }
  for (const RobotView& v : views.views) {
    if (v.capture_index < 0 || v.capture_index >= static_cast<int>(options.angles_rad.size())) {
      return MakeError(ErrorCode::kInvalidArgument, "no angle given for capture " + v.name + " (" +
                                                        std::to_string(options.angles_rad.size()) +
                                                        " angles)");
    }
    if (v.points.size() < 30) {
      return MakeError(
          ErrorCode::kFailedPrecondition,
          "capture " + v.name + ": only " + std::to_string(v.points.size()) + " robot points");
    }
  }
  if (!(options.max_correspondence_m > 0.0) || options.iterations < 1 ||
      !(options.axis_search_radius_m >= 0.0) || !(options.coarse_step_m > 0.0) ||
      !(options.heading_search_rad >= 0.0) || !(options.heading_search_translation_m >= 0.0)) {
    return MakeError(ErrorCode::kInvalidArgument, "registration options out of range");
  }

  std::vector<RobotView> kept = views.views;
  std::vector<ViewResidual> dropped;
  for (;;) {
    const int n = static_cast<int>(kept.size());
    std::vector<std::unique_ptr<ViewData>> data;
    std::vector<double> angles;
    std::vector<Eigen::Vector3d> centroids;
    for (const RobotView& v : kept) {
      data.push_back(Prepare(v, options.normal_radius_m));
      angles.push_back(options.angles_rad[v.capture_index]);
      centroids.push_back(v.centroid.cast<double>());
    }
    CaptureRegistration reg;
    reg.motion = options.motion;
    reg.views = kept;
    if (options.motion == CaptureMotion::kTurntable) {
      std::vector<double> phi;
      Eigen::Vector2d guess = Eigen::Vector2d::Zero();
      for (int i = 0; i < n; ++i) {
        phi.push_back(AngleDiff(angles[i], angles[0]));
        guess += centroids[i].head<2>() / n;
      }
      const std::vector<std::vector<int>> partners = Partners(phi, options.max_pair_angle_rad);
      say(Format("turntable: %d views; searching the axis within %.0f mm of x %.0f, y %.0f mm", n,
                 options.axis_search_radius_m * 1000.0, guess.x() * 1000.0, guess.y() * 1000.0));
      reg.axis_ground = SolveTurntable(data, phi, partners, guess, options, &reg.axis_conditioning,
                                       &reg.iterations_run);
      for (int i = 0; i < n; ++i)
        reg.table_from_ground.push_back(TurntablePose(phi[i], reg.axis_ground));
      say(Format("axis at x %.1f mm, y %.1f mm on the floor (%d iterations)",
                 reg.axis_ground.x() * 1000.0, reg.axis_ground.y() * 1000.0, reg.iterations_run));
      reg.residuals.resize(n);
      Residuals(data, reg.table_from_ground, partners, options.max_correspondence_m,
                &reg.residuals);
      for (int i = 0; i < n; ++i) reg.residuals[i].angle_rad = angles[i];
    } else {
      say(Format("hand-turned: %d views; searching each heading within +-%.0f deg", n,
                 RadToDeg(options.heading_search_rad)));
      reg.table_from_ground =
          SolveHandTurned(data, angles, centroids, options, &reg.iterations_run);
      std::vector<double> refined;
      for (const Pose2D& p : reg.table_from_ground) refined.push_back(-p.theta);
      const std::vector<std::vector<int>> partners = Partners(refined, options.max_pair_angle_rad);
      reg.residuals.resize(n);
      Residuals(data, reg.table_from_ground, partners, options.max_correspondence_m,
                &reg.residuals);
      for (int i = 0; i < n; ++i) reg.residuals[i].angle_rad = NormalizeAngle(refined[i]);
    }
    // The axis direction in the sensor frame is the floor normal.
    reg.axis_direction_sensor = views.floor.plane_sensor.head<3>().normalized();

    int worst = -1;
    double worst_badness = 0.0;
    std::string bad;
    for (int i = 0; i < n; ++i) {
      ViewResidual& r = reg.residuals[i];
      r.name = kept[i].name;
      r.fits = r.inlier_fraction >= options.min_inlier_fraction && r.rms_m <= options.max_rms_m;
      if (r.fits) continue;
      const double badness =
          std::max(r.rms_m / options.max_rms_m,
                   options.min_inlier_fraction / std::max(1e-6, r.inlier_fraction));
      if (badness > worst_badness) {
        worst_badness = badness;
        worst = i;
      }
      char buf[256];
      std::snprintf(buf, sizeof(buf), "%s%s (RMS %.1f mm, %.0f%% inliers)", bad.empty() ? "" : "; ",
                    r.name.c_str(), r.rms_m * 1000.0, r.inlier_fraction * 100.0);
      bad += buf;
    }
    if (worst < 0) {
      for (ViewResidual& d : dropped) reg.residuals.push_back(d);
      reg.unobservable = {
          "translation along the turntable axis (z): a rotation about a vertical axis does not "
          "move points along it; z = 0 is defined as the table top instead",
          "the turntable's zero angle: only angle differences are known; the template's x axis "
          "is defined by the view the robot faced the sensor in"};
      if (options.motion == CaptureMotion::kHandTurned) {
        reg.unobservable = {
            "the robot's placement in the first view: every view is registered to it, so the "
            "template origin is defined from the merged body instead",
            "translation along the vertical: the floor fixes z = 0"};
      }
      return reg;
    }
    if (!options.drop_bad_views) {
      return MakeError(ErrorCode::kFailedPrecondition,
                       "captures that do not fit the others (limits: RMS " +
                           Format("%.1f mm, %.0f%% inliers", options.max_rms_m * 1000.0,
                                  options.min_inlier_fraction * 100.0) +
                           "): " + bad + "; remove them or pass --drop-bad-views");
    }
    ViewResidual d = reg.residuals[worst];
    d.dropped = true;
    say("dropping " + d.name +
        Format(": RMS %.1f mm, %.0f%% inliers", d.rms_m * 1000.0, d.inlier_fraction * 100.0));
    dropped.push_back(d);
    kept.erase(kept.begin() + worst);
    if (kept.size() < 2) {
      return MakeError(ErrorCode::kFailedPrecondition,
                       "fewer than 2 captures fit each other: " + bad);
    }
  }
}

std::vector<Eigen::Vector3f> MergedTablePoints(const CaptureRegistration& registration) {
  std::vector<Eigen::Vector3f> out;
  for (size_t i = 0; i < registration.views.size(); ++i) {
    for (const Eigen::Vector3f& p : registration.views[i].points) {
      out.push_back(Apply(registration.table_from_ground[i], p.cast<double>()).cast<float>());
    }
  }
  return out;
}

}  // namespace hpose
