#ifndef HPOSE_CORE_TEMPLATES_TEMPLATE_IO_H_
#define HPOSE_CORE_TEMPLATES_TEMPLATE_IO_H_

#include <string>

#include "core/common/status.h"
#include "core/templates/voxel_template.h"

namespace hpose {

// Path of the JSON sidecar of a template file: "dir/standing.bt" -> "dir/standing.json".
std::string TemplateSidecarPath(const std::string& bt_path);

// Writes the template as an OctoMap binary tree (.bt, occupied leaves = voxels) plus its JSON
// sidecar {"format":"hpose-template","version":2,"name","variant","resolution_m","source",
// "voxels","height_m","surface_points","surface_0.1mm"} (the surface points as flat x, y, z
// integers in 0.1 mm; version 1 sidecars without them are read too). Both files are written to
// temporaries and renamed, so a failure never leaves a half-written template. Fails with
// kInvalidArgument (path not ending in .bt) or kInternal (cannot write).
Status SaveTemplate(const VoxelTemplate& tpl, const std::string& bt_path);

// Reads a template written by SaveTemplate (or any OctoMap .bt with a sidecar; without a
// sidecar the name is the file stem). Fails with kNotFound (missing file), kDataLoss (corrupt
// tree or sidecar), kInvalidArgument (sidecar and tree disagree on resolution, empty tree).
Result<VoxelTemplate> LoadTemplate(const std::string& bt_path);

}  // namespace hpose

#endif  // HPOSE_CORE_TEMPLATES_TEMPLATE_IO_H_
