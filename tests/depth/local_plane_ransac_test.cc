#include "core/depth/local_plane_ransac.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace hpose {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A floor 0.8 m below a sensor (y down) tilted by `pitch`, with a little noise, in 3 cm steps.
std::vector<Eigen::Vector3f> Floor(double pitch, std::mt19937* rng, Eigen::Vector4f* truth) {
  std::normal_distribution<float> noise(0.0f, 0.002f);
  const Eigen::Vector3f normal(0.0f, -static_cast<float>(std::cos(pitch)),
                               static_cast<float>(std::sin(pitch)));
  const Eigen::Vector3f along(0.0f, static_cast<float>(std::sin(pitch)),
                              static_cast<float>(std::cos(pitch)));
  const Eigen::Vector3f origin = -0.8f * normal;  // the sensor's foot.
  std::vector<Eigen::Vector3f> points;
  for (float x = -1.5f; x <= 1.5f; x += 0.03f) {
    for (float s = 0.5f; s <= 3.5f; s += 0.03f) {
      points.push_back(origin + x * Eigen::Vector3f::UnitX() + s * along + noise(*rng) * normal);
    }
  }
  *truth << normal, 0.8f;
  return points;
}

void AddClutter(int n, std::mt19937* rng, std::vector<Eigen::Vector3f>* points) {
  std::uniform_real_distribution<float> x(-1.5f, 1.5f), y(-0.8f, 0.6f), z(0.5f, 3.5f);
  for (int i = 0; i < n; ++i) points->emplace_back(x(*rng), y(*rng), z(*rng));
}

double AngleBetween(const Eigen::Vector4f& a, const Eigen::Vector4f& b) {
  const double c = std::abs(a.head<3>().normalized().dot(b.head<3>().normalized()));
  return std::acos(std::min(1.0, c));
}

// The plane, signed as the truth, and its distance from the sensor.
double Offset(const Eigen::Vector4f& plane, const Eigen::Vector4f& truth) {
  return plane.head<3>().dot(truth.head<3>()) < 0.0f ? -plane[3] : plane[3];
}

TEST(LocalPlaneRansacTest, FindsAFloorThatIsAMinorityOfThePoints) {
  for (const double pitch : {0.0, 25.0 * kDeg, 55.0 * kDeg}) {
    std::mt19937 rng(21);
    Eigen::Vector4f truth;
    std::vector<Eigen::Vector3f> points = Floor(pitch, &rng, &truth);
    const int floor_points = static_cast<int>(points.size());
    AddClutter(2 * floor_points, &rng, &points);  // a third of the points are floor.
    LocalPlaneRansacOptions options;
    const LocalPlaneRansacResult fit = FitPlaneLocalRansac(points, options);
    ASSERT_TRUE(fit.found) << "pitch " << pitch / kDeg;
    EXPECT_LT(AngleBetween(fit.plane, truth), 2.0 * kDeg) << "pitch " << pitch / kDeg;
    EXPECT_NEAR(Offset(fit.plane, truth), 0.8, 0.02) << "pitch " << pitch / kDeg;
    EXPECT_GE(fit.inliers, floor_points * 9 / 10);
    EXPECT_NEAR(fit.plane.head<3>().norm(), 1.0f, 1e-5f);
    EXPECT_LE(fit.hypotheses, options.max_iterations);
  }
}

TEST(LocalPlaneRansacTest, SamePointsAndSeedSamePlane) {
  std::mt19937 rng(4);
  Eigen::Vector4f truth;
  std::vector<Eigen::Vector3f> points = Floor(10.0 * kDeg, &rng, &truth);
  AddClutter(3000, &rng, &points);
  LocalPlaneRansacOptions options;
  options.seed = 17;
  const LocalPlaneRansacResult a = FitPlaneLocalRansac(points, options);
  const LocalPlaneRansacResult b = FitPlaneLocalRansac(points, options);
  ASSERT_TRUE(a.found);
  EXPECT_EQ(a.plane, b.plane);
  EXPECT_EQ(a.inliers, b.inliers);
  EXPECT_EQ(a.hypotheses, b.hypotheses);
}

// A wall (normal across the axis) is no plane of this search, however many points it has.
TEST(LocalPlaneRansacTest, IgnoresPlanesTooSteepForTheAxis) {
  std::vector<Eigen::Vector3f> wall;
  for (float y = -1.0f; y <= 1.0f; y += 0.03f) {
    for (float x = -1.5f; x <= 1.5f; x += 0.03f) wall.emplace_back(x, y, 2.5f);
  }
  LocalPlaneRansacOptions options;
  options.max_axis_angle_rad = 60.0 * kDeg;
  const LocalPlaneRansacResult fit = FitPlaneLocalRansac(wall, options);
  EXPECT_FALSE(fit.found);
  EXPECT_EQ(fit.hypotheses, 0);
  options.axis = Eigen::Vector3f::UnitZ();  // about the wall's normal: found.
  const LocalPlaneRansacResult along = FitPlaneLocalRansac(wall, options);
  ASSERT_TRUE(along.found);
  EXPECT_EQ(along.inliers, static_cast<int>(wall.size()));
}

// Too few points, or points too far apart to draw a hypothesis from: nothing, and it stops.
TEST(LocalPlaneRansacTest, NothingFromTooFewOrIsolatedPoints) {
  LocalPlaneRansacOptions options;
  EXPECT_FALSE(FitPlaneLocalRansac({}, options).found);
  EXPECT_FALSE(FitPlaneLocalRansac({{0, 1, 1}, {0.1f, 1, 1}}, options).found);
  std::vector<Eigen::Vector3f> sparse;
  for (int i = 0; i < 50; ++i) sparse.emplace_back(1.0f * i, 1.0f, 2.0f);
  EXPECT_FALSE(FitPlaneLocalRansac(sparse, options).found);
  std::vector<Eigen::Vector3f> line;  // neighbours, but every triple is collinear.
  for (int i = 0; i < 50; ++i) line.emplace_back(0.01f * i, 1.0f, 2.0f);
  EXPECT_FALSE(FitPlaneLocalRansac(line, options).found);
}

}  // namespace
}  // namespace hpose
