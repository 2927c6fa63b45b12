#ifndef HPOSE_CORE_TEMPLATES_VOXEL_TEMPLATE_H_
#define HPOSE_CORE_TEMPLATES_VOXEL_TEMPLATE_H_

#include <cstdint>
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
  // Points on the body's surface, template frame, metres: the centroid of the input points in
  // each cell of half the voxel edge, sorted by cell. They keep the sub-voxel shape that voxel
  // centres lose (a flat face between two voxel centres), so rotated copies do not alias and
  // the pose refinement fits the real surface. Empty for templates that hold voxels only (made
  // before surfaces were kept, or by other OctoMap tools); voxel centres stand in for them.
  std::vector<Eigen::Vector3f> surface;
  // Which surface points lie on a free limb: a limb that does not reach the floor (arms, head),
  // which a standing robot may hold otherwise than the template does. Parallel to `surface`
  // (1: on a free limb), or empty when the template does not say (captured templates, voxel-only
  // ones). The refinement fits again without them where they contradict the frame
  // (RefineOptions::refit_without_moved_limbs).
  std::vector<std::uint8_t> free_limb;

  // Height of the highest voxel top above the floor, metres.
  double Height() const;
  // Edge of the cells `surface` was reduced on (half the voxel edge).
  double SurfaceCellM() const { return 0.5 * resolution_m; }
  // One point per voxel, sorted like `voxels`: its centre height, and across the floor the mean
  // of the surface points in its column of voxels (one (x, y) per column, so the search keeps
  // scoring a column with one bit mask), or the voxel centre when the template has no surface.
  // What the search rotates: sub-voxel positions do not alias on the grid as centres do.
  std::vector<Eigen::Vector3f> VoxelSurfaceCentroids() const;
  // The surface points on free limbs (none when `free_limb` does not match `surface`).
  std::vector<Eigen::Vector3f> FreeLimbPoints() const;
  // The surface points, or the voxel centres when there are none.
  const std::vector<Eigen::Vector3f>& SurfaceOrVoxels() const {
    return surface.empty() ? voxels : surface;
  }
};

// Voxelises points given in the template frame at `resolution_m` (cell = floor(p / res)) into a
// template of unique voxel centres, and keeps the surface (VoxelTemplate::surface) from the same
// points: pass points sampled densely on the body's surface (a few mm apart) for templates that
// fit to sub-voxel precision. Non-finite points are skipped. Fails (kInvalidArgument) when
// no finite point remains, the resolution is not in [1 mm, 0.5 m], or the name is empty or holds
// characters other than [A-Za-z0-9_.-].
Result<VoxelTemplate> MakeTemplateFromPoints(const std::vector<Eigen::Vector3f>& points,
                                             const std::string& name, double resolution_m,
                                             const std::string& variant = "",
                                             const std::string& source = "");

// The same body on coarser voxels of edge `resolution_m` (at least the template's own): its
// voxels and surface made again from its surface points (its voxel centres when it has none), as
// MakeTemplateFromPoints would from them. Fails (kInvalidArgument) for a finer edge (the voxels
// cannot be refined) or one outside [1 mm, 0.5 m].
Result<VoxelTemplate> VoxeliseAgain(const VoxelTemplate& tpl, double resolution_m);

// A voxel edge (metres) as people read it in messages: "16.0 mm".
std::string VoxelEdgeText(double m);

// Surface points reduced to the centroid of the points in each cell of edge `cell_m` (how
// VoxelTemplate::surface is kept), in cell order. Non-finite points are skipped.
std::vector<Eigen::Vector3f> ReduceSurfacePoints(const std::vector<Eigen::Vector3f>& points,
                                                 double cell_m);

// Marks the points of `surface` (as ReduceSurfacePoints keeps them, on cells of edge `cell_m`)
// whose cell holds one of `part` (points sampled on a part of the same body): 1 for those, 0 for
// the others. A cell the part shares with the rest of the body (where a limb joins the torso) is
// marked.
std::vector<std::uint8_t> MarkSurfaceCells(const std::vector<Eigen::Vector3f>& surface,
                                           const std::vector<Eigen::Vector3f>& part, double cell_m);

}  // namespace hpose

#endif  // HPOSE_CORE_TEMPLATES_VOXEL_TEMPLATE_H_
