#include "core/sim/primitive.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "tests/sanitizer_build.h"

namespace hpose {
namespace {

Eigen::Isometry3d At(const Eigen::Vector3d& t, double yaw = 0.0, double roll = 0.0) {
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  iso.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
  iso.translation() = t;
  return iso;
}

TEST(PrimitiveTest, SphereHitAlongAxis) {
  const Primitive s = Primitive::Sphere("s", 0.5, Eigen::Vector3d(0, 0, 3));
  const auto hit = s.Intersect(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.0, 100.0);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->t, 2.5, 1e-12);
  EXPECT_NEAR(hit->normal.z(), -1.0, 1e-12);
  EXPECT_FALSE(s.Intersect(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), 0.0, 100.0));
  // t_max excludes a hit beyond it.
  EXPECT_FALSE(s.Intersect(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.0, 2.0));
}

TEST(PrimitiveTest, BoxFaceHitAndNormal) {
  const Primitive b = Primitive::Box("b", Eigen::Vector3d(0.2, 0.4, 0.6), At({2, 0, 0}));
  const auto hit = b.Intersect(Eigen::Vector3d(0, 0.1, 0.2), Eigen::Vector3d::UnitX(), 0, 10);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->t, 1.9, 1e-12);
  EXPECT_NEAR(hit->normal.x(), -1.0, 1e-12);
  // Passes above the box (half height 0.3).
  EXPECT_FALSE(b.Intersect(Eigen::Vector3d(0, 0, 0.31), Eigen::Vector3d::UnitX(), 0, 10));
}

TEST(PrimitiveTest, CylinderSideAndCap) {
  const Primitive c = Primitive::Cylinder("c", 0.1, 0.4, At({0, 0, 1}));  // z in [0.8, 1.2].
  const auto side = c.Intersect(Eigen::Vector3d(-1, 0, 1.1), Eigen::Vector3d::UnitX(), 0, 10);
  ASSERT_TRUE(side.has_value());
  EXPECT_NEAR(side->t, 0.9, 1e-12);
  EXPECT_NEAR(side->normal.x(), -1.0, 1e-12);
  const auto cap = c.Intersect(Eigen::Vector3d(0.05, 0, 3), -Eigen::Vector3d::UnitZ(), 0, 10);
  ASSERT_TRUE(cap.has_value());
  EXPECT_NEAR(cap->t, 1.8, 1e-12);
  EXPECT_NEAR(cap->normal.z(), 1.0, 1e-12);
}

TEST(PrimitiveTest, CapsuleRoundEnd) {
  const Primitive c =
      Primitive::Capsule("c", 0.1, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 1));
  const auto top = c.Intersect(Eigen::Vector3d(0, 0, 5), -Eigen::Vector3d::UnitZ(), 0, 10);
  ASSERT_TRUE(top.has_value());
  EXPECT_NEAR(top->t, 5.0 - 1.1, 1e-12);
  const Eigen::AlignedBox3d bounds = c.Bounds();
  EXPECT_NEAR(bounds.min().z(), -0.1, 1e-12);
  EXPECT_NEAR(bounds.max().z(), 1.1, 1e-12);
  EXPECT_NEAR(bounds.max().x(), 0.1, 1e-12);
}

// For random rays, a reported hit must be a boundary crossing (outside just before, inside
// just after, on entry) and a miss must never pass through the solid.
TEST(PrimitiveTest, RandomRaysAgreeWithContains) {
  const std::vector<Primitive> shapes = {
      Primitive::Box("b", Eigen::Vector3d(0.3, 0.2, 0.5), At({0.1, -0.2, 0.3}, 0.7, 0.4)),
      Primitive::Sphere("s", 0.25, Eigen::Vector3d(0.1, 0.1, 0.1)),
      Primitive::Cylinder("c", 0.2, 0.5, At({0, 0.1, 0}, 0.3, 1.1)),
      Primitive::Capsule("k", 0.12, Eigen::Vector3d(-0.2, 0, 0), Eigen::Vector3d(0.2, 0.3, 0.1))};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (const Primitive& p : shapes) {
    int hits = 0;
    const int rays = testing::kSanitizerBuild ? 300 : 2000;
    for (int i = 0; i < rays; ++i) {
      const Eigen::Vector3d origin =
          2.0 * Eigen::Vector3d(uni(rng), uni(rng), uni(rng)).normalized();
      const Eigen::Vector3d target = 0.3 * Eigen::Vector3d(uni(rng), uni(rng), uni(rng));
      const Eigen::Vector3d dir = (target - origin).normalized();
      const auto hit = p.Intersect(origin, dir, 0.0, 10.0);
      if (hit) {
        ++hits;
        EXPECT_FALSE(p.Contains(origin + (hit->t - 1e-6) * dir)) << p.name;
        EXPECT_TRUE(p.Contains(origin + (hit->t + 1e-6) * dir, -1e-9)) << p.name;
        EXPECT_LT(hit->normal.dot(dir), 0.0) << p.name;
      } else {
        for (double t = 0.0; t < 4.0; t += 0.002) {
          ASSERT_FALSE(p.Contains(origin + t * dir, 1e-4)) << p.name << " ray " << i;
        }
      }
    }
    EXPECT_GT(hits, rays / 20) << p.name;
  }
}

TEST(PrimitiveTest, SurfaceSamplesLieOnTheSurface) {
  const std::vector<Primitive> shapes = {
      Primitive::Box("b", Eigen::Vector3d(0.3, 0.2, 0.5), At({0.1, -0.2, 0.3}, 0.7, 0.4)),
      Primitive::Sphere("s", 0.25, Eigen::Vector3d(0.1, 0.1, 0.1)),
      Primitive::Cylinder("c", 0.2, 0.5, At({0, 0.1, 0}, 0.3, 1.1)),
      Primitive::Capsule("k", 0.12, Eigen::Vector3d(-0.2, 0, 0), Eigen::Vector3d(0.2, 0.3, 0.1))};
  for (const Primitive& p : shapes) {
    const std::vector<Eigen::Vector3d> pts = p.SampleSurface(0.01);
    ASSERT_GT(pts.size(), 100u) << p.name;
    Eigen::AlignedBox3d box = p.Bounds();
    box.extend(box.min() - Eigen::Vector3d::Constant(1e-9));
    box.extend(box.max() + Eigen::Vector3d::Constant(1e-9));
    for (const Eigen::Vector3d& q : pts) {
      EXPECT_TRUE(p.Contains(q, -1e-9)) << p.name;  // within the solid...
      EXPECT_FALSE(p.Contains(q, 1e-6)) << p.name;  // ...but not inside it.
      EXPECT_TRUE(box.contains(q)) << p.name;
    }
  }
}

TEST(PrimitiveTest, ShapeNamesRoundTrip) {
  for (const PrimitiveShape s : {PrimitiveShape::kBox, PrimitiveShape::kSphere,
                                 PrimitiveShape::kCylinder, PrimitiveShape::kCapsule}) {
    const auto back = PrimitiveShapeFromName(PrimitiveShapeName(s));
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(*back, s);
  }
  EXPECT_FALSE(PrimitiveShapeFromName("cone").has_value());
}

}  // namespace
}  // namespace hpose
