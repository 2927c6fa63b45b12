#ifndef HPOSE_CORE_TEMPLATES_CAPTURE_TEMPLATE_H_
#define HPOSE_CORE_TEMPLATES_CAPTURE_TEMPLATE_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/pose2d.h"
#include "core/common/status.h"
#include "core/templates/capture_registration.h"
#include "core/templates/voxel_template.h"

namespace hpose {

// Where the template origin goes (z = 0 is always the table top / floor the robot stands on).
enum class TemplateOrigin {
  // Below the centroid of the body's occupied voxels (each voxel counted once): geometry the
  // sensor sees, so a template of the same robot made another way (generated, from a URDF) can
  // be given the same origin with VoxelCentroidXY.
  kVoxelCentroid,
  // On the turntable axis (turntable captures only).
  kAxis,
};

struct CaptureTemplateOptions {
  std::string name;
  std::string variant;  // [default: the name]
  std::string source;   // how it was made, stored in the sidecar.
  double resolution_m = 0.016;
  TemplateOrigin origin = TemplateOrigin::kVoxelCentroid;
  // The template's +x: the horizontal direction from the robot towards the sensor in view
  // `front_view` (index among the captures given), i.e. the robot faced the sensor in that
  // view, turned by `front_yaw_rad` (e.g. pi when it showed its back).
  int front_view = 0;
  double front_yaw_rad = 0.0;
  // Voxels holding fewer merged points than this are dropped as noise.
  int min_points_per_voxel = 2;
  // Before voxelising, every merged point is moved onto the plane fitted to its neighbours
  // within this radius (metres; 0 disables): sensor noise would otherwise thicken the shell
  // of surface voxels, which a template made from a model does not have.
  double smoothing_radius_m = 0.02;
};

struct CaptureTemplate {
  VoxelTemplate tpl;
  // template_from_table: the template frame relative to the registration's table frame.
  Pose2D table_from_template;  // the template frame expressed in the table frame.
  int merged_points = 0;
  int noise_voxels_dropped = 0;
};

// Centroid (x, y) of the cells of `points` voxelised at `resolution_m` (cell = floor(p / res),
// as MakeTemplateFromPoints) that hold at least `min_points_per_voxel` points, each cell
// counted once at its centre; metres. Zero when no cell qualifies.
Eigen::Vector2d VoxelCentroidXY(const std::vector<Eigen::Vector3f>& points, double resolution_m,
                                int min_points_per_voxel = 1);

// Each point moved onto the least-squares plane of the points within radius_m of it (at least
// 6 of them; otherwise it stays).
std::vector<Eigen::Vector3f> ProjectOntoLocalPlanes(const std::vector<Eigen::Vector3f>& points,
                                                    double radius_m);

// `points` with the cells holding fewer than min_points_per_voxel points removed; `dropped`
// (may be null) receives how many cells went.
std::vector<Eigen::Vector3f> DropSparseVoxels(const std::vector<Eigen::Vector3f>& points,
                                              double resolution_m, int min_points_per_voxel,
                                              int* dropped);

// The registered views as a template: merged, noise voxels dropped, moved into the template
// frame defined by the options, voxelised. Fails (kInvalidArgument) on a front view that is not
// among the registered views, kAxis without a turntable, or what MakeTemplateFromPoints rejects.
Result<CaptureTemplate> MakeCaptureTemplate(const CaptureRegistration& registration,
                                            const CaptureTemplateOptions& options);

}  // namespace hpose

#endif  // HPOSE_CORE_TEMPLATES_CAPTURE_TEMPLATE_H_
