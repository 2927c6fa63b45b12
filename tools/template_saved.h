#ifndef HPOSE_TOOLS_TEMPLATE_SAVED_H_
#define HPOSE_TOOLS_TEMPLATE_SAVED_H_

#include <string>

#include "core/templates/voxel_template.h"

namespace hpose::tools {

// What the template commands print for a template written to `path`: the files, name, voxels,
// edge and height, and for a body taller than the search takes on its own voxels
// (EstimatorOptions::max_height_voxels) a second line saying which edge it is searched at; notes
// when its lowest voxel is off the floor or its footprint far from the origin (a cloud given in
// another frame).
std::string SavedTemplateLines(const VoxelTemplate& tpl, const std::string& path);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_TEMPLATE_SAVED_H_
