#ifndef HPOSE_CORE_SEARCH_SURFACE_MODEL_H_
#define HPOSE_CORE_SEARCH_SURFACE_MODEL_H_

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "core/templates/voxel_template.h"

namespace hpose {

// A template's surface prepared for continuous pose refinement (template frame, metres): the
// surface points (VoxelTemplate::SurfaceOrVoxels) with unsigned normals from local plane fits.
// Built once per template (a few ms), immutable, shareable between threads.
class SurfaceModel {
 public:
  // `spacing_m`: the template's surface is reduced to one point per cell of this edge when it is
  // coarser than the template's own surface cell (fewer points, a faster refinement).
  explicit SurfaceModel(const VoxelTemplate& tpl, double spacing_m = 0.0);

  const std::vector<Eigen::Vector3f>& points() const { return points_; }
  // Unit normals of `points` (sign arbitrary: the direction of least spread of the neighbours).
  const std::vector<Eigen::Vector3f>& normals() const { return normals_; }
  // How far apart neighbouring surface points are (m): the template's surface cell.
  double spacing_m() const { return spacing_; }
  // Centre of the points (template frame).
  const Eigen::Vector3f& centre() const { return centre_; }
  // The points' coordinates as arrays (structure of arrays, for vectorised passes) and their
  // bounding box (inverted, +inf to -inf, without points).
  const std::vector<float>& xs() const { return xs_; }
  const std::vector<float>& ys() const { return ys_; }
  const std::vector<float>& zs() const { return zs_; }
  const Eigen::Vector3d& box_lo() const { return box_lo_; }
  const Eigen::Vector3d& box_hi() const { return box_hi_; }

  // The points off the template's free limbs (VoxelTemplate::free_limb) as a surface of their
  // own (the same points and normals); null when the template marks none.
  const SurfaceModel* without_free_limbs() const { return without_free_limbs_.get(); }
  // Per point of `points`, 1 on a free limb; empty when the template marks none.
  const std::vector<std::uint8_t>& free_limb_marks() const { return free_limb_marks_; }

 private:
  // The points of `full` whose mark equals `keep`.
  SurfaceModel(const SurfaceModel& full, const std::vector<std::uint8_t>& marks, std::uint8_t keep);
  void Finish();

  std::vector<Eigen::Vector3f> points_;
  std::vector<Eigen::Vector3f> normals_;
  double spacing_ = 0.008;
  Eigen::Vector3f centre_ = Eigen::Vector3f::Zero();
  std::vector<float> xs_, ys_, zs_;
  Eigen::Vector3d box_lo_ = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d box_hi_ = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  std::shared_ptr<const SurfaceModel> without_free_limbs_;
  std::vector<std::uint8_t> free_limb_marks_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_SURFACE_MODEL_H_
