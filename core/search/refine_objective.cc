#include "core/search/refine_objective.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hpose {

RefineObjective::RefineObjective(const SurfaceModel& model, const Observation& obs,
                                 const RefineOptions& options)
    : model_(model),
      obs_(obs),
      options_(options),
      a_(obs.sensor_from_ground.linear()),
      projector_(model) {
  const std::vector<Eigen::Vector3f>& points = *obs.cluster_points;
  if (obs.prepared != nullptr && obs.prepared->Matches(points, obs.sensor_from_ground, options_)) {
    cluster_ = obs.prepared;
  } else {
    own_cluster_.emplace(points, obs.sensor_from_ground, options_);
    cluster_ = &*own_cluster_;
  }
}

bool RefineObjective::Project(const Pose2D& pose) {
  c_ = std::cos(pose.theta);
  s_ = std::sin(pose.theta);
  visible_.clear();
  const Eigen::Isometry3d& s_from_g = obs_.sensor_from_ground;
  const Eigen::Vector3d t(pose.x, pose.y, 0.0);
  const Eigen::Vector3d centre =
      s_from_g * (refine_terms::RotateZ(c_, s_, model_.centre().cast<double>()) + t);
  bin_ = 1.5 * model_.spacing_m() / std::max(0.3, centre.norm());
  inv_bin_ = 1.0 / bin_;
  const ViewTransform view(c_, s_, pose, s_from_g);

  if (!projector_.Project(view, bin_)) return false;
  // The visible points, in the order of their bins, with their full sensor-frame position; the
  // z-buffer refers to them from now on.
  for (int& cell : projector_.winner()) {
    if (cell < 0) continue;
    VisiblePoint v;
    v.index = cell;
    view.Apply(projector_.mx(cell), projector_.my(cell), projector_.mz(cell), &v.x, &v.y, &v.z);
    cell = static_cast<int>(visible_.size());
    visible_.push_back(v);
  }
  return true;
}

int RefineObjective::Associate(size_t k) const {
  const int w = projector_.w(), h = projector_.h();
  if (w == 0 || !cluster_->in_front(k)) return -1;
  const refine_terms::DataPoint& d = cluster_->point(k);
  const Eigen::Vector3d& p = d.ps;
  const int bx =
      TemplateProjector::Bin(cluster_->tx(k) * inv_bin_, p.x(), p.z(), bin_) - projector_.lo_x();
  const int by =
      TemplateProjector::Bin(cluster_->ty(k) * inv_bin_, p.y(), p.z(), bin_) - projector_.lo_y();
  const double gate2 = d.gate * d.gate;
  int best = -1;
  double best_dist = std::numeric_limits<double>::infinity();
  const std::vector<int>& slots = projector_.winner();
  for (int y = std::max(0, by - 1); y <= std::min(h - 1, by + 1); ++y) {
    for (int x = std::max(0, bx - 1); x <= std::min(w - 1, bx + 1); ++x) {
      const int slot = slots[static_cast<size_t>(y) * w + x];
      if (slot < 0) continue;
      const VisiblePoint& v = visible_[slot];
      const double dx = v.x - p.x(), dy = v.y - p.y(), dz = v.z - p.z();
      const double d2 = dx * dx + dy * dy + dz * dz;
      if (!(d2 < gate2)) continue;
      const double dist = refine_terms::AssociationDistance(d, dx, dy, dz, d2, options_);
      if (dist < best_dist) {
        best_dist = dist;
        best = slot;
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

  // Cluster points to the visible template surface (point to plane). Each point's match is found
  // one point ahead of its term, and its template point and normal fetched meanwhile (they lie
  // at scattered indices, mostly beyond the first-level cache); the terms are added in order.
  const size_t n = cluster_->size();
  int slot = n > 0 ? Associate(0) : -1;
  for (size_t k = 0; k < n; ++k) {
    const int next = k + 1 < n ? Associate(k + 1) : -1;
    if (next >= 0) {
      const int j = visible_[next].index;
      __builtin_prefetch(&normals[j]);
      __builtin_prefetch(model_.xs().data() + j);
      __builtin_prefetch(model_.ys().data() + j);
      __builtin_prefetch(model_.zs().data() + j);
    }
    ++ev.data_points;
    const refine_terms::DataPoint& d = cluster_->point(k);
    if (slot < 0) {
      ev.cost += d.unexplained_cost;
    } else {
      const int idx = visible_[slot].index;
      const Eigen::Vector3d m(projector_.mx(idx), projector_.my(idx), projector_.mz(idx));
      refine_terms::AddDataTerm(d, pose, refine_terms::RotateZ(c_, s_, m),
                                refine_terms::RotateZ(c_, s_, normals[idx].cast<double>()), a_,
                                options_, &lin);
    }
    if (ev.cost > stop_above) {
      lin.complete = false;
      return lin;
    }
    slot = next;
  }

  // Visible template points against what the sensor saw along their rays.
  const RangeImage& range = *obs_.range;
  const std::vector<std::uint8_t>& limbs = model_.free_limb_marks();
  constexpr size_t kAhead = 4;  // visible points whose template point is fetched ahead.
  for (size_t slot = 0; slot < visible_.size(); ++slot) {
    if (slot + kAhead < visible_.size()) {
      const int j = visible_[slot + kAhead].index;
      __builtin_prefetch(model_.xs().data() + j);
      __builtin_prefetch(model_.ys().data() + j);
      __builtin_prefetch(model_.zs().data() + j);
    }
    const VisiblePoint& v = visible_[slot];
    const double tx = v.x / v.z, ty = v.y / v.z;
    if (!range.CoversRay(tx, ty)) {
      ++ev.model_out_of_view;
      continue;
    }
    const int i = v.index;
    refine_terms::AddViewTerm(range.NearestAroundRay(tx, ty, 1), v.z, c_, s_,
                              Eigen::Vector3d(projector_.mx(i), projector_.my(i), projector_.mz(i)),
                              !limbs.empty() && limbs[i] != 0, a_, options_, &lin);
    if (ev.cost > stop_above) {
      lin.complete = false;
      return lin;
    }
  }
  return lin;
}

}  // namespace hpose
