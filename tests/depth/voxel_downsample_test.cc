#include "core/depth/voxel_downsample.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace hpose {
namespace {

TEST(VoxelDownsampleTest, AveragesPointsPerVoxelAndMapsEveryPoint) {
  const std::vector<Eigen::Vector3f> points = {
      {0.01f, 0.01f, 0.01f}, {0.03f, 0.05f, 0.07f},  // voxel (0, 0, 0) at 0.1 m.
      {0.15f, 0.0f, 0.0f},                           // voxel (1, 0, 0).
      {-0.05f, 0.0f, 0.0f},                          // voxel (-1, 0, 0): floor, not truncation.
      {0.02f, 0.03f, 0.02f},                         // back to voxel (0, 0, 0).
  };
  std::vector<Eigen::Vector3f> centroids;
  std::vector<int> owner;
  VoxelDownsample(points, 0.1f, &centroids, &owner);
  ASSERT_EQ(centroids.size(), 3u);
  ASSERT_EQ(owner.size(), points.size());
  EXPECT_EQ(owner[0], 0);
  EXPECT_EQ(owner[1], 0);
  EXPECT_EQ(owner[4], 0);
  EXPECT_EQ(owner[2], 1);
  EXPECT_EQ(owner[3], 2);
  EXPECT_NEAR(centroids[0].x(), (0.01f + 0.03f + 0.02f) / 3, 1e-6);
  EXPECT_NEAR(centroids[0].y(), (0.01f + 0.05f + 0.03f) / 3, 1e-6);
  EXPECT_NEAR(centroids[0].z(), (0.01f + 0.07f + 0.02f) / 3, 1e-6);
  EXPECT_NEAR(centroids[2].x(), -0.05f, 1e-6);
}

TEST(VoxelDownsampleTest, HandlesLargeExtentsAndEmptyInput) {
  std::vector<Eigen::Vector3f> centroids = {{1, 2, 3}};
  VoxelDownsample({}, 0.01f, &centroids);
  EXPECT_TRUE(centroids.empty());
  // 1 km apart at 1 mm leaf: pcl::VoxelGrid would overflow its index here.
  VoxelDownsample({{0, 0, 0}, {1000, -1000, 500}}, 0.001f, &centroids);
  EXPECT_EQ(centroids.size(), 2u);
}

// VoxelDownsample against the reference: an ordered map from std::floor cell indices, centroids
// in first-seen order, sums in point order (so the floats must agree exactly).
void ExpectEqualsReference(const std::vector<Eigen::Vector3f>& points, float leaf,
                           const std::string& what) {
  std::vector<Eigen::Vector3f> centroids;
  std::vector<int> owner;
  VoxelDownsample(points, leaf, &centroids, &owner);

  std::map<std::tuple<long, long, long>, int> index;
  std::vector<Eigen::Vector3f> sums;
  std::vector<int> counts, expected_owner;
  const float inv = 1.0f / leaf;
  for (const Eigen::Vector3f& p : points) {
    const auto key = std::make_tuple(static_cast<long>(std::floor(p.x() * inv)),
                                     static_cast<long>(std::floor(p.y() * inv)),
                                     static_cast<long>(std::floor(p.z() * inv)));
    auto [it, inserted] = index.emplace(key, static_cast<int>(sums.size()));
    if (inserted) {
      sums.push_back(Eigen::Vector3f::Zero());
      counts.push_back(0);
    }
    sums[it->second] += p;
    ++counts[it->second];
    expected_owner.push_back(it->second);
  }
  ASSERT_EQ(centroids.size(), sums.size()) << what;
  EXPECT_EQ(owner, expected_owner) << what;
  for (size_t v = 0; v < sums.size(); ++v) {
    ASSERT_EQ(centroids[v], sums[v] / static_cast<float>(counts[v])) << what << ", voxel " << v;
  }
}

TEST(VoxelDownsampleTest, EqualsAStraightforwardReferenceOnLargeClouds) {
  std::mt19937 rng(7);
  for (const int n : {10, 5000, 200000}) {
    std::uniform_real_distribution<float> u(-2.0f, 2.0f);
    std::vector<Eigen::Vector3f> points;
    for (int i = 0; i < n; ++i) {
      // Every third point repeats a cell of an earlier one; exact multiples of the leaf too.
      if (i % 3 == 2) {
        points.push_back(points[i / 2] + Eigen::Vector3f::Constant(0.001f));
      } else if (i % 97 == 0) {
        points.emplace_back(0.008f * (i % 11 - 5), -0.016f, 0.0f);
      } else {
        points.emplace_back(u(rng), u(rng), 0.5f * u(rng));
      }
    }
    ExpectEqualsReference(points, 0.008f, std::to_string(n) + " points");
  }
}

// Clouds in scan order, as a depth camera's come: rows of a surface whose neighbouring points
// share a voxel in runs of one to several, and whose next row comes back to the voxels of the
// last; with a gap (no points) now and then, and at two leaves.
TEST(VoxelDownsampleTest, EqualsTheReferenceOnScanOrderedClouds) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> jitter(-0.0005f, 0.0005f);
  std::uniform_real_distribution<float> step(0.002f, 0.012f);
  for (const float leaf : {0.008f, 0.02f}) {
    std::vector<Eigen::Vector3f> points;
    for (int row = 0; row < 240; ++row) {
      float x = -1.0f;
      for (int col = 0; col < 320; ++col) {
        x += step(rng);
        if ((row * 7 + col) % 53 == 0) continue;  // a pixel without a return.
        points.emplace_back(x + jitter(rng), 0.004f * row + jitter(rng),
                            1.5f + 0.1f * std::sin(3.0f * x) + jitter(rng));
      }
    }
    ExpectEqualsReference(points, leaf, "leaf " + std::to_string(leaf));
  }
}

// Cells beyond 2^20 - 1 from the origin on an axis are clamped there (those far voxels merge):
// the sixteen-point path clamps as the scalar one does, on both sides.
TEST(VoxelDownsampleTest, ClampsCellsBeyondTheKeyRange) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 200; ++i) points.emplace_back(u(rng), 0.0f, u(rng));
  const float leaf = 1e-6f;  // 3 m is 3e6 cells: beyond the limit.
  std::vector<Eigen::Vector3f> centroids;
  std::vector<int> owner;
  VoxelDownsample(points, leaf, &centroids, &owner);
  const long limit = (1L << 20) - 1;
  const float inv = 1.0f / leaf;
  std::map<std::tuple<long, long, long>, int> index;
  std::vector<int> expected_owner;
  for (const Eigen::Vector3f& p : points) {
    auto cell = [&](float v) {
      return std::clamp(static_cast<long>(std::floor(v * inv)), -limit, limit);
    };
    const auto key = std::make_tuple(cell(p.x()), cell(p.y()), cell(p.z()));
    expected_owner.push_back(index.emplace(key, static_cast<int>(index.size())).first->second);
  }
  EXPECT_EQ(owner, expected_owner);
  EXPECT_EQ(centroids.size(), index.size());
  EXPECT_LT(index.size(), 150u);  // clamped corners merged many of them.
}

// The keys of every vector path equal the scalar reference's: random points at several leaf
// sizes (cells either side of 0, on cell borders, beyond the 21-bit range, and infinite), counts
// that are and are not multiples of eight and sixteen.
TEST(VoxelDownsampleTest, EveryKeyPathEqualsTheScalarReference) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> u(-4.0f, 4.0f);
  using Pack = void (*)(const Eigen::Vector3f*, size_t, float, std::uint64_t*);
  std::vector<std::pair<Pack, const char*>> paths = {{PackVoxelKeys, "dispatched"}};
  if (VoxelKeysAvx2Available()) paths.emplace_back(PackVoxelKeysAvx2, "avx2");
  int distinct_far = 0;
  for (const float leaf : {0.008f, 0.02f, 0.1f}) {
    for (const size_t n : {size_t{0}, size_t{5}, size_t{8}, size_t{16}, size_t{37}, size_t{4099}}) {
      std::vector<Eigen::Vector3f> points(n);
      for (size_t i = 0; i < n; ++i) {
        points[i] = Eigen::Vector3f(u(rng), u(rng), u(rng));
        if (i % 7 == 0) points[i].x() = std::round(points[i].x() / leaf) * leaf;  // a border.
        if (i % 11 == 0) points[i].y() = (i % 22 == 0 ? 1.0f : -1.0f) * 1.0e5f;   // beyond range.
        if (i % 13 == 0) points[i].z() = (i % 26 == 0 ? 1.0f : -1.0f) * INFINITY;
      }
      std::vector<std::uint64_t> ref(n + 1, 7), fast(n + 1, 7);
      PackVoxelKeysScalar(points.data(), n, 1.0f / leaf, ref.data());
      EXPECT_EQ(ref[n], 7u);  // nothing written past n.
      for (const auto& [pack, name] : paths) {
        std::fill(fast.begin(), fast.end(), 7);
        pack(points.data(), n, 1.0f / leaf, fast.data());
        EXPECT_EQ(fast, ref) << name << " leaf " << leaf << " n " << n;
      }
      for (size_t i = 1; i < n; ++i) distinct_far += ref[i] != ref[i - 1] ? 1 : 0;
    }
  }
  EXPECT_GT(distinct_far, 10000);
}

}  // namespace
}  // namespace hpose
