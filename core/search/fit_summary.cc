#include "core/search/fit_summary.h"

#include <cmath>

namespace hpose {

FitSummary Summarise(const PoseEvidence& e) {
  FitSummary s;
  s.explained = e.Explained();
  s.contradicted = e.Contradicted();
  s.fit = e.Fit();
  const int judged = e.model_seen + e.model_free + e.model_no_return;
  const double p = s.explained, q = s.contradicted;
  const double var_p = e.data_points > 0 ? p * (1.0 - p) / e.data_points : 0.25;
  const double var_q = judged > 0 ? q * (1.0 - q) / judged : 0.25;
  s.fit_sigma = 100.0 * std::sqrt((1.0 - q) * (1.0 - q) * var_p + p * p * var_q);
  s.cost = e.cost;
  const int facing = e.model_visible + e.model_out_of_view;
  s.in_view = facing > 0 ? static_cast<double>(e.model_visible) / facing : 0.0;
  return s;
}

bool WithinNoise(const FitSummary& a, const FitSummary& b) {
  return std::abs(a.fit - b.fit) <= 2.0 * std::hypot(a.fit_sigma, b.fit_sigma);
}

bool FarAhead(const FitSummary& a, const FitSummary& b, double sigmas) {
  return a.fit - b.fit > sigmas * std::hypot(a.fit_sigma, b.fit_sigma);
}

}  // namespace hpose
