#include "core/depth/veil_filter.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

namespace hpose {
namespace {

constexpr float kVeilAngle = 0.2f;  // rad, about 11.5 degrees.

// A depth image of a `width` x `height` sensor: a wall with boxes in front of it (depth jumps),
// noise, invalid pixels (NaN, and now and then infinite), and pixels placed so that a segment to
// a neighbour lies at the veil angle to within a rounding (the cases where only the arithmetic's
// order decides).
PointCloud RandomImage(unsigned seed, int width, int height) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  PointCloud cloud;
  cloud.width = width;
  cloud.height = height;
  cloud.points.resize(static_cast<size_t>(width) * height);
  const float focal = 0.8f * width;
  for (int v = 0; v < height; ++v) {
    for (int c = 0; c < width; ++c) {
      float z = 3.0f + 0.01f * u(rng);
      if (((c / 7) + (v / 5)) % 3 == 0) z = 1.2f + 0.01f * u(rng);  // a box nearer.
      Eigen::Vector3f p((c - 0.5f * width) * z / focal, (v - 0.5f * height) * z / focal, z);
      const float r = u(rng);
      if (r < 0.04f) p.x() = NAN;
      if (r > 0.995f) p.z() = INFINITY;
      cloud.points[static_cast<size_t>(v) * width + c] = p;
    }
  }
  // Neighbours at the veil angle: q = p + t (cos a ray + sin a w), w across the ray.
  const float cos_a = std::cos(kVeilAngle), sin_a = std::sin(kVeilAngle);
  for (int k = 0; k < width * height / 8; ++k) {
    const int c = static_cast<int>(u(rng) * (width - kVeilPixelStep));
    const int v = static_cast<int>(u(rng) * height);
    const Eigen::Vector3f& p = cloud.points[static_cast<size_t>(v) * width + c];
    if (!p.allFinite()) continue;
    const Eigen::Vector3f ray = p.normalized();
    const Eigen::Vector3f w = ray.cross(Eigen::Vector3f::UnitY()).normalized();
    const float t = 0.05f + 0.3f * u(rng);
    cloud.points[static_cast<size_t>(v) * width + c + kVeilPixelStep] =
        p + t * (cos_a * ray + sin_a * w);
  }
  return cloud;
}

// Every finite pixel, with a marker per pixel as its point.
void AllFinite(const PointCloud& cloud, std::vector<Eigen::Vector3f>* kept,
               std::vector<int>* index) {
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    if (!cloud.points[i].allFinite()) continue;
    kept->push_back(Eigen::Vector3f(static_cast<float>(i), 0.0f, 1.0f));
    index->push_back(static_cast<int>(i));
  }
}

// A vector path against the scalar reference on random images.
void ExpectTheScalarDrops(void (*drop)(const PointCloud&, float, std::vector<Eigen::Vector3f>*,
                                       std::vector<int>*),
                          const char* name) {
  const float cos2 = std::cos(kVeilAngle) * std::cos(kVeilAngle);
  int dropped_total = 0, kept_total = 0;
  // Widths with and without a multiple of sixteen and eight, images down to one group a row.
  for (const auto [width, height] : {std::pair{640, 48}, std::pair{37, 23}, std::pair{16, 9},
                                     std::pair{19, 5}, std::pair{64, 3}, std::pair{5, 40}}) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
      const PointCloud cloud = RandomImage(seed, width, height);
      std::vector<Eigen::Vector3f> fast, reference;
      std::vector<int> fast_index, reference_index;
      AllFinite(cloud, &fast, &fast_index);
      reference = fast;
      reference_index = fast_index;
      const size_t before = fast.size();
      drop(cloud, cos2, &fast, &fast_index);
      DropVeilPointsScalar(cloud, cos2, &reference, &reference_index);
      ASSERT_EQ(fast_index, reference_index)
          << name << " " << width << "x" << height << " seed " << seed;
      ASSERT_EQ(fast.size(), fast_index.size());
      for (size_t k = 0; k < fast.size(); ++k) {
        ASSERT_EQ(fast[k], Eigen::Vector3f(static_cast<float>(fast_index[k]), 0.0f, 1.0f));
      }
      dropped_total += static_cast<int>(before - fast.size());
      kept_total += static_cast<int>(fast.size());
    }
  }
  EXPECT_GT(dropped_total, 1000);
  EXPECT_GT(kept_total, 1000);
}

TEST(VeilFilterTest, VectorAndScalarDropTheSamePixels) {
  if (!VeilFilterVectorised())
    GTEST_SKIP() << "no AVX-512 or AVX2 on this CPU: only the scalar path runs";
  ExpectTheScalarDrops(DropVeilPoints, "dispatched");
}

TEST(VeilFilterTest, EightPixelsAStepDropWhatTheScalarPathDrops) {
  if (!VeilFilterAvx2Available()) GTEST_SKIP() << "no AVX2 on this CPU";
  ExpectTheScalarDrops(DropVeilPointsAvx2, "avx2");
}

// A wall whose row ends are wrapped: pixels (v, 0) and (v, 1) lie behind (v - 1, width - 2) and
// (v - 1, width - 1), on their rays. Those are the pixels two before and after them in memory,
// but not their neighbours: no path may test them (the lanes at a row's edges are masked).
PointCloud WrappedRowEnds(int width, int height) {
  PointCloud cloud;
  cloud.width = width;
  cloud.height = height;
  cloud.points.resize(static_cast<size_t>(width) * height);
  const float focal = 0.8f * width, z = 3.0f;
  const auto wall = [&](int c, int v) {
    return Eigen::Vector3f((c - 0.5f * width) * z / focal, (v - 0.5f * height) * z / focal, z);
  };
  for (int v = 0; v < height; ++v) {
    for (int c = 0; c < width; ++c) cloud.points[static_cast<size_t>(v) * width + c] = wall(c, v);
  }
  for (int v = 1; v < height; ++v) {
    for (int c = 0; c < 2; ++c) {
      cloud.points[static_cast<size_t>(v) * width + c] = wall(width - 2 + c, v - 1) * (3.5f / z);
    }
  }
  return cloud;
}

TEST(VeilFilterTest, PixelsAtARowsEndsAreNoNeighboursOfTheNextRow) {
  const float cos2 = std::cos(kVeilAngle) * std::cos(kVeilAngle);
  using Drop = void (*)(const PointCloud&, float, std::vector<Eigen::Vector3f>*, std::vector<int>*);
  std::vector<Drop> paths;
  if (VeilFilterVectorised()) paths.push_back(DropVeilPoints);
  if (VeilFilterAvx2Available()) paths.push_back(DropVeilPointsAvx2);
  for (const int width : {64, 640}) {
    const PointCloud cloud = WrappedRowEnds(width, 12);
    std::vector<Eigen::Vector3f> all, reference;
    std::vector<int> all_index, reference_index;
    AllFinite(cloud, &all, &all_index);
    reference = all;
    reference_index = all_index;
    DropVeilPointsScalar(cloud, cos2, &reference, &reference_index);
    // The scalar path keeps every pixel: the wall's and the wrapped ones.
    ASSERT_EQ(reference_index, all_index) << width;
    for (const Drop drop : paths) {
      std::vector<Eigen::Vector3f> kept = all;
      std::vector<int> index = all_index;
      drop(cloud, cos2, &kept, &index);
      EXPECT_EQ(index, reference_index) << width;
    }
  }
}

// The reference against the definition, written out: a pixel goes when a finite pixel two away
// in u or v makes a segment within the veil angle of its ray.
TEST(VeilFilterTest, DropsThePixelsAtDepthJumps) {
  const int width = 40, height = 30;
  const PointCloud cloud = RandomImage(7, width, height);
  const double cos_a = std::cos(static_cast<double>(kVeilAngle));
  std::vector<Eigen::Vector3f> kept;
  std::vector<int> index;
  AllFinite(cloud, &kept, &index);
  const std::vector<int> all = index;
  const float cos_f = std::cos(kVeilAngle);
  DropVeilPointsScalar(cloud, cos_f * cos_f, &kept, &index);
  size_t k = 0;
  int clear = 0;
  for (const int i : all) {
    const int c = i % width, v = i / width;
    const Eigen::Vector3d p = cloud.points[i].cast<double>();
    double best_cos = 0.0;  // the smallest angle to the ray over the neighbours, as a cosine.
    for (const auto [dc, dv] :
         {std::pair{2, 0}, std::pair{-2, 0}, std::pair{0, 2}, std::pair{0, -2}}) {
      if (c + dc < 0 || c + dc >= width || v + dv < 0 || v + dv >= height) continue;
      const Eigen::Vector3f& q = cloud.points[static_cast<size_t>(v + dv) * width + c + dc];
      if (!q.allFinite()) continue;
      const Eigen::Vector3d step = q.cast<double>() - p;
      best_cos = std::max(best_cos, std::abs(step.dot(p)) / (step.norm() * p.norm()));
    }
    const bool was_kept = k < index.size() && index[k] == i;
    if (was_kept) ++k;
    // Away from the angle itself the float test must agree with the exact one.
    if (std::abs(best_cos - cos_a) < 1e-4) continue;
    const bool veil = best_cos > cos_a;
    EXPECT_EQ(was_kept, !veil) << "pixel " << c << "," << v << " cos " << best_cos;
    ++clear;
  }
  EXPECT_GT(clear, 500);
}

TEST(VeilFilterTest, KeepsEverythingOnASmoothSurface) {
  // A wall seen square on: neighbours' segments are across the rays.
  PointCloud cloud;
  cloud.width = 48;
  cloud.height = 20;
  for (int v = 0; v < cloud.height; ++v) {
    for (int c = 0; c < cloud.width; ++c) {
      cloud.points.emplace_back((c - 24) * 0.005f, (v - 10) * 0.005f, 2.0f);
    }
  }
  std::vector<Eigen::Vector3f> kept;
  std::vector<int> index;
  AllFinite(cloud, &kept, &index);
  const float cos2 = std::cos(kVeilAngle) * std::cos(kVeilAngle);
  DropVeilPoints(cloud, cos2, &kept, &index);
  EXPECT_EQ(kept.size(), cloud.points.size());
  EXPECT_EQ(index.size(), cloud.points.size());
}

TEST(VeilFilterTest, AnUnorganisedCloudKeepsEverything) {
  PointCloud cloud = RandomImage(3, 37, 23);
  std::vector<Eigen::Vector3f> kept;
  std::vector<int> index;
  AllFinite(cloud, &kept, &index);
  const size_t before = kept.size();
  const float cos2 = std::cos(kVeilAngle) * std::cos(kVeilAngle);
  std::vector<Eigen::Vector3f> organised_kept = kept;
  std::vector<int> organised_index = index;
  DropVeilPoints(cloud, cos2, &organised_kept, &organised_index);
  ASSERT_LT(organised_kept.size(), before);  // the same pixels organised do lose some.
  cloud.width = 0;
  cloud.height = 0;
  DropVeilPoints(cloud, cos2, &kept, &index);
  DropVeilPointsScalar(cloud, cos2, &kept, &index);
  EXPECT_EQ(kept.size(), before);
  EXPECT_EQ(index.size(), before);
}

}  // namespace
}  // namespace hpose
