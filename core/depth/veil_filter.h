#ifndef HPOSE_CORE_DEPTH_VEIL_FILTER_H_
#define HPOSE_CORE_DEPTH_VEIL_FILTER_H_

#include <vector>

#include <Eigen/Core>

#include "core/depth/point_cloud.h"

namespace hpose {

// Pixels this far apart (in u or v) are compared by the veil test: two pixels rather than one
// so that one depth-quantisation step on an oblique surface does not look like a jump.
constexpr int kVeilPixelStep = 2;

// True when the point at pixel (u, v) of an organised cloud (sensor frame, finite) lies on a
// depth jump: the segment to a finite pixel kVeilPixelStep away in u or v runs within the veil
// angle of the viewing ray, i.e. (q - p).p squared exceeds cos2_veil |q - p|^2 |p|^2. Structured-
// light sensors interpolate "mixed pixels" across such jumps, which would glue a person to
// whatever stands behind. Both borders of the jump go too (a couple of pixels per object).
bool IsVeilPoint(const PointCloud& cloud, int u, int v, float cos2_veil);

// Removes from `kept` (and `index`) the entries whose pixel index[k] (into the organised
// `cloud`) is a veil point, keeping the order of the rest; `kept` and `index` are parallel
// (a point derived from each pixel, e.g. its ground-frame position, and the pixel). An
// unorganised cloud has no neighbours to test: nothing is removed.
//
// With AVX-512 the test takes sixteen pixels of a row a step, with AVX2 eight
// (VeilFilterVectorised() where either), the scalar loop over IsVeilPoint otherwise:
// DropVeilPointsScalar, the reference. All add and multiply in Eigen's order, each operation
// rounded on its own, so they drop the same points. DropVeilPointsAvx2 takes the AVX2 path
// whatever else the CPU has (only where VeilFilterAvx2Available()), for tests and benchmarks.
void DropVeilPoints(const PointCloud& cloud, float cos2_veil, std::vector<Eigen::Vector3f>* kept,
                    std::vector<int>* index);
void DropVeilPointsScalar(const PointCloud& cloud, float cos2_veil,
                          std::vector<Eigen::Vector3f>* kept, std::vector<int>* index);
bool VeilFilterVectorised();
void DropVeilPointsAvx2(const PointCloud& cloud, float cos2_veil,
                        std::vector<Eigen::Vector3f>* kept, std::vector<int>* index);
bool VeilFilterAvx2Available();

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_VEIL_FILTER_H_
