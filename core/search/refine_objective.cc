#include "core/search/refine_objective.h"

#include <algorithm>
#include <cmath>

namespace hpose {
namespace {

// A z-buffer bin is floor(t / bin) of a ray slope t = x / z, divided as the reference does.
// Here the quotient q is approximated with one division per point (x * (1 / bin / z)), within
// a few units in the last place of the exact one, so both have the same floor unless q lies
// within kEdge * (|q| + 1) of an integer: there the exact quotients decide.
constexpr double kEdge = 1e-9;
// Bins beyond this are degenerate geometry (a template point almost in the optical plane).
constexpr double kMaxBin = 1 << 28;

// floor(q) as an int, for |q| < kMaxBin.
inline int FloorToInt(double q) {
  const int i = static_cast<int>(q);
  return i - (q < static_cast<double>(i) ? 1 : 0);
}

// How far q is inside the bin [f, f + 1) beyond the edge margin (negative: too near an edge to
// trust the approximation, or f is not floor(q)).
inline double EdgeClearance(double q, double f) {
  const double margin = kEdge * (std::abs(q) + 1.0);
  const double e = q - f;
  return std::min(e - margin, (1.0 - margin) - e);
}

// floor(x / z / bin) from q, its approximation.
inline int BinOf(double q, double x, double z, double bin) {
  const int b = FloorToInt(q);
  return EdgeClearance(q, b) < 0.0 ? FloorToInt(x / z / bin) : b;
}

// Template frame to sensor frame at a pose: rotated about z by (c, s) = (cos, sin) of the
// heading, translated by (px, py), then through the mount (a, b), in the reference's order of
// operations so that the results are the same to the last bit.
struct ViewTransform {
  double c, s, px, py;
  double a00, a01, a02, a10, a11, a12, a20, a21, a22, b0, b1, b2;

  ViewTransform(double cos_t, double sin_t, const Pose2D& pose, const Eigen::Isometry3d& s_from_g)
      : c(cos_t), s(sin_t), px(pose.x), py(pose.y) {
    const Eigen::Matrix3d a = s_from_g.linear();
    a00 = a(0, 0), a01 = a(0, 1), a02 = a(0, 2);
    a10 = a(1, 0), a11 = a(1, 1), a12 = a(1, 2);
    a20 = a(2, 0), a21 = a(2, 1), a22 = a(2, 2);
    b0 = s_from_g.translation().x(), b1 = s_from_g.translation().y();
    b2 = s_from_g.translation().z();
  }

  void Apply(double mx, double my, double mz, double* x, double* y, double* z) const {
    const double gx = (c * mx - s * my) + px;
    const double gy = (s * mx + c * my) + py;
    const double gz = mz + 0.0;
    *x = a00 * gx + a01 * gy + a02 * gz + b0;
    *y = a10 * gx + a11 * gy + a12 * gz + b1;
    *z = a20 * gx + a21 * gy + a22 * gz + b2;
  }
};

// The template's points (mx, my, mz) in the sensor frame (x, y, z), their z-buffer bins from
// approximate quotients (fx, fy) and the bins' EdgeClearance (clear, the smaller of x and y);
// meaningless where z <= kMinViewDepth. Branch-free over unaliased arrays, so that it
// vectorises: the floor is rounding to nearest of q - 1/2 (adding and taking away 1.5 * 2^52),
// which is floor(q) wherever the clearance is positive.
void PlaceInView(int n, const float* __restrict mx, const float* __restrict my,
                 const float* __restrict mz, const ViewTransform& view, double inv_bin,
                 double* __restrict xs, double* __restrict ys, double* __restrict zs,
                 double* __restrict fxs, double* __restrict fys, double* __restrict clear) {
  constexpr double kRound = 6755399441055744.0;
  const ViewTransform v = view;
  const double min_z = refine_terms::kMinViewDepth;
  for (int i = 0; i < n; ++i) {
    double x, y, z;
    v.Apply(mx[i], my[i], mz[i], &x, &y, &z);
    const double r = inv_bin / std::max(z, min_z);
    const double qx = x * r, qy = y * r;
    const double fx = ((qx - 0.5) + kRound) - kRound;
    const double fy = ((qy - 0.5) + kRound) - kRound;
    xs[i] = x;
    ys[i] = y;
    zs[i] = z;
    fxs[i] = fx;
    fys[i] = fy;
    clear[i] = std::min(EdgeClearance(qx, fx), EdgeClearance(qy, fy));
  }
}

// Points per block of the projection: its temporaries stay in the first-level cache.
constexpr int kBlock = 256;

}  // namespace

RefineObjective::RefineObjective(const SurfaceModel& model, const Observation& obs,
                                 const RefineOptions& options)
    : model_(model), obs_(obs), options_(options), a_(obs.sensor_from_ground.linear()) {
  const std::vector<Eigen::Vector3f>& data = *obs.cluster_points;
  const size_t stride = refine_terms::DataStride(data.size(), options_);
  data_.reserve(data.size() / stride + 1);
  for (size_t k = 0; k < data.size(); k += stride) {
    const refine_terms::DataPoint d =
        refine_terms::MakeDataPoint(data[k], obs.sensor_from_ground, options_);
    const bool in_front = d.ps.z() > refine_terms::kMinViewDepth;
    data_.push_back(d);
    data_in_front_.push_back(in_front ? 1 : 0);
    data_tx_.push_back(in_front ? d.ps.x() / d.ps.z() : 0.0);
    data_ty_.push_back(in_front ? d.ps.y() / d.ps.z() : 0.0);
  }
  const std::vector<Eigen::Vector3f>& pts = model.points();
  const size_t n = pts.size();
  mx_.resize(n);
  my_.resize(n);
  mz_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    mx_[i] = pts[i].x();
    my_[i] = pts[i].y();
    mz_[i] = pts[i].z();
  }
  x_.resize(n);
  y_.resize(n);
  z_.resize(n);
  bx_.resize(n);
  by_.resize(n);
}

bool RefineObjective::Project(const Pose2D& pose) {
  c_ = std::cos(pose.theta);
  s_ = std::sin(pose.theta);
  visible_.clear();
  w_ = h_ = 0;
  const Eigen::Isometry3d& s_from_g = obs_.sensor_from_ground;
  const Eigen::Vector3d t(pose.x, pose.y, 0.0);
  const Eigen::Vector3d centre =
      s_from_g * (refine_terms::RotateZ(c_, s_, model_.centre().cast<double>()) + t);
  bin_ = 1.5 * model_.spacing_m() / std::max(0.3, centre.norm());
  inv_bin_ = 1.0 / bin_;
  const ViewTransform view(c_, s_, pose, s_from_g);

  // The template's depths and z-buffer bins (exact where near an edge), block by block, and
  // their extent over the points in front of the sensor.
  const double min_z = refine_terms::kMinViewDepth;
  const int n = static_cast<int>(mx_.size());
  double xb[kBlock], yb[kBlock], fxb[kBlock], fyb[kBlock], clearb[kBlock];
  double* zs = z_.data();
  int* bxs = bx_.data();
  int* bys = by_.data();
  int lo_x = 1 << 29, lo_y = 1 << 29, hi_x = -(1 << 29), hi_y = -(1 << 29);
  for (int i0 = 0; i0 < n; i0 += kBlock) {
    const int m = std::min(kBlock, n - i0);
    PlaceInView(m, mx_.data() + i0, my_.data() + i0, mz_.data() + i0, view, inv_bin_, xb, yb,
                zs + i0, fxb, fyb, clearb);
    for (int j = 0; j < m; ++j) {
      const int i = i0 + j;
      if (!(zs[i] > min_z)) continue;
      if (!(std::abs(fxb[j]) < kMaxBin && std::abs(fyb[j]) < kMaxBin)) return false;
      int bx = static_cast<int>(fxb[j]), by = static_cast<int>(fyb[j]);
      if (clearb[j] < 0.0) {
        bx = FloorToInt(xb[j] / zs[i] / bin_);
        by = FloorToInt(yb[j] / zs[i] / bin_);
      }
      bxs[i] = bx;
      bys[i] = by;
      lo_x = std::min(lo_x, bx);
      lo_y = std::min(lo_y, by);
      hi_x = std::max(hi_x, bx);
      hi_y = std::max(hi_y, by);
    }
  }
  if (lo_x > hi_x) return false;
  const int w = hi_x - lo_x + 1, h = hi_y - lo_y + 1;
  if (static_cast<long>(w) * h > 4000000L) return false;  // degenerate geometry.
  lo_x_ = lo_x;
  lo_y_ = lo_y;
  w_ = w;
  h_ = h;
  // Nearest point per bin; the first in order wins a tie.
  winner_.assign(static_cast<size_t>(w) * h, -1);
  int* winner = winner_.data();
  for (int i = 0; i < n; ++i) {
    if (!(zs[i] > min_z)) continue;
    int& wi = winner[static_cast<size_t>(bys[i] - lo_y) * w + (bxs[i] - lo_x)];
    if (wi < 0 || zs[i] < zs[wi]) wi = i;
  }
  // The visible points, with their full sensor-frame position.
  for (int wi : winner_) {
    if (wi < 0) continue;
    visible_.push_back(wi);
    double z;
    view.Apply(mx_[wi], my_[wi], mz_[wi], &x_[wi], &y_[wi], &z);
  }
  return true;
}

int RefineObjective::Associate(size_t k) const {
  if (w_ == 0 || !data_in_front_[k]) return -1;
  const Eigen::Vector3d& p = data_[k].ps;
  const int bx = BinOf(data_tx_[k] * inv_bin_, p.x(), p.z(), bin_) - lo_x_;
  const int by = BinOf(data_ty_[k] * inv_bin_, p.y(), p.z(), bin_) - lo_y_;
  const double gate = data_[k].gate;
  int best = -1;
  double best_d2 = gate * gate;
  for (int y = std::max(0, by - 1); y <= std::min(h_ - 1, by + 1); ++y) {
    for (int x = std::max(0, bx - 1); x <= std::min(w_ - 1, bx + 1); ++x) {
      const int wi = winner_[static_cast<size_t>(y) * w_ + x];
      if (wi < 0) continue;
      const double dx = x_[wi] - p.x(), dy = y_[wi] - p.y(), dz = z_[wi] - p.z();
      const double d2 = dx * dx + dy * dy + dz * dz;
      if (d2 < best_d2) {
        best_d2 = d2;
        best = wi;
      }
    }
  }
  return best;
}

Linearisation RefineObjective::Linearise(const Pose2D& pose, double stop_above) {
  Linearisation lin;
  PoseEvidence& ev = lin.evidence;
  Project(pose);
  const std::vector<Eigen::Vector3f>& normals = model_.normals();

  // Cluster points to the visible template surface (point to plane).
  for (size_t k = 0; k < data_.size(); ++k) {
    ++ev.data_points;
    const int idx = Associate(k);
    if (idx < 0) {
      ev.cost += data_[k].unexplained_cost;
    } else {
      const Eigen::Vector3d m(mx_[idx], my_[idx], mz_[idx]);
      refine_terms::AddDataTerm(data_[k], pose, refine_terms::RotateZ(c_, s_, m),
                                refine_terms::RotateZ(c_, s_, normals[idx].cast<double>()), a_,
                                options_, &lin);
    }
    if (ev.cost > stop_above) {
      lin.complete = false;
      return lin;
    }
  }

  // Visible template points against what the sensor saw along their rays.
  const RangeImage& range = *obs_.range;
  for (int i : visible_) {
    const double tx = x_[i] / z_[i], ty = y_[i] / z_[i];
    if (!range.CoversRay(tx, ty)) continue;
    refine_terms::AddViewTerm(range.NearestAroundRay(tx, ty, 1), z_[i], c_, s_,
                              Eigen::Vector3d(mx_[i], my_[i], mz_[i]), a_, options_, &lin);
    if (ev.cost > stop_above) {
      lin.complete = false;
      return lin;
    }
  }
  return lin;
}

}  // namespace hpose
