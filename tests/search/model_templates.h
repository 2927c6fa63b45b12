#ifndef HPOSE_TESTS_SEARCH_MODEL_TEMPLATES_H_
#define HPOSE_TESTS_SEARCH_MODEL_TEMPLATES_H_

// Templates of the parametric humanoid for estimator tests.

#include <string>
#include <vector>

#include "core/sim/humanoid_model.h"
#include "core/templates/voxel_template.h"

namespace hpose::testing {

// The template of a humanoid joint preset ("standing", "right_arm_raised"), voxels of
// `resolution_m` (16 mm), of the proportions `body` (HumanoidDimensions::Variant).
inline VoxelTemplate ModelTemplate(const std::string& preset, const std::string& body = "nao",
                                   double resolution_m = 0.016) {
  const HumanoidModel model =
      *HumanoidModel::FromPreset(preset, *HumanoidDimensions::Variant(body));
  const std::vector<Eigen::Vector3f> pts = *model.SampleSurface(0.004);
  return *MakeTemplateFromPoints(pts, preset, resolution_m, preset, "test");
}

}  // namespace hpose::testing

#endif  // HPOSE_TESTS_SEARCH_MODEL_TEMPLATES_H_
