#ifndef HPOSE_CORE_SEARCH_REFINE_OBJECTIVE_H_
#define HPOSE_CORE_SEARCH_REFINE_OBJECTIVE_H_

#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/pose2d.h"
#include "core/search/pose_refiner.h"
#include "core/search/prepared_cluster.h"
#include "core/search/refine_terms.h"
#include "core/search/surface_model.h"
#include "core/search/template_projector.h"

namespace hpose {

// The refinement's objective for one template on one observation, prepared once so that each
// pose only costs what depends on it. At construction: the cluster's side (PreparedCluster:
// the points' sensor-frame positions, rays, noise, association gates and unexplained costs),
// unless the observation brings it, and the template's points (TemplateProjector). Per pose: the
// projector's z-buffer, the visible points packed with their positions, then the terms in the
// reference's order, stopping as soon as the cost exceeds the caller's bound. Every decision (bin,
// winner, association, class of a visible point) and every term is computed with the reference's
// arithmetic, so the result equals LineariseReference's (to the bit on x86-64).
//
// Keeps references to `model` and `obs` (and what it points to): they must outlive it. Not
// thread-safe (one objective per refinement).
class RefineObjective {
 public:
  RefineObjective(const SurfaceModel& model, const Observation& obs, const RefineOptions& options);

  // The linearisation at `pose`. Every term of the cost is non-negative, so once the running
  // cost exceeds `stop_above` the full cost would too: it stops there and returns what it has
  // with `complete` false (a step that would be rejected anyway).
  Linearisation Linearise(const Pose2D& pose,
                          double stop_above = std::numeric_limits<double>::infinity());

 private:
  // Places the template at `pose` in the sensor's view and fills the z-buffer; false when
  // nothing of it is visible.
  bool Project(const Pose2D& pose);
  // The visible template point (its slot in visible_) nearest to cluster point k among the bins
  // around its ray, within its gate, or -1.
  int Associate(size_t k) const;

  const SurfaceModel& model_;
  const Observation& obs_;
  RefineOptions options_;
  Eigen::Matrix3d a_;  // sensor_from_ground rotation.

  // The cluster's side: the observation's own when it matches the options, else made here.
  std::optional<PreparedCluster> own_cluster_;
  const PreparedCluster* cluster_;

  // Per pose: the heading's cos and sin, the template's z-buffer and its extent (the entries
  // rewritten to slots of visible_), and the visible points.
  TemplateProjector projector_;
  double c_ = 1.0, s_ = 0.0;
  double bin_ = 0.01, inv_bin_ = 100.0;
  struct VisiblePoint {
    double x, y, z;  // sensor frame.
    int index;       // in the template's points.
  };
  std::vector<VisiblePoint> visible_;
};

// The same linearisation computed directly from `model` and `obs` at `pose`, everything
// recomputed: the reference RefineObjective is tested against (and what
// RefineOptions::reference_evaluation runs).
Linearisation LineariseReference(const SurfaceModel& model, const Observation& obs,
                                 const Pose2D& pose, const RefineOptions& o);

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_REFINE_OBJECTIVE_H_
