#include "core/sim/truth_comparison.h"

#include <cmath>

#include "core/common/quantile.h"

namespace hpose {
namespace {

std::string LastPart(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

const SimFrameTruth* FindFrameTruth(const SimTruth& truth, const std::string& file_name) {
  const std::string name = LastPart(file_name);
  if (name.empty()) return nullptr;
  for (const SimFrameTruth& frame : truth.frames) {
    if (LastPart(frame.depth_file) == name || LastPart(frame.cloud_file) == name) return &frame;
  }
  return nullptr;
}

void TruthComparer::Add(const Pose2D& truth, bool found, const Pose2D& estimate) {
  ++frames_;
  if (!found) return;
  position_m_.push_back(std::hypot(estimate.x - truth.x, estimate.y - truth.y));
  heading_rad_.push_back(std::abs(AngleDiff(estimate.theta, truth.theta)));
}

TruthComparison TruthComparer::Summary() const {
  TruthComparison s;
  s.frames = frames_;
  s.found = static_cast<int>(position_m_.size());
  for (std::size_t i = 0; i < position_m_.size(); ++i) {
    if (heading_rad_[i] <= DegToRad(5.0) && position_m_[i] <= 0.1) ++s.within_5deg;
    if (heading_rad_[i] > DegToRad(150.0)) ++s.turned_about;
  }
  s.position_median_m = Quantile(position_m_, 0.5);
  s.position_p95_m = Quantile(position_m_, 0.95);
  s.position_max_m = Quantile(position_m_, 1.0);
  s.heading_median_rad = Quantile(heading_rad_, 0.5);
  s.heading_p95_rad = Quantile(heading_rad_, 0.95);
  s.heading_max_rad = Quantile(heading_rad_, 1.0);
  return s;
}

}  // namespace hpose
