#include "core/search/template_projector.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/depth/point_lanes.h"
#include "core/search/refine_terms.h"

namespace hpose {

ViewTransform::ViewTransform(double cos_t, double sin_t, const Pose2D& pose,
                             const Eigen::Isometry3d& s_from_g)
    : c(cos_t), s(sin_t), px(pose.x), py(pose.y) {
  const Eigen::Matrix3d a = s_from_g.linear();
  a00 = a(0, 0), a01 = a(0, 1), a02 = a(0, 2);
  a10 = a(1, 0), a11 = a(1, 1), a12 = a(1, 2);
  a20 = a(2, 0), a21 = a(2, 1), a22 = a(2, 2);
  b0 = s_from_g.translation().x(), b1 = s_from_g.translation().y();
  b2 = s_from_g.translation().z();
}

namespace {

using refine_terms::kMinViewDepth;  // points nearer the optical plane are not seen.

// A z-buffer bin is floor(t / bin) of a ray slope t = x / z, divided as the reference does.
// Here the quotient q is approximated with one division per point (x * (1 / bin / z)), within
// a few units in the last place of the exact one (below 1e-9 for |q| < kApproxMaxBin), so both
// have the same floor unless q lies within kEdge of an integer: there, and beyond
// kApproxMaxBin, the exact quotients decide.
constexpr double kEdge = 1e-6;
constexpr double kApproxMaxBin = 1 << 20;
// Bins beyond this are degenerate geometry (a template point almost in the optical plane).
constexpr double kMaxBin = 1 << 28;
// A z-buffer with more bins than this is degenerate geometry too: nothing is visible.
constexpr long kMaxBins = 4000000L;

// floor(q) as an int, for |q| < kMaxBin.
inline int FloorToInt(double q) {
  const int i = static_cast<int>(q);
  return i - (q < static_cast<double>(i) ? 1 : 0);
}

// How far e = q - f lies inside [0, 1) beyond the edge margin, for the smaller of two (negative:
// too near an edge to trust the approximation, or f is not floor(q)).
inline double EdgeClearance(double ex, double ey) {
  return std::min(std::min(ex, ey) - kEdge, (1.0 - kEdge) - std::max(ex, ey));
}

// The bins a z-buffer spans (inclusive).
struct BinWindow {
  double lo_x, lo_y, hi_x, hi_y;
};

// The template's points (mx, my, mz) in the sensor frame: their depths (zs) and their z-buffer
// bins (bx, by) from approximate quotients, which are to be trusted where `ok` is positive: in
// front of the sensor, clear of a bin edge (EdgeClearance) and within `window`. Elsewhere the
// bins are meaningless (but defined). Branch-free over unaliased arrays, so that it vectorises:
// the floor is rounding to nearest of q - 1/2 (adding and taking away 1.5 * 2^52), which is
// floor(q) wherever the clearance is positive.
#define HPOSE_PLACE_IN_VIEW_PARAMS                                                           \
  int n, const float *__restrict mx, const float *__restrict my, const float *__restrict mz, \
      const ViewTransform &view, double inv_bin, BinWindow window, double *__restrict zs,    \
      int *__restrict bx, int *__restrict by, double *__restrict ok

[[gnu::always_inline]] inline void PlaceInViewLoop(HPOSE_PLACE_IN_VIEW_PARAMS) {
  constexpr double kRound = 6755399441055744.0;
  const ViewTransform v = view;
  const double min_z = kMinViewDepth;
  for (int i = 0; i < n; ++i) {
    double x, y, z;
    v.Apply(mx[i], my[i], mz[i], &x, &y, &z);
    const double r = inv_bin / std::max(z, min_z);
    const double qx = x * r, qy = y * r;
    const double fx = ((qx - 0.5) + kRound) - kRound;
    const double fy = ((qy - 0.5) + kRound) - kRound;
    // Clamped into the window (a NaN to its low end) so that the conversions are defined.
    const double cx = std::max(window.lo_x, std::min(fx, window.hi_x));
    const double cy = std::max(window.lo_y, std::min(fy, window.hi_y));
    const double inside = std::min(std::min(fx - window.lo_x, window.hi_x - fx),
                                   std::min(fy - window.lo_y, window.hi_y - fy)) +
                          0.5;
    zs[i] = z;
    bx[i] = static_cast<int>(cx);
    by[i] = static_cast<int>(cy);
    // NaN (from a NaN pose) stays NaN, so not positive.
    ok[i] = std::min(z - min_z, std::min(EdgeClearance(qx - fx, qy - fy), inside));
  }
}

void PlaceInViewBaseline(HPOSE_PLACE_IN_VIEW_PARAMS) {
  PlaceInViewLoop(n, mx, my, mz, view, inv_bin, window, zs, bx, by, ok);
}

// The same loop compiled for AVX2 (wider vectors, conversions to int) where the compiler can
// target it and the CPU has it: AVX2 does not fuse multiplies and adds, so the results are the
// same to the bit.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
[[gnu::target("avx2")]] void PlaceInViewAvx2(HPOSE_PLACE_IN_VIEW_PARAMS) {
  PlaceInViewLoop(n, mx, my, mz, view, inv_bin, window, zs, bx, by, ok);
}

// And for AVX-512 (eight doubles a vector): multiplies and adds stay unfused there too (the
// build turns contraction off), so the same bits again.
[[gnu::target("avx512f")]] void PlaceInViewAvx512(HPOSE_PLACE_IN_VIEW_PARAMS) {
  PlaceInViewLoop(n, mx, my, mz, view, inv_bin, window, zs, bx, by, ok);
}
#else
void PlaceInViewAvx2(HPOSE_PLACE_IN_VIEW_PARAMS) {
  PlaceInViewLoop(n, mx, my, mz, view, inv_bin, window, zs, bx, by, ok);
}
constexpr auto* PlaceInViewAvx512 = &PlaceInViewAvx2;
#endif

void PlaceInView(HPOSE_PLACE_IN_VIEW_PARAMS) {
  (PointLanesAvailable() ? PlaceInViewAvx512
   : PointLanes8Available()
       ? PlaceInViewAvx2
       : PlaceInViewBaseline)(n, mx, my, mz, view, inv_bin, window, zs, bx, by, ok);
}

#undef HPOSE_PLACE_IN_VIEW_PARAMS

// Points per block of the projection: its temporaries stay in the first-level cache.
constexpr int kBlock = 256;

// The bins of a template point in front of the sensor from the exact quotients, as the
// reference divides; false when out of range (degenerate geometry).
bool ExactBins(const ViewTransform& view, double bin, double mx, double my, double mz, int* bx,
               int* by) {
  double x, y, z;
  view.Apply(mx, my, mz, &x, &y, &z);
  const double qx = x / z / bin, qy = y / z / bin;
  if (!(std::abs(qx) < kMaxBin && std::abs(qy) < kMaxBin)) return false;
  *bx = FloorToInt(qx);
  *by = FloorToInt(qy);
  return true;
}

}  // namespace

int TemplateProjector::Bin(double q, double x, double z, double bin) {
  if (std::abs(q) < kApproxMaxBin) {
    const int b = FloorToInt(q);
    const double e = q - b;
    if (EdgeClearance(e, e) >= 0.0) return b;
  }
  return FloorToInt(x / z / bin);
}

TemplateProjector::TemplateProjector(const SurfaceModel& model)
    : mx_(model.xs().data()),
      my_(model.ys().data()),
      mz_(model.zs().data()),
      n_(static_cast<int>(model.xs().size())),
      box_lo_(model.box_lo()),
      box_hi_(model.box_hi()) {}

bool TemplateProjector::Project(const ViewTransform& view, double bin) {
  bin_ = bin;
  inv_bin_ = 1.0 / bin;
  w_ = h_ = 0;
  if (FillBounded(view) || FillTwoPasses(view)) return true;
  w_ = h_ = 0;
  winner_.clear();
  return false;
}

bool TemplateProjector::FillBounded(const ViewTransform& view) {
  // Every template point lies in its bounding box, and a ray slope (x / z) over a box in front
  // of the sensor is extreme at a corner: the corners bound the bins (one bin of margin for
  // rounding), so the points go into the z-buffer as they are placed.
  int lo[2] = {1 << 29, 1 << 29}, hi[2] = {-(1 << 29), -(1 << 29)};
  for (int corner = 0; corner < 8; ++corner) {
    double x, y, z;
    view.Apply(corner & 1 ? box_hi_.x() : box_lo_.x(), corner & 2 ? box_hi_.y() : box_lo_.y(),
               corner & 4 ? box_hi_.z() : box_lo_.z(), &x, &y, &z);
    if (!(z > kMinViewDepth + 1e-6)) return false;
    const double q[2] = {x / z * inv_bin_, y / z * inv_bin_};
    for (int k = 0; k < 2; ++k) {
      if (!(std::abs(q[k]) < kMaxBin)) return false;
      lo[k] = std::min(lo[k], FloorToInt(q[k]) - 1);
      hi[k] = std::max(hi[k], FloorToInt(q[k]) + 1);
    }
  }
  const int w = hi[0] - lo[0] + 1, h = hi[1] - lo[1] + 1;
  if (static_cast<long>(w) * h > kMaxBins) return false;
  winner_.assign(static_cast<size_t>(w) * h, -1);
  // The depth of each bin's winner beside it (no dependent load per point).
  winner_z_.assign(winner_.size(), std::numeric_limits<double>::infinity());
  int* winner = winner_.data();
  double* winner_z = winner_z_.data();
  const int n = n_;
  const BinWindow window{static_cast<double>(lo[0]), static_cast<double>(lo[1]),
                         static_cast<double>(hi[0]), static_cast<double>(hi[1])};
  // The block's depths stay in the first-level cache (a whole template's would not).
  double zs[kBlock];
  int bx[kBlock], by[kBlock];
  double ok[kBlock];
  for (int i0 = 0; i0 < n; i0 += kBlock) {
    const int m = std::min(kBlock, n - i0);
    PlaceInView(m, mx_ + i0, my_ + i0, mz_ + i0, view, inv_bin_, window, zs, bx, by, ok);
    for (int j = 0; j < m; ++j) {
      const int i = i0 + j;
      if (!(ok[j] > 0.0)) {
        if (!(zs[j] > kMinViewDepth)) continue;
        if (!ExactBins(view, bin_, mx_[i], my_[i], mz_[i], &bx[j], &by[j])) return false;
        if (bx[j] < lo[0] || by[j] < lo[1] || bx[j] > hi[0] || by[j] > hi[1]) {
          return false;  // not bounded after all.
        }
      }
      const size_t cell = static_cast<size_t>(by[j] - lo[1]) * w + (bx[j] - lo[0]);
      // As `winner < 0 || z < z of winner`: an empty bin's depth is infinite, z is finite.
      if (zs[j] < winner_z[cell]) {
        winner[cell] = i;
        winner_z[cell] = zs[j];
      }
    }
  }
  lo_x_ = lo[0];
  lo_y_ = lo[1];
  w_ = w;
  h_ = h;
  return true;
}

bool TemplateProjector::FillTwoPasses(const ViewTransform& view) {
  // The bins of every point and their extent first, then the z-buffer.
  const int n = n_;
  z_.resize(n);
  bx_.resize(n);
  by_.resize(n);
  const BinWindow window{-kApproxMaxBin, -kApproxMaxBin, kApproxMaxBin, kApproxMaxBin};
  double* zs = z_.data();
  int* bxs = bx_.data();
  int* bys = by_.data();
  double ok[kBlock];
  for (int i0 = 0; i0 < n; i0 += kBlock) {
    const int m = std::min(kBlock, n - i0);
    PlaceInView(m, mx_ + i0, my_ + i0, mz_ + i0, view, inv_bin_, window, zs + i0, bxs + i0,
                bys + i0, ok);
    for (int j = 0; j < m; ++j) {
      const int i = i0 + j;
      if (ok[j] > 0.0 || !(zs[i] > kMinViewDepth)) continue;
      if (!ExactBins(view, bin_, mx_[i], my_[i], mz_[i], &bxs[i], &bys[i])) return false;
    }
  }
  int lo_x = 1 << 29, lo_y = 1 << 29, hi_x = -(1 << 29), hi_y = -(1 << 29);
  for (int i = 0; i < n; ++i) {
    if (!(zs[i] > kMinViewDepth)) continue;
    lo_x = std::min(lo_x, bxs[i]);
    lo_y = std::min(lo_y, bys[i]);
    hi_x = std::max(hi_x, bxs[i]);
    hi_y = std::max(hi_y, bys[i]);
  }
  if (lo_x > hi_x) return false;
  const int w = hi_x - lo_x + 1, h = hi_y - lo_y + 1;
  if (static_cast<long>(w) * h > kMaxBins) return false;  // degenerate geometry.
  winner_.assign(static_cast<size_t>(w) * h, -1);
  int* winner = winner_.data();
  for (int i = 0; i < n; ++i) {
    if (!(zs[i] > kMinViewDepth)) continue;
    int& wi = winner[static_cast<size_t>(bys[i] - lo_y) * w + (bxs[i] - lo_x)];
    if (wi < 0 || zs[i] < zs[wi]) wi = i;
  }
  lo_x_ = lo_x;
  lo_y_ = lo_y;
  w_ = w;
  h_ = h;
  return true;
}

}  // namespace hpose
