#include "core/sim/truth_comparison.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

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

void TruthComparer::Add(const Pose2D& truth, const std::vector<Pose2D>& humanoids) {
  ++frames_;
  const Pose2D* nearest = nullptr;
  double nearest_m = 0.0;
  for (const Pose2D& h : humanoids) {
    const double d = std::hypot(h.x - truth.x, h.y - truth.y);
    if (nearest == nullptr || d < nearest_m) {
      nearest = &h;
      nearest_m = d;
    }
  }
  if (nearest == nullptr) return;
  position_m_.push_back(nearest_m);
  heading_rad_.push_back(std::abs(AngleDiff(nearest->theta, truth.theta)));
}

TruthComparison TruthComparer::Summary() const {
  TruthComparison s;
  s.frames = frames_;
  s.found = static_cast<int>(position_m_.size());
  for (std::size_t i = 0; i < position_m_.size(); ++i) {
    if (heading_rad_[i] <= DegToRad(5.0) && position_m_[i] <= 0.1) ++s.within_5deg_10cm;
    if (heading_rad_[i] > DegToRad(150.0)) ++s.turned_about;
  }
  std::vector<double> sorted = position_m_;
  std::sort(sorted.begin(), sorted.end());
  s.position_median_m = QuantileOfSorted(sorted, 0.5);
  s.position_p95_m = QuantileOfSorted(sorted, 0.95);
  s.position_max_m = QuantileOfSorted(sorted, 1.0);
  sorted = heading_rad_;
  std::sort(sorted.begin(), sorted.end());
  s.heading_median_rad = QuantileOfSorted(sorted, 0.5);
  s.heading_p95_rad = QuantileOfSorted(sorted, 0.95);
  s.heading_max_rad = QuantileOfSorted(sorted, 1.0);
  return s;
}

std::string DescribeTruthComparison(const TruthComparison& c) {
  char text[400];
  int n = std::snprintf(text, sizeof text,
                        "humanoid found in %d of %d frame(s), %d within 5 deg and 0.1 m, %d turned "
                        "about (over 150 deg off)",
                        c.found, c.frames, c.within_5deg_10cm, c.turned_about);
  if (c.found > 0 && n > 0 && static_cast<std::size_t>(n) < sizeof text) {
    std::snprintf(text + n, sizeof text - n,
                  "; position error median %.1f mm, p95 %.1f, max %.1f; heading error median "
                  "%.2f deg, p95 %.2f, max %.2f",
                  c.position_median_m * 1000.0, c.position_p95_m * 1000.0,
                  c.position_max_m * 1000.0, RadToDeg(c.heading_median_rad),
                  RadToDeg(c.heading_p95_rad), RadToDeg(c.heading_max_rad));
  }
  return text;
}

}  // namespace hpose
