#ifndef HPOSE_TOOLS_TEMPLATE_PICTURE_H_
#define HPOSE_TOOLS_TEMPLATE_PICTURE_H_

#include <string>

#include "core/common/status.h"
#include "core/templates/voxel_template.h"

namespace hpose::tools {

// Where the simulated Kinect of the fourth panel stands.
struct TemplatePictureOptions {
  double sensor_distance_m = 1.5;  // horizontal distance from the sensor to the template origin.
  double sensor_height_m = 0.34;   // optical centre above the floor (level sensor).
  double heading_deg = 150.0;      // robot heading in the ground frame (180 = facing the sensor).
};

// Draws a PNG of the template: front, side (from its left) and top orthographic views shaded
// by depth, and the voxels as a Kinect v1 sees them from `options`; each with the template
// frame's origin and axes (x red, y green, z blue) drawn and labelled, and a scale.
Status WriteTemplatePicture(const VoxelTemplate& tpl, const std::string& path,
                            const TemplatePictureOptions& options = {});

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_TEMPLATE_PICTURE_H_
