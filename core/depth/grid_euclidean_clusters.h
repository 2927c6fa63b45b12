#ifndef HPOSE_CORE_DEPTH_GRID_EUCLIDEAN_CLUSTERS_H_
#define HPOSE_CORE_DEPTH_GRID_EUCLIDEAN_CLUSTERS_H_

#include <vector>

#include <Eigen/Core>

namespace hpose {

// Euclidean clusters of `points` (metres, finite) as connected components of "closer than
// tolerance_m": the same clusters as pcl::EuclideanClusterExtraction with a kd-tree and the same
// tolerance (no size limits), found through a hash-free bucket grid of cell tolerance_m instead
// of radius searches. Two points are neighbours when their squared distance, summed over x, y, z
// in float, is below float(tolerance_m^2) (the FLANN radius search's test). Labels are numbered
// in the order of each cluster's lowest point index, as PCL numbers its clusters.
// Returns the label of every point; *cluster_count receives the number of clusters.
// tolerance_m must be > 0.
std::vector<int> GridEuclideanClusterLabels(const std::vector<Eigen::Vector3f>& points,
                                            double tolerance_m, int* cluster_count);

// The distance tests take sixteen points at a time, with AVX-512 or else AVX2 (two vectors of
// eight) where the CPU has either; the scalar form gives the
// same labels on any CPU (the reference the tests compare with), as does the AVX2 form whatever
// else the CPU has (only where GridEuclideanClustersAvx2Available()), for tests.
std::vector<int> GridEuclideanClusterLabelsScalar(const std::vector<Eigen::Vector3f>& points,
                                                  double tolerance_m, int* cluster_count);
std::vector<int> GridEuclideanClusterLabelsAvx2(const std::vector<Eigen::Vector3f>& points,
                                                double tolerance_m, int* cluster_count);
bool GridEuclideanClustersAvx2Available();

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_GRID_EUCLIDEAN_CLUSTERS_H_
