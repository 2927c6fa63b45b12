// The reference evaluation of the refinement's objective: every quantity recomputed at every
// pose, straight from the template, the cluster and the range image.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/search/refine_objective.h"

namespace hpose {
namespace {

// The template's surface as the sensor sees it at a pose: its points placed in the ground frame
// and a z-buffer of them in the sensor's view (bins of 1.5 surface cells at the template's
// distance) that keeps the nearest point of each bin, so hidden surface (the back, a torso behind
// an arm) takes no part.
class ModelView {
 public:
  ModelView(const SurfaceModel& model, const Pose2D& pose, const Eigen::Isometry3d& s_from_g)
      : model_(model), c_(std::cos(pose.theta)), s_(std::sin(pose.theta)) {
    const std::vector<Eigen::Vector3f>& pts = model.points();
    rotated_.resize(pts.size());
    in_sensor_.resize(pts.size());
    const Eigen::Vector3d t(pose.x, pose.y, 0.0);
    for (size_t i = 0; i < pts.size(); ++i) {
      const Eigen::Vector3d m = pts[i].cast<double>();
      rotated_[i] = refine_terms::RotateZ(c_, s_, m);
      in_sensor_[i] = s_from_g * (rotated_[i] + t);
    }
    const Eigen::Vector3d centre = s_from_g * (Rotate(model.centre().cast<double>()) + t);
    bin_ = 1.5 * model.spacing_m() / std::max(0.3, centre.norm());
    lo_ = Eigen::Vector2i(1 << 29, 1 << 29);
    Eigen::Vector2i hi(-(1 << 29), -(1 << 29));
    for (const Eigen::Vector3d& p : in_sensor_) {
      if (!(p.z() > refine_terms::kMinViewDepth)) continue;
      const Eigen::Vector2i b = Bin(p);
      lo_ = lo_.cwiseMin(b);
      hi = hi.cwiseMax(b);
    }
    if (lo_.x() > hi.x()) return;
    w_ = hi.x() - lo_.x() + 1;
    h_ = hi.y() - lo_.y() + 1;
    if (static_cast<long>(w_) * h_ > 4000000L) {  // degenerate geometry: nothing visible.
      w_ = h_ = 0;
      return;
    }
    winner_.assign(static_cast<size_t>(w_) * h_, -1);
    for (size_t i = 0; i < in_sensor_.size(); ++i) {
      if (!(in_sensor_[i].z() > refine_terms::kMinViewDepth)) continue;
      int& wi = winner_[Index(Bin(in_sensor_[i]))];
      if (wi < 0 || in_sensor_[i].z() < in_sensor_[wi].z()) wi = static_cast<int>(i);
    }
    for (int wi : winner_) {
      if (wi >= 0) visible_.push_back(wi);
    }
  }

  // The visible template point nearest to cluster point `d` (refine_terms::AssociationDistance)
  // among the bins around its ray, within its gate, or -1.
  int Associate(const refine_terms::DataPoint& d, const RefineOptions& o) const {
    const Eigen::Vector3d& p_sensor = d.ps;
    if (w_ == 0 || !(p_sensor.z() > refine_terms::kMinViewDepth)) return -1;
    const Eigen::Vector2i b = Bin(p_sensor) - lo_;
    int best = -1;
    double best_dist = std::numeric_limits<double>::infinity();
    for (int y = std::max(0, b.y() - 1); y <= std::min(h_ - 1, b.y() + 1); ++y) {
      for (int x = std::max(0, b.x() - 1); x <= std::min(w_ - 1, b.x() + 1); ++x) {
        const int wi = winner_[static_cast<size_t>(y) * w_ + x];
        if (wi < 0) continue;
        const Eigen::Vector3d off = in_sensor_[wi] - p_sensor;
        const double d2 = off.x() * off.x() + off.y() * off.y() + off.z() * off.z();
        if (!(d2 < d.gate * d.gate)) continue;
        const double dist = refine_terms::AssociationDistance(d, off.x(), off.y(), off.z(), d2, o);
        if (dist < best_dist) {
          best_dist = dist;
          best = wi;
        }
      }
    }
    return best;
  }

  Eigen::Vector3d Rotate(const Eigen::Vector3d& v) const {
    return refine_terms::RotateZ(c_, s_, v);
  }
  // Point i rotated into the ground frame's axes (not translated), and in the sensor frame.
  const Eigen::Vector3d& rotated(int i) const { return rotated_[i]; }
  const Eigen::Vector3d& in_sensor(int i) const { return in_sensor_[i]; }
  Eigen::Vector3d normal_ground(int i) const { return Rotate(model_.normals()[i].cast<double>()); }
  const std::vector<int>& visible() const { return visible_; }
  double c() const { return c_; }
  double s() const { return s_; }

 private:
  Eigen::Vector2i Bin(const Eigen::Vector3d& p) const {
    return Eigen::Vector2i(static_cast<int>(std::floor(p.x() / p.z() / bin_)),
                           static_cast<int>(std::floor(p.y() / p.z() / bin_)));
  }
  size_t Index(const Eigen::Vector2i& b) const {
    return static_cast<size_t>(b.y() - lo_.y()) * w_ + (b.x() - lo_.x());
  }

  const SurfaceModel& model_;
  double c_, s_;
  double bin_ = 0.01;
  std::vector<Eigen::Vector3d> rotated_, in_sensor_;
  Eigen::Vector2i lo_;
  int w_ = 0, h_ = 0;
  std::vector<int> winner_;
  std::vector<int> visible_;
};

}  // namespace

Linearisation LineariseReference(const SurfaceModel& model, const Observation& obs,
                                 const Pose2D& pose, const RefineOptions& o) {
  Linearisation lin;
  PoseEvidence& ev = lin.evidence;
  const Eigen::Matrix3d a = obs.sensor_from_ground.linear();
  const ModelView view(model, pose, obs.sensor_from_ground);

  // Cluster points to the visible template surface (point to plane).
  const std::vector<Eigen::Vector3f>& data = *obs.cluster_points;
  const size_t stride = refine_terms::DataStride(data.size(), o);
  for (size_t k = 0; k < data.size(); k += stride) {
    const refine_terms::DataPoint d =
        refine_terms::MakeDataPoint(data[k], obs.sensor_from_ground, o);
    ++ev.data_points;
    const int idx = view.Associate(d, o);
    if (idx < 0) {
      ev.cost += d.unexplained_cost;
      continue;
    }
    refine_terms::AddDataTerm(d, pose, view.rotated(idx), view.normal_ground(idx), a, o, &lin);
  }

  // Visible template points against what the sensor saw along their rays.
  const std::vector<std::uint8_t>& limbs = model.free_limb_marks();
  for (int i : view.visible()) {
    const Eigen::Vector3d& ps = view.in_sensor(i);
    if (!obs.range->Covers(ps)) {
      ++ev.model_out_of_view;
      continue;
    }
    refine_terms::AddViewTerm(obs.range->NearestAround(ps, 1), ps.z(), view.c(), view.s(),
                              model.points()[i].cast<double>(), !limbs.empty() && limbs[i] != 0, a,
                              o, &lin);
  }
  return lin;
}

}  // namespace hpose
