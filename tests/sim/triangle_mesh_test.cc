#include "core/sim/triangle_mesh.h"

#include <cmath>
#include <random>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "tests/sanitizer_build.h"

#include "core/sim/mesh_bvh.h"

namespace hpose {
namespace {

std::set<std::tuple<int, int, int>> Cells(const std::vector<Eigen::Vector3f>& points, double res) {
  std::set<std::tuple<int, int, int>> cells;
  for (const Eigen::Vector3f& p : points) {
    cells.emplace(static_cast<int>(std::floor(p.x() / res)),
                  static_cast<int>(std::floor(p.y() / res)),
                  static_cast<int>(std::floor(p.z() / res)));
  }
  return cells;
}

// Random triangles of all sizes, from slivers far below the voxel size to large ones.
TriangleMesh RandomTriangles(int count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-0.2f, 0.2f);
  std::uniform_real_distribution<float> size(-1.0f, 1.0f);
  TriangleMesh mesh;
  for (int i = 0; i < count; ++i) {
    const float scale = std::pow(10.0f, -3.0f + 2.5f * (i % 7) / 6.0f);  // 1 mm .. 0.3 m
    const Eigen::Vector3f a(pos(rng), pos(rng), pos(rng));
    const Eigen::Vector3f b = a + scale * Eigen::Vector3f(size(rng), size(rng), size(rng));
    const Eigen::Vector3f c = a + scale * Eigen::Vector3f(size(rng), size(rng), size(rng)) * 0.1f *
                                      static_cast<float>(1 + i % 10);
    const int n = static_cast<int>(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), {a, b, c});
    mesh.triangles.emplace_back(n, n + 1, n + 2);
  }
  return mesh;
}

TEST(TriangleMeshTest, VoxelisationHitsEveryVoxelADenseSamplingHits) {
  const double res = 0.016;
  const TriangleMesh mesh = RandomTriangles(testing::kSanitizerBuild ? 30 : 150, 3);
  const auto exact = Cells(VoxelizeMeshSurface(mesh, res), res);
  const auto dense = Cells(SampleMeshSurface(mesh, res / 50.0), res);
  for (const auto& c : dense) {
    EXPECT_TRUE(exact.count(c)) << std::get<0>(c) << "," << std::get<1>(c) << "," << std::get<2>(c);
  }
  // The exact set adds only cells the surface merely clips (between dense samples).
  EXPECT_LE(exact.size(), dense.size() + dense.size() / 20);
  // Centres are unique and in the cells they name.
  const std::vector<Eigen::Vector3f> centres = VoxelizeMeshSurface(mesh, res);
  EXPECT_EQ(centres.size(), exact.size());
}

TEST(TriangleMeshTest, SamplingCoversTinyTrianglesAndKeepsSpacing) {
  TriangleMesh tiny;
  tiny.vertices = {{0.0f, 0.0f, 0.0f}, {1e-4f, 0.0f, 0.0f}, {0.0f, 1e-4f, 0.0f}};
  tiny.triangles = {{0, 1, 2}};
  EXPECT_EQ(SampleMeshSurface(tiny, 0.004).size(), 3u);
  TriangleMesh big;
  big.vertices = {{0.0f, 0.0f, 0.0f}, {0.1f, 0.0f, 0.0f}, {0.0f, 0.1f, 0.0f}};
  big.triangles = {{0, 1, 2}};
  // The longest edge (0.1414 m) in 36 steps of at most 4 mm: 37 * 38 / 2 lattice points.
  EXPECT_EQ(SampleMeshSurface(big, 0.004).size(), 703u);
}

TEST(TriangleMeshTest, SurfaceOnACellFaceBelongsToTheCellAbove) {
  // A square on z = 0 (a sole on the floor) gives voxels with z in [0, res) only.
  TriangleMesh floor;
  floor.vertices = {
      {0.0f, 0.0f, 0.0f}, {0.09f, 0.0f, 0.0f}, {0.09f, 0.09f, 0.0f}, {0.0f, 0.09f, 0.0f}};
  floor.triangles = {{0, 1, 2}, {0, 2, 3}};
  const std::vector<Eigen::Vector3f> v = VoxelizeMeshSurface(floor, 0.02);
  EXPECT_EQ(v.size(), 25u);
  for (const Eigen::Vector3f& c : v) EXPECT_NEAR(c.z(), 0.01, 1e-6);
}

TEST(TriangleMeshTest, TessellatedPrimitivesMatchTheirShapes) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(0.3, -0.1, 0.2);
  const Primitive shapes[] = {
      Primitive::Box("b", Eigen::Vector3d(0.2, 0.1, 0.3), pose),
      Primitive::Sphere("s", 0.07, Eigen::Vector3d(0.1, 0.2, 0.3)),
      Primitive::Cylinder("c", 0.05, 0.3, pose),
      Primitive::Capsule("k", 0.04, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.1, 0.1, 0.2))};
  for (const Primitive& p : shapes) {
    const TriangleMesh mesh = TessellatePrimitive(p, 0.005);
    ASSERT_TRUE(mesh.IsValid());
    // Vertices on the surface: inside the shape grown by 1 mm, outside it shrunk by 1 mm
    // (inscribed polyhedra are within max_edge^2 / (8 r) of the surface).
    for (const Eigen::Vector3f& v : mesh.vertices) {
      EXPECT_TRUE(p.Contains(v.cast<double>(), -0.001)) << p.name;
      EXPECT_FALSE(p.Contains(v.cast<double>(), 0.001)) << p.name;
    }
    const Eigen::AlignedBox3d mb = mesh.Bounds();
    const Eigen::AlignedBox3d pb = p.Bounds();
    EXPECT_LT((mb.min() - pb.min()).cwiseAbs().maxCoeff(), 0.002) << p.name;
    EXPECT_LT((mb.max() - pb.max()).cwiseAbs().maxCoeff(), 0.002) << p.name;
  }
}

// A body far larger than a humanoid (a mesh in millimetres, a shape placed far away), a surface
// too fine to sample in memory and a broken mesh are errors naming the cause, before any
// sampling; a humanoid-sized body at the same voxels is a template.
TEST(TriangleMeshTest, MeshTemplatesRefuseBodiesTooLargeOrTooFineOrBroken) {
  const auto box = [](double side) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation().z() = 0.5 * side;
    return TessellatePrimitive(Primitive::Box("b", Eigen::Vector3d::Constant(side), pose), side);
  };
  Result<VoxelTemplate> ok = MakeMeshTemplate(box(0.5), "small", 0.016);
  ASSERT_TRUE(ok.ok()) << ok.error().message;
  EXPECT_GT(ok->voxels.size(), 100u);

  // A 1.2 m robot read in millimetres.
  const Result<VoxelTemplate> in_mm = MakeMeshTemplate(box(1200.0), "in_mm", 0.016);
  ASSERT_FALSE(in_mm.ok());
  EXPECT_EQ(in_mm.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(in_mm.error().message.find("'in_mm'"), std::string::npos) << in_mm.error().message;
  EXPECT_NE(in_mm.error().message.find("1.2e+03 x"), std::string::npos) << in_mm.error().message;
  EXPECT_NE(in_mm.error().message.find("millimetres"), std::string::npos);
  EXPECT_TRUE(CheckMeshForTemplate(box(kMaxTemplateBodyM * 0.99), "edge", 0.016).ok());

  // A shape placed a million kilometres away (a joint origin in other units): single-precision
  // vertices there are 64 m apart, so the body would collapse to a point; it is refused by name.
  const auto box_at = [](double x) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(x, 0.0, 0.25);
    return TessellatePrimitive(Primitive::Box("b", Eigen::Vector3d::Constant(0.5), pose), 0.5);
  };
  const Result<VoxelTemplate> far = MakeMeshTemplate(box_at(1e9), "far", 0.016);
  ASSERT_FALSE(far.ok());
  EXPECT_EQ(far.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(far.error().message.find("'far'"), std::string::npos) << far.error().message;
  EXPECT_NE(far.error().message.find("1e+09 m from the origin"), std::string::npos)
      << far.error().message;
  EXPECT_FALSE(CheckMeshForTemplate(box_at(-1.01 * kMaxTemplateOffsetM), "beyond", 0.016).ok());
  EXPECT_TRUE(CheckMeshForTemplate(box_at(0.9 * kMaxTemplateOffsetM), "within", 0.016).ok());

  // 2 m of body on 1 mm voxels: 7.7e8 samples a quarter voxel apart.
  const Result<VoxelTemplate> fine = MakeMeshTemplate(box(2.0), "fine", 0.001);
  ASSERT_FALSE(fine.ok());
  EXPECT_NE(fine.error().message.find("samples"), std::string::npos) << fine.error().message;
  EXPECT_NE(fine.error().message.find("1 mm"), std::string::npos) << fine.error().message;

  TriangleMesh broken = box(0.5);
  broken.vertices[3].y() = std::nanf("");
  const Result<VoxelTemplate> nan = MakeMeshTemplate(broken, "nan", 0.016);
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.error().message.find("non-finite"), std::string::npos) << nan.error().message;
  broken = box(0.5);
  broken.triangles[0].z() = static_cast<int>(broken.vertices.size());
  EXPECT_FALSE(MakeMeshTemplate(broken, "index", 0.016).ok());
}

TEST(MeshBvhTest, IntersectEqualsBruteForce) {
  const TriangleMesh mesh = RandomTriangles(2000, 11);
  Result<std::shared_ptr<const MeshBvh>> bvh = MeshBvh::Build(mesh);
  ASSERT_TRUE(bvh.ok()) << bvh.error().message;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // Under the sanitizers 500 rays: the reference tests every triangle for every ray.
  const int rays = testing::kSanitizerBuild ? 500 : 3000;
  int hits = 0;
  for (int i = 0; i < rays; ++i) {
    const Eigen::Vector3d origin(u(rng), u(rng), u(rng));
    const Eigen::Vector3d target(0.2 * u(rng), 0.2 * u(rng), 0.2 * u(rng));
    const Eigen::Vector3d dir = (target - origin).normalized();
    // Reference: every triangle, Moller-Trumbore-free (plane hit + inside test).
    double best = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3i& t : mesh.triangles) {
      const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>();
      const Eigen::Vector3d b = mesh.vertices[t[1]].cast<double>();
      const Eigen::Vector3d c = mesh.vertices[t[2]].cast<double>();
      const Eigen::Vector3d n = (b - a).cross(c - a);
      const double nd = n.dot(dir);
      if (std::abs(nd) < 1e-15) continue;
      const double t_hit = n.dot(a - origin) / nd;
      if (!(t_hit > 1e-9) || t_hit >= best) continue;
      const Eigen::Vector3d p = origin + t_hit * dir;
      if (n.dot((b - a).cross(p - a)) >= 0 && n.dot((c - b).cross(p - b)) >= 0 &&
          n.dot((a - c).cross(p - c)) >= 0) {
        best = t_hit;
      }
    }
    const std::optional<RayHit> hit =
        (*bvh)->Intersect(origin, dir, 1e-9, std::numeric_limits<double>::infinity());
    ASSERT_EQ(hit.has_value(), std::isfinite(best)) << i;
    if (hit) {
      ++hits;
      EXPECT_NEAR(hit->t, best, 1e-7) << i;
      EXPECT_LE(hit->normal.dot(dir), 0.0);
    }
  }
  EXPECT_GT(hits, rays / 6);
}

TEST(MeshBvhTest, RejectsEmptyAndInvalidMeshes) {
  EXPECT_FALSE(MeshBvh::Build(TriangleMesh{}).ok());
  TriangleMesh bad;
  bad.vertices = {{0, 0, 0}, {1, 0, 0}};
  bad.triangles = {{0, 1, 2}};
  EXPECT_FALSE(MeshBvh::Build(bad).ok());
}

}  // namespace
}  // namespace hpose
