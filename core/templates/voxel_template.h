#ifndef HPOSE_CORE_TEMPLATES_VOXEL_TEMPLATE_H_
#define HPOSE_CORE_TEMPLATES_VOXEL_TEMPLATE_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/status.h"

namespace hpose {

// A humanoid template: the surface of the robot as occupied voxels in the template frame
// (origin on the floor below the torso centre, +x forward, +y left, +z up; metres).
struct VoxelTemplate {
  std::string name;                     // what users select it by, e.g. "standing".
  std::string variant;                  // shape, e.g. "standing", "right_arm_raised".
  std::string source;                   // how it was made (command or description).
  double resolution_m = 0.016;          // voxel edge.
  std::vector<Eigen::Vector3f> voxels;  // centres of occupied voxels, unique, sorted.

  // Height of the highest voxel top above the floor, metres.
  double Height() const;
};

// Voxelises points given in the template frame at `resolution_m` (cell = floor(p / res)) into a
// template of unique voxel centres. Non-finite points are skipped. Fails (kInvalidArgument) when
// no finite point remains, the resolution is not in [1 mm, 0.5 m], or the name is empty or holds
// characters other than [A-Za-z0-9_.-].
Result<VoxelTemplate> MakeTemplateFromPoints(const std::vector<Eigen::Vector3f>& points,
                                             const std::string& name, double resolution_m,
                                             const std::string& variant = "",
                                             const std::string& source = "");

}  // namespace hpose

#endif  // HPOSE_CORE_TEMPLATES_VOXEL_TEMPLATE_H_
