#include "core/search/view_comparison.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "core/search/refine_terms.h"
#include "core/search/template_projector.h"

namespace hpose {
namespace {

// The template's surface at a pose in the sensor frame: its points, and the normal of any of
// them on demand (only the z-buffer's winners need one). Placed as `sensor_from_ground *
// (RotateZ(m) + t)`, the arithmetic of ViewTransform (TemplateProjector), so that the reference
// and the projector's evaluation agree to the bit.
struct PlacedSurface {
  const SurfaceModel* model = nullptr;
  double c = 1.0, s = 0.0;                          // the heading's cos and sin.
  Eigen::Matrix3d a = Eigen::Matrix3d::Identity();  // sensor_from_ground rotation.
  std::vector<Eigen::Vector3d> points;

  Eigen::Vector3d Normal(int i) const { return SensorNormal(a, c, s, model->normals()[i]); }

  static Eigen::Vector3d SensorNormal(const Eigen::Matrix3d& a, double c, double s,
                                      const Eigen::Vector3f& n) {
    return a * refine_terms::RotateZ(c, s, n.cast<double>());
  }
};

PlacedSurface Place(const SurfaceModel& model, const Pose2D& pose,
                    const Eigen::Isometry3d& sensor_from_ground) {
  PlacedSurface out;
  out.model = &model;
  out.c = std::cos(pose.theta);
  out.s = std::sin(pose.theta);
  out.a = sensor_from_ground.linear();
  const Eigen::Vector3d t(pose.x, pose.y, 0.0);
  out.points.reserve(model.points().size());
  for (const Eigen::Vector3f& p : model.points()) {
    out.points.push_back(sensor_from_ground *
                         (refine_terms::RotateZ(out.c, out.s, p.cast<double>()) + t));
  }
  return out;
}

// A pose's z-buffer as the projector made it (its winners over its window) and the extent of the
// bins its points fall in (empty: lo > hi).
struct ProjectedWinners {
  std::vector<int> winner;
  int lo_x = 0, lo_y = 0, w = 0, h = 0;
  Eigen::Vector2i lo = Eigen::Vector2i::Constant(1 << 29);
  Eigen::Vector2i hi = Eigen::Vector2i::Constant(-(1 << 29));
};

ProjectedWinners ProjectWinners(TemplateProjector* projector, const ViewTransform& view,
                                double bin) {
  ProjectedWinners out;
  if (!projector->Project(view, bin)) return out;
  out.winner = projector->winner();
  out.lo_x = projector->lo_x();
  out.lo_y = projector->lo_y();
  out.w = projector->w();
  out.h = projector->h();
  // Every point in front of the sensor lands in a bin, and every bin with a point has a winner.
  for (int j = 0; j < out.h; ++j) {
    for (int i = 0; i < out.w; ++i) {
      if (out.winner[static_cast<size_t>(j) * out.w + i] < 0) continue;
      const Eigen::Vector2i c(out.lo_x + i, out.lo_y + j);
      out.lo = out.lo.cwiseMin(c);
      out.hi = out.hi.cwiseMax(c);
    }
  }
  return out;
}

// The rays both poses are judged on: a grid of ray slopes (x / z, y / z) over what either pose
// covers (with a margin for the poses to move), each ray with what the sensor saw along it.
class RaySet {
 public:
  // Over the bins [lo, hi] (inclusive) grown by `margin_bins` on every side; empty when lo > hi
  // or the grid would be degenerate (millions of bins).
  RaySet(double bin, const Eigen::Vector2i& lo, const Eigen::Vector2i& hi, int margin_bins)
      : bin_(bin) {
    if (lo.x() > hi.x() || lo.y() > hi.y()) return;
    lo_ = lo - Eigen::Vector2i::Constant(margin_bins);
    w_ = hi.x() - lo.x() + 1 + 2 * margin_bins;
    h_ = hi.y() - lo.y() + 1 + 2 * margin_bins;
    if (static_cast<long>(w_) * h_ > 4000000L) w_ = h_ = 0;  // degenerate: nothing to compare.
  }

  // The bins of a placed surface's points in front of the sensor: grows [lo, hi] to them.
  static void Extend(double bin, const PlacedSurface& s, Eigen::Vector2i* lo, Eigen::Vector2i* hi) {
    for (const Eigen::Vector3d& p : s.points) {
      if (!(p.z() > 0.05)) continue;
      const Eigen::Vector2i c = Bin(p, bin);
      *lo = lo->cwiseMin(c);
      *hi = hi->cwiseMax(c);
    }
  }

  // Bin of each grid cell's nearest point of `s` (-1: none).
  std::vector<int> ZBuffer(const PlacedSurface& s) const {
    std::vector<int> winner(static_cast<size_t>(w_) * h_, -1);
    for (size_t i = 0; i < s.points.size(); ++i) {
      const Eigen::Vector3d& p = s.points[i];
      if (!(p.z() > 0.05)) continue;
      const Eigen::Vector2i c = Bin(p, bin_) - lo_;
      if (c.x() < 0 || c.y() < 0 || c.x() >= w_ || c.y() >= h_) continue;
      int& wi = winner[static_cast<size_t>(c.y()) * w_ + c.x()];
      if (wi < 0 || p.z() < s.points[wi].z()) wi = static_cast<int>(i);
    }
    return winner;
  }

  // The same from a projector's z-buffer (the same bins and winners).
  std::vector<int> ZBuffer(const ProjectedWinners& p) const {
    std::vector<int> winner(static_cast<size_t>(w_) * h_, -1);
    for (int k = 0; k < size(); ++k) {
      const int bx = BinX(k) - p.lo_x, by = BinY(k) - p.lo_y;
      if (bx >= 0 && by >= 0 && bx < p.w && by < p.h) {
        winner[k] = p.winner[static_cast<size_t>(by) * p.w + bx];
      }
    }
    return winner;
  }

  int size() const { return w_ * h_; }
  double bin() const { return bin_; }
  // The bin (floor(x / z / bin), floor(y / z / bin)) of cell k.
  int BinX(int k) const { return lo_.x() + k % w_; }
  int BinY(int k) const { return lo_.y() + k / w_; }
  // The ray through cell k's centre, scaled to z = 1.
  Eigen::Vector3d Ray(int k) const {
    return Eigen::Vector3d((lo_.x() + k % w_ + 0.5) * bin_, (lo_.y() + k / w_ + 0.5) * bin_, 1.0);
  }

 private:
  static Eigen::Vector2i Bin(const Eigen::Vector3d& p, double bin) {
    return Eigen::Vector2i(static_cast<int>(std::floor(p.x() / p.z() / bin)),
                           static_cast<int>(std::floor(p.y() / p.z() / bin)));
  }

  double bin_;
  Eigen::Vector2i lo_ = Eigen::Vector2i::Zero();
  int w_ = 0, h_ = 0;
};

// Depth (z) where `ray` (z = 1) meets the plane through p with normal n; p's own depth where
// the plane is nearly parallel to the ray, and never more than `reach` from it.
double ExpectedDepth(const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Eigen::Vector3d& ray,
                     double reach) {
  const double nq = n.dot(ray);
  if (std::abs(nq) < 0.2 * ray.norm()) return p.z();
  return std::clamp(n.dot(p) / nq, p.z() - reach, p.z() + reach);
}

// The derivative of ExpectedDepth(p, n, ray, reach) with respect to the pose (x, y, theta), given
// those of p and n (columns: x, y, theta), by the same cases.
Eigen::Vector3d ExpectedDepthGradient(const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                                      const Eigen::Matrix3d& dp, const Eigen::Matrix3d& dn,
                                      const Eigen::Vector3d& ray, double reach) {
  const double nq = n.dot(ray);
  if (std::abs(nq) < 0.2 * ray.norm()) return dp.row(2).transpose();
  const double z = n.dot(p) / nq;
  if (z < p.z() - reach || z > p.z() + reach) return dp.row(2).transpose();  // clamped.
  const Eigen::Vector3d dnp = dn.transpose() * p + dp.transpose() * n;
  return (dnp - z * (dn.transpose() * ray)) / nq;
}

// One observed ray: its cell, what the sensor saw along it and whether that return lies on
// either pose's surface or nearer (foreground) rather than behind both (background).
struct ObservedRay {
  int cell = 0;
  Eigen::Vector3d ray;
  double depth = 0.0, var = 0.0;
  bool foreground = false;
};

// A ray's covering point at a pose: its index in the template, its position and normal (sensor
// frame) and the ray's depth residual there.
struct CoveredRay {
  int index = -1;
  Eigen::Vector3d p, n;
  double residual = 0.0;
};

// Gauss-Newton normal equations of (x, y, theta).
struct NormalEquations {
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
};

// What the rays cost a pose, ray by ray: a truncated Gaussian of the depth residual where the
// pose covers the ray; where it does not, nothing for a background return and the truncation
// for a foreground one (a return it does not explain).
class RayCosts {
 public:
  // `bias`: how far the returns lie behind the surface they hit on average, in sigmas (the
  // range image keeps the nearest of the returns in a bin, which lies nearer than the surface).
  // `projected`: z-buffers the projector already made (at their poses, with the grid's bin),
  // used instead of projecting those poses again.
  RayCosts(const SurfaceModel& model, const Observation& obs, const RaySet& grid,
           std::vector<ObservedRay> rays, double t_max, double bias, bool reference,
           TemplateProjector projector, std::vector<std::pair<Pose2D, ProjectedWinners>> projected)
      : model_(model),
        obs_(obs),
        grid_(grid),
        rays_(std::move(rays)),
        t_max_(t_max),
        bias_(bias),
        reference_(reference),
        projector_(std::move(projector)),
        projected_(std::move(projected)) {}

  std::vector<double> PerRay(const Pose2D& pose) const {
    std::vector<double> cost(rays_.size());
    ForEachRay(pose, [&](size_t k, double c, const CoveredRay*) { cost[k] = c; });
    return cost;
  }

  // Poses evaluated so far (PerRay and Total calls).
  int evaluations() const { return evaluations_; }

  // The total cost at `pose`; with `lin`, also its Gauss-Newton normal equations.
  // With `per_ray`, also each ray's cost (as PerRay).
  double Total(const Pose2D& pose, NormalEquations* lin = nullptr,
               std::vector<double>* per_ray = nullptr) const {
    double sum = 0.0;
    const double c = std::cos(pose.theta), s = std::sin(pose.theta);
    if (per_ray != nullptr) per_ray->assign(rays_.size(), 0.0);
    ForEachRay(pose, [&](size_t k, double cost, const CoveredRay* hit) {
      sum += cost;
      if (per_ray != nullptr) (*per_ray)[k] = cost;
      if (lin != nullptr && hit != nullptr) AddTerm(rays_[k], *hit, c, s, lin);
    });
    return sum;
  }

  // The pose of least total cost near `start` by Gauss-Newton steps on the depth residuals
  // (their derivatives through the expected depth of each covered ray), each kept within the
  // options' bounds around `start` and taken only when it lowers the cost. A step that does not
  // is halved; a second refusal ends the settle: the z-buffer makes the cost piecewise, and
  // below a millimetre its steps are noise.
  // `per_ray` receives the rays' costs at the pose returned (as PerRay), from the evaluation
  // that accepted it.
  std::pair<Pose2D, double> SettleByGaussNewton(const Pose2D& start, const ViewComparisonOptions& o,
                                                std::vector<double>* per_ray) const {
    NormalEquations lin;
    double cost = Total(start, &lin, per_ray);
    Pose2D pose = start;
    int refused = 0;
    double scale = 1.0;
    std::vector<double> trial_per_ray;
    for (int it = 0; it < o.settle_rounds && refused < 2; ++it) {
      Eigen::Matrix3d damped = lin.h;
      for (int k = 0; k < 3; ++k) damped(k, k) += 1e-3 * std::max(lin.h(k, k), 1e-9) + 1e-12;
      const Eigen::Vector3d step = scale * damped.ldlt().solve(-lin.g);
      if (!step.allFinite()) break;
      if ((std::hypot(step.x(), step.y()) < o.settle_converged_m &&
           std::abs(step.z()) < o.settle_converged_rad) ||
          step.dot(lin.h * step) < o.settle_converged_sigmas * o.settle_converged_sigmas) {
        break;
      }
      Eigen::Vector2d shift(pose.x + step.x() - start.x, pose.y + step.y() - start.y);
      if (shift.norm() > o.settle_shift_m) shift *= o.settle_shift_m / shift.norm();
      const double turn = std::clamp(AngleDiff(pose.theta + step.z(), start.theta),
                                     -o.settle_turn_rad, o.settle_turn_rad);
      const Pose2D next{start.x + shift.x(), start.y + shift.y(),
                        NormalizeAngle(start.theta + turn)};
      NormalEquations trial;
      const double trial_cost = Total(next, &trial, &trial_per_ray);
      if (trial_cost < cost) {
        pose = next;
        cost = trial_cost;
        lin = trial;
        per_ray->swap(trial_per_ray);
        refused = 0;
        scale = 1.0;
      } else {
        ++refused;
        scale *= 0.5;
      }
    }
    return {pose, cost};
  }

  // The pose of least total cost near `start` (pattern search on x, y, theta within the
  // options' bounds around `start`): each pose is judged where it fits the depth image best, so
  // the comparison tells shapes apart rather than how well two refinements happened to place
  // them. The search begins at `from` (cost `from_cost` when known, else NaN) with shift steps
  // of `first_step_m` (the turn steps in proportion).
  Pose2D SettleByPatternSearch(const Pose2D& start, const Pose2D& from, double from_cost,
                               double first_step_m, const ViewComparisonOptions& o) const {
    // Costs of the poses tried so far: a step back to where the search came from (the other
    // sign of the step it just took) is looked up, not evaluated again.
    std::vector<std::pair<Pose2D, double>> tried;
    if (!std::isnan(from_cost)) tried.emplace_back(from, from_cost);
    const auto cost = [&](const Pose2D& p) {
      for (const auto& [q, c] : tried) {
        if (q.x == p.x && q.y == p.y && q.theta == p.theta) return c;
      }
      tried.emplace_back(p, Total(p));
      return tried.back().second;
    };
    Pose2D best = from;
    double best_cost = cost(best);
    double step_m = first_step_m, step_rad = first_step_m * o.settle_turn_rad / o.settle_shift_m;
    for (int round = 0; round < o.settle_rounds; ++round) {
      bool moved = false;
      for (int dim = 0; dim < 3; ++dim) {
        for (const double sign : {-1.0, 1.0}) {
          Pose2D trial = best;
          if (dim == 0) trial.x += sign * step_m;
          if (dim == 1) trial.y += sign * step_m;
          if (dim == 2) trial.theta = NormalizeAngle(trial.theta + sign * step_rad);
          if (std::hypot(trial.x - start.x, trial.y - start.y) > o.settle_shift_m + 1e-9 ||
              std::abs(AngleDiff(trial.theta, start.theta)) > o.settle_turn_rad + 1e-9) {
            continue;
          }
          const double c = cost(trial);
          if (c < best_cost) {
            best_cost = c;
            best = trial;
            moved = true;
          }
        }
      }
      if (!moved) {
        step_m *= 0.5;
        step_rad *= 0.5;
        if (step_m < o.settle_min_step_m) break;  // settled to what the steps can tell.
      }
    }
    return best;
  }

 private:
  // The depth residual of ray r where the pose's nearest surface point along it is p with
  // normal n (the return's depth less the expected one and the returns' bias), and its cost.
  double Residual(const ObservedRay& r, const Eigen::Vector3d& p, const Eigen::Vector3d& n) const {
    return r.depth - ExpectedDepth(p, n, r.ray, 3.0 * grid_.bin() * r.depth) -
           bias_ * std::sqrt(r.var);
  }
  double CoveredCost(const ObservedRay& r, double e) const {
    return 0.5 * std::min(e * e / r.var, t_max_);
  }
  double UncoveredCost(const ObservedRay& r) const { return r.foreground ? 0.5 * t_max_ : 0.0; }

  // Adds covered ray r's term to the Gauss-Newton normal equations of the pose whose heading
  // has cos c and sin s, where the term is not truncated (beyond, the cost is flat).
  void AddTerm(const ObservedRay& r, const CoveredRay& hit, double c, double s,
               NormalEquations* lin) const {
    if (!(hit.residual * hit.residual < t_max_ * r.var)) return;
    const Eigen::Matrix3d a = obs_.sensor_from_ground.linear();
    const Eigen::Vector3d m_rot =
        refine_terms::RotateZ(c, s,
                              Eigen::Vector3d(projector_.mx(hit.index), projector_.my(hit.index),
                                              projector_.mz(hit.index)));
    const Eigen::Vector3d n_rot =
        refine_terms::RotateZ(c, s, model_.normals()[hit.index].cast<double>());
    Eigen::Matrix3d dp, dn;
    dp << a.col(0), a.col(1), a * Eigen::Vector3d(-m_rot.y(), m_rot.x(), 0.0);
    dn << Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
        a * Eigen::Vector3d(-n_rot.y(), n_rot.x(), 0.0);
    // d(residual) = -d(expected depth).
    const Eigen::Vector3d j =
        -ExpectedDepthGradient(hit.p, hit.n, dp, dn, r.ray, 3.0 * grid_.bin() * r.depth);
    lin->h += j * j.transpose() / r.var;
    lin->g += j * hit.residual / r.var;
  }

  // Calls f(k, cost of ray k, its covering point or nullptr) for every ray in order: from the
  // projector's z-buffer, or with the reference's placement and z-buffer over the rays' grid
  // (RefineOptions::reference_evaluation). Both give the same winners and the same arithmetic.
  template <typename F>
  void ForEachRay(const Pose2D& pose, F f) const {
    ++evaluations_;
    if (reference_) {
      const PlacedSurface s = Place(model_, pose, obs_.sensor_from_ground);
      const std::vector<int> winner = grid_.ZBuffer(s);
      for (size_t k = 0; k < rays_.size(); ++k) {
        const ObservedRay& r = rays_[k];
        const int w = winner[r.cell];
        if (w < 0) {
          f(k, UncoveredCost(r), nullptr);
          continue;
        }
        CoveredRay hit{w, s.points[w], s.Normal(w), 0.0};
        hit.residual = Residual(r, hit.p, hit.n);
        f(k, CoveredCost(r, hit.residual), &hit);
      }
      return;
    }
    const double c = std::cos(pose.theta), s = std::sin(pose.theta);
    const ViewTransform view(c, s, pose, obs_.sensor_from_ground);
    const ProjectedWinners* known = nullptr;
    for (const auto& [at, z] : projected_) {
      if (at.x == pose.x && at.y == pose.y && at.theta == pose.theta) known = &z;
    }
    if (known == nullptr) projector_.Project(view, grid_.bin());
    const std::vector<int>& winner = known ? known->winner : projector_.winner();
    const int w = known ? known->w : projector_.w(), h = known ? known->h : projector_.h();
    const int lo_x = known ? known->lo_x : projector_.lo_x();
    const int lo_y = known ? known->lo_y : projector_.lo_y();
    const Eigen::Matrix3d a = obs_.sensor_from_ground.linear();
    for (size_t k = 0; k < rays_.size(); ++k) {
      const ObservedRay& r = rays_[k];
      const int bx = grid_.BinX(r.cell) - lo_x;
      const int by = grid_.BinY(r.cell) - lo_y;
      const int i =
          bx >= 0 && by >= 0 && bx < w && by < h ? winner[static_cast<size_t>(by) * w + bx] : -1;
      if (i < 0) {
        f(k, UncoveredCost(r), nullptr);
        continue;
      }
      CoveredRay hit{i, Eigen::Vector3d::Zero(),
                     PlacedSurface::SensorNormal(a, c, s, model_.normals()[i]), 0.0};
      view.Apply(projector_.mx(i), projector_.my(i), projector_.mz(i), &hit.p.x(), &hit.p.y(),
                 &hit.p.z());
      hit.residual = Residual(r, hit.p, hit.n);
      f(k, CoveredCost(r, hit.residual), &hit);
    }
  }

  const SurfaceModel& model_;
  const Observation& obs_;
  const RaySet& grid_;
  std::vector<ObservedRay> rays_;
  double t_max_;
  double bias_;
  bool reference_;
  mutable TemplateProjector projector_;  // scratch of ForEachRay.
  std::vector<std::pair<Pose2D, ProjectedWinners>> projected_;
  mutable int evaluations_ = 0;
};

}  // namespace

ViewComparison CompareViews(const SurfaceModel& model, const Observation& obs, const Pose2D& a,
                            const Pose2D& b, const RefineOptions& noise,
                            const ViewComparisonOptions& options) {
  ViewComparison out;
  if (obs.range == nullptr || model.points().empty()) return out;
  const Eigen::Vector3d centre =
      obs.sensor_from_ground * Eigen::Vector3d(a.x, a.y, model.centre().z());
  const double bin = 1.5 * model.spacing_m() / std::max(0.3, centre.norm());
  // Room for the poses to settle: their largest shift seen from the nearest distance.
  const int margin =
      2 + static_cast<int>(std::ceil(options.settle_shift_m / (bin * std::max(0.3, centre.z()))));
  // The grid over both poses' bins and their z-buffers on it: with the reference, every point
  // placed and binned directly; else from the projector, which gives the same bins and winners.
  const double cos_a = std::cos(a.theta), sin_a = std::sin(a.theta);
  const double cos_b = std::cos(b.theta), sin_b = std::sin(b.theta);
  const ViewTransform view_a(cos_a, sin_a, a, obs.sensor_from_ground);
  const ViewTransform view_b(cos_b, sin_b, b, obs.sensor_from_ground);
  TemplateProjector projector(model);
  std::optional<RaySet> grid_storage;
  std::vector<int> wa, wb;
  // Both poses' z-buffers: the settles begin at them.
  std::vector<std::pair<Pose2D, ProjectedWinners>> projected;
  if (noise.reference_evaluation) {
    const PlacedSurface pa = Place(model, a, obs.sensor_from_ground);
    const PlacedSurface pb = Place(model, b, obs.sensor_from_ground);
    Eigen::Vector2i lo = Eigen::Vector2i::Constant(1 << 29);
    Eigen::Vector2i hi = Eigen::Vector2i::Constant(-(1 << 29));
    RaySet::Extend(bin, pa, &lo, &hi);
    RaySet::Extend(bin, pb, &lo, &hi);
    grid_storage.emplace(bin, lo, hi, margin);
    wa = grid_storage->ZBuffer(pa);
    wb = grid_storage->ZBuffer(pb);
  } else {
    projected.emplace_back(a, ProjectWinners(&projector, view_a, bin));
    projected.emplace_back(b, ProjectWinners(&projector, view_b, bin));
    const ProjectedWinners& za = projected[0].second;
    const ProjectedWinners& zb = projected[1].second;
    grid_storage.emplace(bin, za.lo.cwiseMin(zb.lo), za.hi.cwiseMax(zb.hi), margin);
    wa = grid_storage->ZBuffer(za);
    wb = grid_storage->ZBuffer(zb);
  }
  const RaySet& grid = *grid_storage;
  if (grid.size() == 0) return out;
  const Eigen::Matrix3d rot = obs.sensor_from_ground.linear();
  // Where ray `ray` meets the surface of template point i at a pose (its position placed as
  // Place does, to the bit).
  const auto expected = [&](const ViewTransform& view, double c, double s, int i,
                            const Eigen::Vector3d& ray, double reach) {
    Eigen::Vector3d p;
    view.Apply(projector.mx(i), projector.my(i), projector.mz(i), &p.x(), &p.y(), &p.z());
    return ExpectedDepth(p, PlacedSurface::SensorNormal(rot, c, s, model.normals()[i]), ray, reach);
  };
  const double model_var = noise.model_sigma_m * noise.model_sigma_m;
  const double k = std::sqrt(options.max_squared_residual);
  std::vector<ObservedRay> rays;
  std::vector<double> shared;
  for (int cell = 0; cell < grid.size(); ++cell) {
    if (wa[cell] < 0 && wb[cell] < 0) continue;
    ObservedRay r;
    r.cell = cell;
    r.ray = grid.Ray(cell);
    r.depth = obs.range->DepthToward(r.ray);
    if (!(r.depth > 0.0)) continue;  // no return: says nothing about either pose.
    r.var = refine_terms::AxialVariance(r.depth, noise) + model_var;
    const double reach = 3.0 * bin * r.depth;
    const double za = wa[cell] >= 0 ? expected(view_a, cos_a, sin_a, wa[cell], r.ray, reach) : 0.0;
    const double zb = wb[cell] >= 0 ? expected(view_b, cos_b, sin_b, wb[cell], r.ray, reach) : 0.0;
    r.foreground = r.depth <= std::max({0.0, za, zb}) + k * std::sqrt(r.var);
    rays.push_back(r);
    // Normalised residuals where both poses see the same surface, for the returns' bias.
    if (wa[cell] >= 0 && wb[cell] >= 0) {
      for (const double z : {za, zb}) {
        const double u = (r.depth - z) / std::sqrt(r.var);
        if (std::abs(u) < k) shared.push_back(u);
      }
    }
  }
  // The returns' common offset from the surfaces, in sigmas (median): the same for both poses.
  double bias = 0.0;
  if (!shared.empty()) {
    std::nth_element(shared.begin(), shared.begin() + shared.size() / 2, shared.end());
    bias = shared[shared.size() / 2];
  }
  out.rays = static_cast<int>(rays.size());
  const RayCosts costs(model, obs, grid, std::move(rays), options.max_squared_residual, bias,
                       noise.reference_evaluation, std::move(projector), std::move(projected));
  // Settles a pose; its rays' costs there in `per_ray`.
  const auto settle = [&](const Pose2D& p, std::vector<double>* per_ray) {
    Pose2D settled = p;
    if (options.settle_rounds > 0 && options.settle_by_gauss_newton) {
      double cost = 0.0;
      std::tie(settled, cost) = costs.SettleByGaussNewton(p, options, per_ray);
      if (!(options.settle_polish_step_m > 0.0)) return settled;
      settled =
          costs.SettleByPatternSearch(p, settled, cost, options.settle_polish_step_m, options);
    } else if (options.settle_rounds > 0) {
      settled = costs.SettleByPatternSearch(p, p, std::numeric_limits<double>::quiet_NaN(),
                                            0.5 * options.settle_shift_m, options);
    }
    *per_ray = costs.PerRay(settled);
    return settled;
  };
  std::vector<double> ca, cb;
  const Pose2D pa = settle(a, &ca);
  const Pose2D pb = settle(b, &cb);
  double sum = 0.0, sum2 = 0.0;
  for (size_t i = 0; i < ca.size(); ++i) {
    out.cost_a += ca[i];
    out.cost_b += cb[i];
    const double diff = cb[i] - ca[i];
    sum += diff;
    sum2 += diff * diff;
  }
  out.log_likelihood_ratio = sum;
  if (out.rays > 1) {
    const double n = out.rays;
    const double mean = sum / n;
    const double var_diff = std::max(0.0, (sum2 - n * mean * mean) / (n - 1.0));
    out.sigma = std::sqrt(n * var_diff);
  }
  out.settled_a = pa;
  out.settled_b = pb;
  out.evaluations = costs.evaluations();
  return out;
}

}  // namespace hpose
