#ifndef HPOSE_CORE_SEARCH_TEMPLATE_PROJECTOR_H_
#define HPOSE_CORE_SEARCH_TEMPLATE_PROJECTOR_H_

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/pose2d.h"
#include "core/search/surface_model.h"

namespace hpose {

// Template frame to sensor frame at a pose: rotated about z by (c, s) = (cos, sin) of the
// heading, translated by (px, py), then through the mount: the order of operations of
// `sensor_from_ground * (RotateZ(c, s, m) + t)` with Eigen, so that the results are the same to
// the last bit.
struct ViewTransform {
  double c, s, px, py;
  double a00, a01, a02, a10, a11, a12, a20, a21, a22, b0, b1, b2;

  ViewTransform(double cos_t, double sin_t, const Pose2D& pose, const Eigen::Isometry3d& s_from_g);

  void Apply(double mx, double my, double mz, double* x, double* y, double* z) const {
    const double gx = (c * mx - s * my) + px;
    const double gy = (s * mx + c * my) + py;
    const double gz = mz + 0.0;
    *x = a00 * gx + a01 * gy + a02 * gz + b0;
    *y = a10 * gx + a11 * gy + a12 * gz + b1;
    *z = a20 * gx + a21 * gy + a22 * gz + b2;
  }
};

// A template's surface points placed in the sensor's view and z-buffered: for each bin of ray
// slope (floor(x / z / bin), floor(y / z / bin)), the point nearest the sensor (lowest z; the
// lowest index among equals), points at z <= 0.05 m left out. One vectorised pass over the
// points (one division per point, the exact quotients wherever a point lies within 1e-6 of a
// bin edge) straight into a z-buffer whose extent the template's bounding box bounds; two
// passes where the box does not bound it. The bins and winners equal those of dividing each
// point's x and y by its z and by `bin` and keeping the nearest (to the bit on x86-64).
//
// Keeps a reference to `model` (its points): it must outlive the projector. Not thread-safe.
class TemplateProjector {
 public:
  explicit TemplateProjector(const SurfaceModel& model);

  // Fills the z-buffer for the template placed by `view` with bins of `bin` (ray slope); false
  // when nothing is visible or the geometry is degenerate (a point almost in the optical
  // plane, a z-buffer of millions of bins): then it is empty (w() == 0).
  bool Project(const ViewTransform& view, double bin);

  // The z-buffer: bin (lo_x() + i, lo_y() + j) is winner()[j * w() + i], a point's index in
  // the model's points or -1. Callers may rewrite the entries (RefineObjective stores slots).
  int lo_x() const { return lo_x_; }
  int lo_y() const { return lo_y_; }
  int w() const { return w_; }
  int h() const { return h_; }
  std::vector<int>& winner() { return winner_; }
  const std::vector<int>& winner() const { return winner_; }

  // Point i of the model in the template frame (as float, like the model's).
  double mx(int i) const { return mx_[i]; }
  double my(int i) const { return my_[i]; }
  double mz(int i) const { return mz_[i]; }

  // floor(x / z / bin) for a ray slope whose quotient q was approximated (as t * (1 / bin)):
  // q's floor unless q lies within 1e-6 of an integer (or is huge), the exact quotient's there.
  static int Bin(double q, double x, double z, double bin);

 private:
  bool FillBounded(const ViewTransform& view);
  bool FillTwoPasses(const ViewTransform& view);

  // The model's points (structure of arrays, the model's own) and their bounding box.
  const float* mx_;
  const float* my_;
  const float* mz_;
  int n_;
  Eigen::Vector3d box_lo_, box_hi_;
  double bin_ = 0.01, inv_bin_ = 100.0;
  // Two passes only: per point, its sensor-frame depth and bins.
  std::vector<double> z_;
  std::vector<int> bx_, by_;
  int lo_x_ = 0, lo_y_ = 0, w_ = 0, h_ = 0;
  std::vector<int> winner_;
  std::vector<double> winner_z_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_TEMPLATE_PROJECTOR_H_
