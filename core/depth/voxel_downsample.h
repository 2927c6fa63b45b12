#ifndef HPOSE_CORE_DEPTH_VOXEL_DOWNSAMPLE_H_
#define HPOSE_CORE_DEPTH_VOXEL_DOWNSAMPLE_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace hpose {

// Voxel-grid downsampling shared by the floor fitter and the cluster extractor: every occupied
// cube of side `leaf_m` (metres, > 0, aligned at the frame origin) becomes the centroid of its
// points. Centroids come out in the order their voxels are first met, so the result is
// deterministic. Unlike pcl::VoxelGrid it has no limit on the extent / leaf ratio and needs no
// copy into a PCL cloud. All points must be finite.
//
// `voxel_of_point` (optional) receives, for every input point, the index of its centroid.
// Runs in O(n) with a hash table of the voxels; `centroids` is cleared first. Each calling
// thread keeps its working arrays for its next call (grown as needed, never shrunk: about 7 MB
// for a room seen by a 640x480 sensor, at most about 28 MB).
void VoxelDownsample(const std::vector<Eigen::Vector3f>& points, float leaf_m,
                     std::vector<Eigen::Vector3f>* centroids,
                     std::vector<int>* voxel_of_point = nullptr);

// The voxel key of each of points[0 .. n) as VoxelDownsample hashes it (the floored cell per
// axis, clamped to 21 bits, packed x, y, z from the high bits), into keys[0 .. n). Exposed for
// the tests of its paths: PackVoxelKeys takes the fastest this CPU has (AVX-512, AVX2),
// PackVoxelKeysScalar is the reference, PackVoxelKeysAvx2 the AVX2 path whatever else the CPU
// has (only where VoxelKeysAvx2Available()). All give the same keys for finite points.
void PackVoxelKeys(const Eigen::Vector3f* points, size_t n, float inv_leaf, std::uint64_t* keys);
void PackVoxelKeysScalar(const Eigen::Vector3f* points, size_t n, float inv_leaf,
                         std::uint64_t* keys);
void PackVoxelKeysAvx2(const Eigen::Vector3f* points, size_t n, float inv_leaf,
                       std::uint64_t* keys);
bool VoxelKeysAvx2Available();

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_VOXEL_DOWNSAMPLE_H_
