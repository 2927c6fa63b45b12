#include "core/sim/kinect_noise_model.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace hpose {
namespace {

constexpr double kTwoPi = 6.283185307179586;

std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// Uniform in (0, 1]: never 0, so log() below is finite.
double UnitOpen(std::uint64_t bits) {
  return (static_cast<double>(bits >> 11) + 1.0) * (1.0 / 9007199254740992.0);
}

// The hash state a pixel's random numbers are drawn from (stream k: SplitMix64(state + k)).
std::uint64_t PixelState(std::uint64_t seed, std::uint64_t pixel_index) {
  return SplitMix64(SplitMix64(seed) ^ (pixel_index * 0xd1b54a32d192ed03ULL));
}

}  // namespace

Status KinectNoiseOptions::Validate() const {
  auto bad = [](const std::string& what) {
    return Status(MakeError(ErrorCode::kInvalidArgument, "Kinect noise option " + what));
  };
  if (!std::isfinite(axial_sigma_per_m) || axial_sigma_per_m < 0.0) {
    return bad("axial_sigma_per_m must be finite and >= 0");
  }
  if (!std::isfinite(lateral_sigma_px) || lateral_sigma_px < 0.0 || lateral_sigma_px > 10.0) {
    return bad("lateral_sigma_px must be in [0, 10]");
  }
  if (!std::isfinite(min_range_m) || !std::isfinite(max_range_m) || min_range_m < 0.0 ||
      max_range_m <= min_range_m || max_range_m > 65.0) {
    return bad("range must satisfy 0 <= min_range_m < max_range_m <= 65");
  }
  if (!std::isfinite(max_incidence_rad) || max_incidence_rad <= 0.0 ||
      max_incidence_rad > 1.5707963267948966) {
    return bad("max_incidence_rad must be in (0, pi/2]");
  }
  if (!std::isfinite(correlated_share) || correlated_share < 0.0 || correlated_share > 1.0) {
    return bad("correlated_share must be in [0, 1]");
  }
  if (correlation_radius_px < 1 || correlation_radius_px > 64) {
    return bad("correlation_radius_px must be in [1, 64]");
  }
  return Status::Ok();
}

Result<KinectNoiseModel> KinectNoiseModel::Create(const KinectNoiseOptions& options) {
  if (Status s = options.Validate(); !s.ok()) return s.error();
  return KinectNoiseModel(options);
}

KinectNoiseModel::PixelDraw KinectNoiseModel::Draw(std::uint64_t seed,
                                                   std::uint64_t pixel_index) const {
  PixelDraw draw;
  if (!options_.noise_enabled) return draw;
  const std::uint64_t state = PixelState(seed, pixel_index);
  // Two Box-Muller pairs from four independent uniforms.
  const double u1 = UnitOpen(SplitMix64(state + 1));
  const double u2 = UnitOpen(SplitMix64(state + 2));
  const double u3 = UnitOpen(SplitMix64(state + 3));
  const double u4 = UnitOpen(SplitMix64(state + 4));
  const double r1 = std::sqrt(-2.0 * std::log(u1));
  const double r2 = std::sqrt(-2.0 * std::log(u3));
  draw.du_px = options_.lateral_sigma_px * r1 * std::cos(kTwoPi * u2);
  draw.dv_px = options_.lateral_sigma_px * r1 * std::sin(kTwoPi * u2);
  draw.axial_normal = r2 * std::cos(kTwoPi * u4);
  return draw;
}

namespace {

// Sums of `in` (width x height, row by row) over the windows of `radius` around each pixel,
// clipped by the image, divided by the square root of their pixel count: the windows' means of
// independent unit normals scaled back to unit variance.
std::vector<double> WindowField(const std::vector<double>& in, int width, int height, int radius) {
  const size_t n = in.size();
  std::vector<double> rows(n), out(n);
  const auto count = [radius](int i, int size) {
    return std::min(size - 1, i + radius) - std::max(0, i - radius) + 1;
  };
  for (int v = 0; v < height; ++v) {
    const double* src = &in[static_cast<size_t>(v) * width];
    double* sum = &rows[static_cast<size_t>(v) * width];
    double run = 0.0;
    for (int u = 0; u <= std::min(width - 1, radius); ++u) run += src[u];
    for (int u = 0; u < width; ++u) {
      sum[u] = run;
      if (u + radius + 1 < width) run += src[u + radius + 1];
      if (u - radius >= 0) run -= src[u - radius];
    }
  }
  for (int u = 0; u < width; ++u) {
    double run = 0.0;
    for (int v = 0; v <= std::min(height - 1, radius); ++v) {
      run += rows[static_cast<size_t>(v) * width + u];
    }
    for (int v = 0; v < height; ++v) {
      out[static_cast<size_t>(v) * width + u] =
          run / std::sqrt(static_cast<double>(count(u, width)) * count(v, height));
      if (v + radius + 1 < height) run += rows[static_cast<size_t>(v + radius + 1) * width + u];
      if (v - radius >= 0) run -= rows[static_cast<size_t>(v - radius) * width + u];
    }
  }
  return out;
}

}  // namespace

std::vector<KinectNoiseModel::PixelDraw> KinectNoiseModel::Draws(std::uint64_t seed, int width,
                                                                 int height) const {
  std::vector<PixelDraw> out;
  if (width <= 0 || height <= 0) return out;
  const size_t n = static_cast<size_t>(width) * height;
  out.resize(n);
  if (!options_.noise_enabled) return out;
  for (size_t i = 0; i < n; ++i) out[i] = Draw(seed, i);
  const double share = options_.correlated_share;
  if (!(share > 0.0)) return out;
  // The fields' own unit normals: three more of the same hash's streams (Draw uses 1-4).
  std::vector<double> own[3];
  for (std::vector<double>& o : own) o.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const std::uint64_t state = PixelState(seed, i);
    const double r1 = std::sqrt(-2.0 * std::log(UnitOpen(SplitMix64(state + 5))));
    const double r2 = std::sqrt(-2.0 * std::log(UnitOpen(SplitMix64(state + 7))));
    const double a1 = kTwoPi * UnitOpen(SplitMix64(state + 6));
    own[0][i] = r1 * std::cos(a1);
    own[1][i] = r1 * std::sin(a1);
    own[2][i] = r2 * std::cos(kTwoPi * UnitOpen(SplitMix64(state + 8)));
  }
  const int radius = options_.correlation_radius_px;
  const std::vector<double> du = WindowField(own[0], width, height, radius);
  const std::vector<double> dv = WindowField(own[1], width, height, radius);
  const std::vector<double> axial = WindowField(own[2], width, height, radius);
  const double a = std::sqrt(1.0 - share), b = std::sqrt(share);
  const double lateral = options_.lateral_sigma_px;
  for (size_t i = 0; i < n; ++i) {
    PixelDraw& d = out[i];
    d.du_px = a * d.du_px + b * lateral * du[i];
    d.dv_px = a * d.dv_px + b * lateral * dv[i];
    d.axial_normal = a * d.axial_normal + b * axial[i];
  }
  return out;
}

std::uint16_t KinectNoiseModel::Measure(double z_m, double incidence_rad,
                                        double axial_normal) const {
  if (!std::isfinite(z_m) || z_m <= 0.0) return 0;
  if (!(incidence_rad <= options_.max_incidence_rad)) return 0;
  double z = z_m;
  if (options_.noise_enabled) {
    z += axial_normal * AxialSigma(z_m);
    if (options_.quantise_disparity) {
      if (z <= 0.0) return 0;
      z = DepthFromRaw(RawFromDepth(z));
    }
  }
  if (!(z >= options_.min_range_m && z <= options_.max_range_m)) return 0;
  const double mm = std::round(z * 1000.0);
  return static_cast<std::uint16_t>(std::clamp(mm, 0.0, 65535.0));
}

int KinectNoiseModel::RawFromDepth(double z_m) {
  const double raw = std::round((1.0 / z_m - kRawOffset) / kRawScale);
  return static_cast<int>(std::clamp(raw, 0.0, static_cast<double>(kMaxValidRaw)));
}

double KinectNoiseModel::DepthFromRaw(int raw) {
  if (raw < 0 || raw > kMaxValidRaw) return 0.0;
  return 1.0 / (raw * kRawScale + kRawOffset);
}

}  // namespace hpose
