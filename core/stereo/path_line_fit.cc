#include "core/stereo/path_line_fit.h"

#include <cmath>

namespace hpose {

PathPrediction::Approach PathPrediction::ClosestApproach(const Eigen::Vector2d& point) const {
  Approach a;
  const double v2 = velocity_mps.squaredNorm();
  if (v2 < 1e-12) {
    a.t_s = t0_s;
    a.distance_m = (origin_m - point).norm();
    return a;
  }
  a.t_s = t0_s + (point - origin_m).dot(velocity_mps) / v2;
  a.distance_m = (PositionAt(a.t_s) - point).norm();
  return a;
}

Result<PathPrediction> FitPathLine(const std::vector<TimedPosition>& samples, double t0_s) {
  if (samples.size() < 2) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "path fit needs at least 2 samples, got " + std::to_string(samples.size()));
  }
  if (!std::isfinite(t0_s))
    return MakeError(ErrorCode::kInvalidArgument, "path fit: t0 not finite");
  const double n = static_cast<double>(samples.size());
  double mt = 0;
  Eigen::Vector2d mp = Eigen::Vector2d::Zero();
  for (const TimedPosition& s : samples) {
    if (!std::isfinite(s.t_s) || !s.position_m.allFinite()) {
      return MakeError(ErrorCode::kInvalidArgument, "path fit: non-finite sample");
    }
    mt += s.t_s - t0_s;
    mp += s.position_m;
  }
  mt /= n;
  mp /= n;
  double stt = 0;
  Eigen::Vector2d stp = Eigen::Vector2d::Zero();
  for (const TimedPosition& s : samples) {
    const double dt = s.t_s - t0_s - mt;
    stt += dt * dt;
    stp += dt * (s.position_m - mp);
  }
  if (stt < 1e-12) {
    return MakeError(ErrorCode::kInvalidArgument, "path fit: all samples have the same time");
  }
  PathPrediction p;
  p.t0_s = t0_s;
  p.velocity_mps = stp / stt;
  p.origin_m = mp - p.velocity_mps * mt;
  p.frames = static_cast<int>(samples.size());
  double sum = 0;
  for (const TimedPosition& s : samples) sum += (p.PositionAt(s.t_s) - s.position_m).squaredNorm();
  p.rms_residual_m = std::sqrt(sum / n);
  return p;
}

}  // namespace hpose
