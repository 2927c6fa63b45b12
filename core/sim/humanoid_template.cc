#include "core/sim/humanoid_template.h"

#include <utility>
#include <vector>

#include "core/sim/humanoid_model.h"

namespace hpose {

Result<VoxelTemplate> MakeHumanoidTemplate(const HumanoidModel& model, const std::string& name,
                                           double resolution_m, const std::string& variant,
                                           const std::string& source, double spacing_m) {
  Result<std::vector<Eigen::Vector3f>> points = model.SampleSurface(spacing_m);
  if (!points.ok()) return points.error();
  Result<VoxelTemplate> tpl = MakeTemplateFromPoints(*points, name, resolution_m, variant, source);
  if (!tpl.ok()) return tpl.error();
  Result<std::vector<Eigen::Vector3f>> limbs = model.SampleFreeLimbSurface(spacing_m);
  if (!limbs.ok()) return limbs.error();
  tpl->free_limb = MarkSurfaceCells(tpl->surface, *limbs, tpl->SurfaceCellM());
  return tpl;
}

}  // namespace hpose
