#ifndef HPOSE_CORE_DEPTH_GROUND_BAND_H_
#define HPOSE_CORE_DEPTH_GROUND_BAND_H_

#include <vector>

#include <Eigen/Core>

#include "core/depth/point_cloud.h"

namespace hpose {

// The slab of space the clusters are looked for in: heights above the floor and a horizontal
// range from the sensor's foot, in the ground frame, with the sensor-to-ground transform in
// float like the points.
struct GroundBand {
  Eigen::Matrix3f rotation = Eigen::Matrix3f::Identity();  // ground_from_sensor.
  Eigen::Vector3f translation = Eigen::Vector3f::Zero();
  float z_min = 0.0f;   // lowest height kept (m, inclusive).
  float z_max = 0.0f;   // highest height kept (m, inclusive).
  float range2 = 0.0f;  // largest squared horizontal distance kept (m^2, inclusive).
};

// Appends to `out` the ground-frame position g = rotation * p + translation of every finite
// point p of `cloud` whose g lies within the band, in the cloud's order, and their indices in
// the cloud to `index` when given. Every comparison fails for NaN, so only points provably
// inside pass.
//
// With AVX-512 sixteen points a step, with AVX2 eight (GroundBandVectorised() where either),
// the scalar loop otherwise: SelectGroundBandScalar, the reference. All compute g as Eigen does
// (per row r0 x + (r1 y + r2 z), then + t; no fused multiply-adds), so their points are equal
// to the bit. SelectGroundBandAvx2 takes the AVX2 path whatever else the CPU has (only where
// GroundBandAvx2Available()), for tests and benchmarks.
void SelectGroundBand(const PointCloud& cloud, const GroundBand& band,
                      std::vector<Eigen::Vector3f>* out, std::vector<int>* index = nullptr);
void SelectGroundBandScalar(const PointCloud& cloud, const GroundBand& band,
                            std::vector<Eigen::Vector3f>* out, std::vector<int>* index = nullptr);
bool GroundBandVectorised();
void SelectGroundBandAvx2(const PointCloud& cloud, const GroundBand& band,
                          std::vector<Eigen::Vector3f>* out, std::vector<int>* index = nullptr);
bool GroundBandAvx2Available();

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_GROUND_BAND_H_
