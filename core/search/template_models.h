#ifndef HPOSE_CORE_SEARCH_TEMPLATE_MODELS_H_
#define HPOSE_CORE_SEARCH_TEMPLATE_MODELS_H_

#include <memory>

#include "core/scoring/pose_lattice.h"

namespace hpose {

class SurfaceModel;

// What an Estimator prepares for one template before its first frame: the template's rotations
// under the search lattice (with the search tables they make, on first use or all at start) and
// its surface with normals for the refinement. Both are immutable once made (each table is made
// once, thread-safe), so one copy can serve every estimator of a process that searches the same
// lattice and refines on the same surface spacing (Estimator::Create's `shared`).
struct TemplateModels {
  PoseLattice lattice;             // what the rotations were made for.
  double surface_spacing_m = 0.0;  // the spacing the surface was asked for.
  std::shared_ptr<const TemplateRotations> rotations;
  std::shared_ptr<const SurfaceModel> surface;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_TEMPLATE_MODELS_H_
