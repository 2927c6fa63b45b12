#ifndef HPOSE_CORE_TEMPLATES_TEMPLATE_SHAPE_H_
#define HPOSE_CORE_TEMPLATES_TEMPLATE_SHAPE_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/templates/voxel_template.h"

namespace hpose {

// Where an orthographic view of a template looks from (template frame).
enum class TemplateSide {
  kFront,  // from +x, looking back at the robot's front; image right = robot's left (+y).
  kBack,   // from -x; image right = robot's right (-y).
  kLeft,   // from +y (the robot's left side); image right = robot's back (-x).
  kRight,  // from -y; image right = robot's front (+x).
  kTop,    // from above; image up = forward (+x), image right = robot's right (-y).
};

// An orthographic depth image of a template's voxels, one cell per voxel. Every side view of a
// template shares the same grid: columns u in [-half_width, half_width) with the template's
// vertical axis between u = -1 and u = 0 (a mirrored axis maps voxel i to -i - 1, so the grid
// is symmetric), rows v from the lowest voxel layer up (v = 0: the floor layer; top view: v in
// [-half_width, half_width) around the origin as well).
struct TemplateView {
  int half_width = 0;  // columns either side of the vertical axis.
  int v_min = 0;       // first row's index, in voxels.
  int rows = 0;
  double resolution_m = 0.0;
  // Per cell (row-major from v_min upwards, columns from -half_width): how far the nearest
  // voxel stands out towards the viewer, in voxels; kEmpty where none.
  std::vector<int> depth;
  // Per cell: the nearest voxel holds surface on a free limb (VoxelTemplate::free_limb).
  std::vector<std::uint8_t> free_limb;
  static constexpr int kEmpty = -1000000;

  int columns() const { return 2 * half_width; }
  int at(int u, int v) const { return depth[(v - v_min) * columns() + (u + half_width)]; }
};

// Renders one side of the template. An empty template gives an empty view (rows = 0).
TemplateView ViewTemplate(const VoxelTemplate& tpl, TemplateSide side);

// How different two views of the same grid look: 1 - (cells occupied in both with depths
// within one voxel) / (cells occupied in either). 0: identical; 1: nothing in common.
double ViewDifference(const TemplateView& a, const TemplateView& b);

// Facts about a template a user checks before trusting it (template frame, metres).
struct TemplateShape {
  size_t voxels = 0;
  double height_m = 0.0;                          // top of the highest voxel above the floor.
  Eigen::Vector3d min = Eigen::Vector3d::Zero();  // outer bounds of the voxels.
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
  double width_x_m = 0.0;  // extent front to back.
  double width_y_m = 0.0;  // extent left to right.
  // How different the sensor's images of the robot are (ViewDifference of orthographic depth
  // views); small numbers predict confusions:
  double front_back_difference = 0.0;  // facing the sensor vs facing away: 180-degree flips.
  double left_right_difference = 0.0;  // left side vs right side shown: +-90-degree flips.
  double mirror_difference = 0.0;      // front view vs its mirror image: left/right symmetry
                                       // (0 for a symmetric robot, whose arms can be swapped).
};

TemplateShape DescribeTemplate(const VoxelTemplate& tpl);

}  // namespace hpose

#endif  // HPOSE_CORE_TEMPLATES_TEMPLATE_SHAPE_H_
