#ifndef HPOSE_TESTS_SEARCH_SEARCH_TEST_SCENES_H_
#define HPOSE_TESTS_SEARCH_SEARCH_TEST_SCENES_H_

#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/pose2d.h"
#include "core/templates/voxel_template.h"

namespace hpose::testing {

// A crude random "robot": a few boxes stacked on the floor, sampled on their surfaces every
// 8 mm, in the template frame. Different seeds give different, asymmetric shapes.
inline std::vector<Eigen::Vector3f> RandomRobotPoints(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> size(0.04f, 0.14f), off(-0.08f, 0.08f);
  std::vector<Eigen::Vector3f> pts;
  float z = 0.0f;
  for (int part = 0; part < 4; ++part) {
    const Eigen::Vector3f c(off(rng), off(rng), 0.0f);
    const Eigen::Vector3f s(size(rng), size(rng), size(rng) + 0.05f);
    for (float x = -s.x() / 2; x <= s.x() / 2; x += 0.008f)
      for (float y = -s.y() / 2; y <= s.y() / 2; y += 0.008f)
        for (float h = 0; h <= s.z(); h += 0.008f) {
          const bool surface = std::abs(x) > s.x() / 2 - 0.008f ||
                               std::abs(y) > s.y() / 2 - 0.008f || h < 0.008f || h > s.z() - 0.008f;
          if (surface) pts.emplace_back(c.x() + x, c.y() + y, z + h);
        }
    z += s.z();
  }
  return pts;
}

// The side of `robot_pts` facing a sensor at the ground origin, after placing it at `pose`:
// points whose outward direction (from the robot's vertical axis) faces the sensor, plus noise.
inline std::vector<Eigen::Vector3f> VisibleCluster(const std::vector<Eigen::Vector3f>& robot_pts,
                                                   const Pose2D& pose, float noise_m,
                                                   unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.0f, noise_m);
  const Eigen::Isometry3f t = pose.ToIsometry().cast<float>();
  const Eigen::Vector2f centre(static_cast<float>(pose.x), static_cast<float>(pose.y));
  std::vector<Eigen::Vector3f> out;
  for (const Eigen::Vector3f& p : robot_pts) {
    const Eigen::Vector3f q = t * p;
    const Eigen::Vector2f outward = q.head<2>() - centre;
    const Eigen::Vector2f to_sensor = -q.head<2>();
    if (outward.dot(to_sensor) < 0.0f) continue;
    out.emplace_back(q.x() + g(rng), q.y() + g(rng), std::max(0.021f, q.z() + g(rng)));
  }
  return out;
}

}  // namespace hpose::testing

#endif  // HPOSE_TESTS_SEARCH_SEARCH_TEST_SCENES_H_
