#ifndef HPOSE_CORE_SIM_HUMANOID_TEMPLATE_H_
#define HPOSE_CORE_SIM_HUMANOID_TEMPLATE_H_

#include <string>

#include "core/common/status.h"
#include "core/templates/voxel_template.h"

namespace hpose {

class HumanoidModel;

// A template of the parametric humanoid as posed: its outer surface sampled every `spacing_m`
// (HumanoidModel::SampleSurface) and voxelised at `resolution_m` (MakeTemplateFromPoints), with
// the surface points on its free limbs marked (HumanoidModel::IsFreeLimb,
// VoxelTemplate::free_limb), as `template from-urdf` marks a URDF robot's. Fails as those do.
Result<VoxelTemplate> MakeHumanoidTemplate(const HumanoidModel& model, const std::string& name,
                                           double resolution_m, const std::string& variant = "",
                                           const std::string& source = "",
                                           double spacing_m = 0.004);

}  // namespace hpose

#endif  // HPOSE_CORE_SIM_HUMANOID_TEMPLATE_H_
