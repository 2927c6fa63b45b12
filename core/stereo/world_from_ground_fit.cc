#include "core/stereo/world_from_ground_fit.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <sstream>

#include <Eigen/Eigenvalues>

namespace hpose {
namespace {

// Bounds on the pose pairs a fit accepts: positions within 10 km of the origin, headings within
// a thousand radians (about 160 turns). Anything beyond is a unit or parsing mistake.
constexpr double kMaxPairPositionM = 1e4;
constexpr double kMaxPairHeadingRad = 1e3;

struct Transform2 {
  double yaw = 0.0;
  Eigen::Vector2d t = Eigen::Vector2d::Zero();
  Eigen::Vector2d Apply(const Pose2D& p) const {
    return Eigen::Rotation2Dd(yaw) * Eigen::Vector2d(p.x, p.y) + t;
  }
};

// Circular mean of world.theta - ground.theta over the selected pairs.
double HeadingYaw(const std::vector<GroundWorldPair>& pairs, const std::vector<bool>& use) {
  double s = 0, c = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!use[i]) continue;
    const double d = pairs[i].world.theta - pairs[i].ground.theta;
    s += std::sin(d);
    c += std::cos(d);
  }
  return std::atan2(s, c);
}

Transform2 Fit(const std::vector<GroundWorldPair>& pairs, const std::vector<bool>& use,
               bool from_positions) {
  Eigen::Vector2d mg = Eigen::Vector2d::Zero(), mw = Eigen::Vector2d::Zero();
  int n = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!use[i]) continue;
    mg += Eigen::Vector2d(pairs[i].ground.x, pairs[i].ground.y);
    mw += Eigen::Vector2d(pairs[i].world.x, pairs[i].world.y);
    ++n;
  }
  mg /= n;
  mw /= n;
  Transform2 out;
  if (from_positions) {
    // 2D Kabsch: yaw = atan2(sum cross, sum dot) of the centred point pairs.
    double sc = 0, sd = 0;
    for (size_t i = 0; i < pairs.size(); ++i) {
      if (!use[i]) continue;
      const Eigen::Vector2d g = Eigen::Vector2d(pairs[i].ground.x, pairs[i].ground.y) - mg;
      const Eigen::Vector2d w = Eigen::Vector2d(pairs[i].world.x, pairs[i].world.y) - mw;
      sd += g.dot(w);
      sc += g.x() * w.y() - g.y() * w.x();
    }
    out.yaw = std::atan2(sc, sd);
  } else {
    out.yaw = HeadingYaw(pairs, use);
  }
  out.t = mw - Eigen::Rotation2Dd(out.yaw) * mg;
  return out;
}

}  // namespace

Result<WorldFromGroundFit> FitWorldFromGround(const std::vector<GroundWorldPair>& pairs,
                                              const WorldFromGroundOptions& options) {
  if (pairs.size() < 3) {
    return MakeError(
        ErrorCode::kInvalidArgument,
        "world-from-ground fit: needs at least 3 pose pairs, got " + std::to_string(pairs.size()));
  }
  for (size_t i = 0; i < pairs.size(); ++i) {
    const GroundWorldPair& p = pairs[i];
    if (!std::isfinite(p.ground.x + p.ground.y + p.ground.theta + p.world.x + p.world.y +
                       p.world.theta)) {
      return MakeError(ErrorCode::kInvalidArgument,
                       "world-from-ground fit: pair " + std::to_string(i) + " is not finite");
    }
    // Finite but absurd values would swamp the sums (a 1e300 m position fitted to nonsense).
    const double far = std::max(
        {std::abs(p.ground.x), std::abs(p.ground.y), std::abs(p.world.x), std::abs(p.world.y)});
    const double turned = std::max(std::abs(p.ground.theta), std::abs(p.world.theta));
    if (far > kMaxPairPositionM || turned > kMaxPairHeadingRad) {
      std::ostringstream msg;
      msg << "world-from-ground fit: pair " << i << " has a position " << far
          << " m from the origin or a heading of " << turned << " rad; a robot on a field is "
          << "within " << kMaxPairPositionM << " m and its headings within +-" << kMaxPairHeadingRad
          << " rad";
      return MakeError(ErrorCode::kInvalidArgument, msg.str());
    }
  }
  const size_t n = pairs.size();
  std::vector<bool> use(n, true);
  WorldFromGroundFit fit;
  fit.pairs = static_cast<int>(n);
  Transform2 tf;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    // Spread of the positions in use decides where the rotation comes from.
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    int m = 0;
    for (size_t i = 0; i < n; ++i) {
      if (use[i]) {
        mean += Eigen::Vector2d(pairs[i].ground.x, pairs[i].ground.y);
        ++m;
      }
    }
    if (m < 3) {
      return MakeError(ErrorCode::kFailedPrecondition,
                       "world-from-ground fit: only " + std::to_string(m) + " of " +
                           std::to_string(n) + " pairs agree with each other");
    }
    mean /= m;
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (size_t i = 0; i < n; ++i) {
      if (!use[i]) continue;
      const Eigen::Vector2d d = Eigen::Vector2d(pairs[i].ground.x, pairs[i].ground.y) - mean;
      cov += d * d.transpose() / m;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    fit.spread_minor_m = std::sqrt(std::max(0.0, eig.eigenvalues()(0)));
    fit.spread_major_m = std::sqrt(std::max(0.0, eig.eigenvalues()(1)));
    fit.rotation_from_positions = fit.spread_major_m >= options.min_position_spread_m;
    tf = Fit(pairs, use, fit.rotation_from_positions);

    // Residuals of every pair; robust scale from the inliers' median absolute residual.
    fit.residuals_m.assign(n, 0.0);
    std::vector<double> in_use;
    for (size_t i = 0; i < n; ++i) {
      fit.residuals_m[i] =
          (tf.Apply(pairs[i].ground) - Eigen::Vector2d(pairs[i].world.x, pairs[i].world.y)).norm();
      if (use[i]) in_use.push_back(fit.residuals_m[i]);
    }
    std::nth_element(in_use.begin(), in_use.begin() + in_use.size() / 2, in_use.end());
    const double sigma = 1.4826 * in_use[in_use.size() / 2];
    const double limit = std::max(options.outlier_threshold_m, 3.0 * sigma);
    std::vector<bool> next(n);
    for (size_t i = 0; i < n; ++i) {
      const double heading =
          std::abs(AngleDiff(pairs[i].world.theta, pairs[i].ground.theta + tf.yaw));
      next[i] = fit.residuals_m[i] <= limit && heading <= options.outlier_heading_rad;
    }
    if (next == use) break;
    use = next;
  }
  fit.inlier = use;
  fit.world_from_ground = Pose2D{tf.t.x(), tf.t.y(), NormalizeAngle(tf.yaw)};
  double sum = 0, sum_heading = 0;
  fit.inliers = 0;
  fit.max_m = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!use[i]) continue;
    ++fit.inliers;
    sum += fit.residuals_m[i] * fit.residuals_m[i];
    fit.max_m = std::max(fit.max_m, fit.residuals_m[i]);
    const double h = AngleDiff(pairs[i].world.theta, pairs[i].ground.theta + tf.yaw);
    sum_heading += h * h;
  }
  if (fit.inliers < 3) {
    return MakeError(ErrorCode::kFailedPrecondition,
                     "world-from-ground fit: fewer than 3 pairs agree with each other");
  }
  fit.rms_m = std::sqrt(sum / fit.inliers);
  fit.heading_rms_rad = std::sqrt(sum_heading / fit.inliers);
  std::ostringstream o;
  o.precision(3);
  if (fit.rotation_from_positions) {
    o << "the robot's positions spread " << fit.spread_major_m << " m x " << fit.spread_minor_m
      << " m (1 sigma): yaw and x, y follow from the positions";
    if (fit.spread_minor_m < 0.25 * fit.spread_major_m) {
      o << " (a nearly straight path: yaw rests on one direction)";
    }
  } else {
    o << "the robot hardly moved (spread " << fit.spread_major_m
      << " m): the yaw comes from the headings only, x, y from the mean position; walk the "
         "robot around for a position-based yaw";
  }
  fit.observability = o.str();
  return fit;
}

std::vector<GroundWorldPair> PairPosesByTime(const std::vector<TimedPose>& ground,
                                             const std::vector<TimedPose>& world, double max_dt_s) {
  std::vector<TimedPose> sorted = world;
  std::sort(sorted.begin(), sorted.end(),
            [](const TimedPose& a, const TimedPose& b) { return a.timestamp_s < b.timestamp_s; });
  std::vector<GroundWorldPair> pairs;
  for (const TimedPose& g : ground) {
    const auto after =
        std::lower_bound(sorted.begin(), sorted.end(), g.timestamp_s,
                         [](const TimedPose& w, double t) { return w.timestamp_s < t; });
    const TimedPose* nearest = nullptr;
    if (after != sorted.end()) nearest = &*after;
    if (after != sorted.begin()) {
      const TimedPose* before = &*std::prev(after);
      if (nearest == nullptr ||
          g.timestamp_s - before->timestamp_s < nearest->timestamp_s - g.timestamp_s) {
        nearest = before;
      }
    }
    if (nearest == nullptr || std::abs(nearest->timestamp_s - g.timestamp_s) > max_dt_s) continue;
    pairs.push_back(GroundWorldPair{g.timestamp_s, g.pose, nearest->pose});
  }
  return pairs;
}

}  // namespace hpose
