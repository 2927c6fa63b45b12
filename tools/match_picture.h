#ifndef HPOSE_TOOLS_MATCH_PICTURE_H_
#define HPOSE_TOOLS_MATCH_PICTURE_H_

#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/depth/point_cloud.h"
#include "core/search/estimate.h"
#include "core/templates/voxel_template.h"

namespace hpose {
struct EstimatorOptions;
}  // namespace hpose

namespace hpose::tools {

// Draws a PNG for people: left, the scene from above (points above the floor coloured by
// height, the sensor and its field of view, every cluster's box, each humanoid with its placed
// template and heading); right, the best humanoid close up from above and from the sensor's
// side, cluster voxels in blue, template voxels in red (orange on free limbs the pose was fitted
// without, Candidate::free_limbs_left_out), overlap in magenta, with the score, scaled to the
// template's size. A frame without a humanoid shows its nearest miss instead
// (grey in the overview), with why it was refused (NearestMissReason, with `options` the
// estimator's). `cloud_sensor` may be empty (then only the templates and boxes are drawn).
Status WriteMatchPicture(const Estimate& estimate, const std::vector<VoxelTemplate>& templates,
                         const PointCloud& cloud_sensor, const std::string& path,
                         const EstimatorOptions* options = nullptr);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_MATCH_PICTURE_H_
