#include "core/depth/range_image.h"

#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <utility>

#include <gtest/gtest.h>

#include "core/depth/floor_estimate.h"

namespace hpose {
namespace {

// A cloud in front of the sensor: random points over a +-40 degree view at 0.5-5 m, some NaN,
// some behind the sensor, a few almost in the optical centre's plane (slopes up to infinite),
// a few with one infinite coordinate.
PointCloud RandomCloud(unsigned seed, int n) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> tan(-0.8f, 0.8f), depth(0.5f, 5.0f);
  PointCloud cloud;
  for (int i = 0; i < n; ++i) {
    const float z = depth(rng);
    if (i % 50 == 0) {
      cloud.points.emplace_back(NAN, NAN, NAN);
    } else if (i % 71 == 0) {
      cloud.points.emplace_back(tan(rng), tan(rng), -z);
    } else if (i % 113 == 0) {
      cloud.points.emplace_back(tan(rng), tan(rng), 1e-7f);
    } else if (i % 211 == 0) {  // slopes of 1e35 and more, mostly +-inf.
      cloud.points.emplace_back(tan(rng), tan(rng), 1e-40f);
    } else if (i % 307 == 0) {  // one coordinate infinite, the others finite.
      cloud.points.emplace_back(tan(rng), INFINITY, z);
    } else {
      cloud.points.emplace_back(tan(rng) * z, tan(rng) * z, z);
    }
  }
  return cloud;
}

// Points within slopes that differ per axis and per side (x in [-0.9, 0.3), y in [-0.2, 0.6)),
// with NaN holes and points behind the sensor but no extreme slope: an image whose extent, and
// so its offsets u0 != v0, come from the points rather than from the +-3 clamp.
PointCloud UnevenCloud(unsigned seed, int n) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> tan_x(-0.9f, 0.3f), tan_y(-0.2f, 0.6f), depth(0.5f, 5.0f);
  PointCloud cloud;
  for (int i = 0; i < n; ++i) {
    const float z = depth(rng), tx = tan_x(rng), ty = tan_y(rng);
    if (i % 37 == 0) {
      cloud.points.emplace_back(NAN, NAN, NAN);
    } else if (i % 53 == 0) {
      cloud.points.emplace_back(tx * z, ty * z, -z);
    } else {
      cloud.points.emplace_back(tx * z, ty * z, z);
    }
  }
  return cloud;
}

// The reference binning: bin = floor(tan * focal + offset), tan = x / z in float as the sensor
// frame's points are, over the cloud's own tangent extent
// (clamped to +-3), nearest z per bin.
TEST(RangeImageTest, NearestDepthPerBinEqualsAStraightforwardReference) {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    // Sizes not a multiple of four too: FromCloud bins four points a step, then the rest. The
    // last two clouds set their extent themselves (no slope reaches the +-3 clamp).
    const PointCloud cloud = seed <= 4 ? RandomCloud(seed, 20000 + static_cast<int>(seed))
                                       : UnevenCloud(seed, 20000 + static_cast<int>(seed));
    const double focal = 300.0;
    const RangeImage image = RangeImage::FromCloud(cloud, focal);
    double tx_lo = 3.0, ty_lo = 3.0, tx_hi = -3.0, ty_hi = -3.0;
    for (const Eigen::Vector3f& p : cloud.points) {
      if (!p.allFinite() || p.z() <= 0.0f) continue;
      tx_lo = std::min(tx_lo, static_cast<double>(p.x() / p.z()));
      ty_lo = std::min(ty_lo, static_cast<double>(p.y() / p.z()));
      tx_hi = std::max(tx_hi, static_cast<double>(p.x() / p.z()));
      ty_hi = std::max(ty_hi, static_cast<double>(p.y() / p.z()));
    }
    tx_lo = std::max(tx_lo, -3.0);
    ty_lo = std::max(ty_lo, -3.0);
    tx_hi = std::min(tx_hi, 3.0);
    ty_hi = std::min(ty_hi, 3.0);
    const int width = static_cast<int>((tx_hi - tx_lo) * focal) + 1;
    const int height = static_cast<int>((ty_hi - ty_lo) * focal) + 1;
    ASSERT_EQ(image.width(), width);
    ASSERT_EQ(image.height(), height);
    EXPECT_DOUBLE_EQ(image.TopTan(), ty_lo);
    std::map<std::pair<int, int>, float> nearest;
    for (const Eigen::Vector3f& p : cloud.points) {
      if (!p.allFinite() || p.z() <= 0.0f) continue;
      const double u = std::floor(static_cast<double>(p.x() / p.z()) * focal - tx_lo * focal);
      const double v = std::floor(static_cast<double>(p.y() / p.z()) * focal - ty_lo * focal);
      if (!(u >= 0 && v >= 0 && u < width && v < height)) continue;
      const std::pair<int, int> bin(static_cast<int>(u), static_cast<int>(v));
      auto it = nearest.find(bin);
      if (it == nearest.end() || p.z() < it->second) nearest[bin] = p.z();
    }
    ASSERT_GT(nearest.size(), 1000u);
    for (const auto& [bin, z] : nearest) {
      // Ask along the ray through the bin's centre.
      const Eigen::Vector3d ray((bin.first + 0.5) / focal + tx_lo,
                                (bin.second + 0.5) / focal + ty_lo, 1.0);
      EXPECT_EQ(image.DepthToward(ray), z) << "bin " << bin.first << ", " << bin.second;
    }
    // Bins without a point are unknown.
    int empty = 0;
    for (int v = 0; v < height; v += 7) {
      for (int u = 0; u < width; u += 7) {
        if (nearest.count({u, v}) > 0) continue;
        ++empty;
        EXPECT_EQ(image.DepthToward(
                      Eigen::Vector3d((u + 0.5) / focal + tx_lo, (v + 0.5) / focal + ty_lo, 1.0)),
                  0.0f);
      }
    }
    EXPECT_GT(empty, 0);
  }
}

TEST(RangeImageTest, EmptyAndBehindTheSensorGiveAnEmptyImage) {
  PointCloud cloud;
  cloud.points.emplace_back(0.0f, 0.0f, -1.0f);
  cloud.points.emplace_back(NAN, 0.0f, 1.0f);
  const RangeImage image = RangeImage::FromCloud(cloud);
  EXPECT_EQ(image.width(), 0);
  EXPECT_EQ(image.DepthToward(Eigen::Vector3d(0, 0, 1)), 0.0f);
  EXPECT_FALSE(image.Covers(Eigen::Vector3d(0, 0, 1)));
}

// A view's known edges widen the image past its points' extent, never narrow it: rays within
// the edges and beyond every point are covered (an empty bin: no return), the points' bins and
// depths are those of the image without edges, and unknown (NaN) edges change nothing.
TEST(RangeImageTest, KnownEdgesWidenTheImageToTheView) {
  PointCloud cloud;  // a patch 0.2 wide and 0.1 high (slopes) about the optical axis, 2 m away.
  for (int i = 0; i <= 20; ++i) {
    for (int j = 0; j <= 10; ++j) {
      cloud.points.emplace_back(2.0f * (-0.1f + 0.01f * i), 2.0f * (-0.05f + 0.01f * j), 2.0f);
    }
  }
  ViewSpan view;
  view.left = -0.6;
  view.right = 0.55;
  view.top = -0.45;
  view.bottom = 0.4;
  const RangeImage own = RangeImage::FromCloud(cloud);
  const RangeImage wide = RangeImage::FromCloud(cloud, 300.0, view);
  const RangeImage four = RangeImage::FromCloudFourLanes(cloud, 300.0, view);
  const Eigen::Vector3d above(0.0, -0.3, 1.0), right(0.5, 0.0, 1.0), beyond(0.0, -0.5, 1.0);
  EXPECT_FALSE(own.Covers(above));
  EXPECT_FALSE(own.Covers(right));
  EXPECT_TRUE(wide.Covers(above));
  EXPECT_TRUE(wide.Covers(right));
  EXPECT_FALSE(wide.Covers(beyond));  // above the view's top.
  EXPECT_EQ(wide.DepthToward(above), 0.0f);
  EXPECT_NEAR(wide.TopTan(), -0.45, 1.0 / 300.0);
  EXPECT_NEAR(wide.width(), 1.15 * 300.0, 1.0);
  EXPECT_NEAR(wide.height(), 0.85 * 300.0, 1.0);
  ASSERT_EQ(four.width(), wide.width());
  ASSERT_EQ(four.height(), wide.height());
  EXPECT_EQ(std::memcmp(four.depth_data(), wide.depth_data(),
                        sizeof(float) * static_cast<size_t>(wide.width()) * wide.height()),
            0);
  int known = 0;
  for (const Eigen::Vector3f& p : cloud.points) {
    EXPECT_EQ(wide.DepthToward(p.cast<double>()), own.DepthToward(p.cast<double>()));
    known += wide.DepthToward(p.cast<double>()) > 0.0f;
  }
  EXPECT_EQ(known, static_cast<int>(cloud.points.size()));
  // Edges inside the points' extent, or unknown, leave the points' extent.
  ViewSpan narrow;
  narrow.left = -0.05;
  narrow.top = 0.0;
  for (const ViewSpan& v : {narrow, ViewSpan{}}) {
    const RangeImage same = RangeImage::FromCloud(cloud, 300.0, v);
    EXPECT_EQ(same.width(), own.width());
    EXPECT_EQ(same.height(), own.height());
    EXPECT_EQ(same.u0(), own.u0());
    EXPECT_EQ(same.v0(), own.v0());
  }
}

// A wider pass (`build`) against the four-lane one, to the bit: the same extent, offsets and
// depths in every bin, on clouds with NaN, points behind the sensor, near-infinite slopes and
// infinite coordinates, and on uneven ones whose extent the points set, of sizes with and
// without a remainder of sixteen (and of eight).
template <typename Build>
void ExpectEqualToFourLanes(const Build& build) {
  int bins = 0;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    const PointCloud cloud = seed <= 6 ? RandomCloud(seed, 30000 + 7 * static_cast<int>(seed))
                                       : UnevenCloud(seed, 20000 + 5 * static_cast<int>(seed));
    for (const double focal : {300.0, 97.5}) {
      const RangeImage wide = build(cloud, focal);
      const RangeImage four = RangeImage::FromCloudFourLanes(cloud, focal);
      ASSERT_EQ(wide.width(), four.width());
      ASSERT_EQ(wide.height(), four.height());
      ASSERT_GT(four.width(), 0);
      EXPECT_EQ(wide.u0(), four.u0());
      EXPECT_EQ(wide.v0(), four.v0());
      const size_t n = static_cast<size_t>(four.width()) * four.height();
      EXPECT_EQ(std::memcmp(wide.depth_data(), four.depth_data(), n * sizeof(float)), 0)
          << "seed " << seed << " focal " << focal;
      for (size_t k = 0; k < n; ++k) bins += four.depth_data()[k] > 0.0f ? 1 : 0;
    }
  }
  EXPECT_GT(bins, 50000);
}

TEST(RangeImageTest, SixteenLanesEqualFourLanesToTheBit) {
  if (!RangeImage::SixteenLanes()) {
    GTEST_SKIP() << "no AVX-512 on this CPU: FromCloud does not take the sixteen-lane path";
  }
  ExpectEqualToFourLanes(
      [](const PointCloud& c, double focal) { return RangeImage::FromCloud(c, focal); });
}

TEST(RangeImageTest, EightLanesEqualFourLanesToTheBit) {
  if (!RangeImage::EightLanes()) GTEST_SKIP() << "no AVX2 on this CPU";
  ExpectEqualToFourLanes(
      [](const PointCloud& c, double focal) { return RangeImage::FromCloudEightLanes(c, focal); });
}

// How far below the horizon the ray through the centre of bin (u, v) points, worked out
// directly: the ray's unit direction in the ground frame, and its angle below the x-y plane.
double RayDownDeg(const RangeImage& image, const Eigen::Isometry3d& ground_from_sensor, int u,
                  int v) {
  const Eigen::Vector3d ray = Eigen::Vector3d((u + 0.5 - image.u0()) / image.focal(),
                                              (v + 0.5 - image.v0()) / image.focal(), 1.0)
                                  .normalized();
  return std::asin(-(ground_from_sensor.linear() * ray).z()) * 180.0 / M_PI;
}

Eigen::Isometry3d Mount(double pitch_deg, double roll_deg) {
  return FloorEstimate::FromHeightPitchRoll(2.5, pitch_deg * M_PI / 180.0, roll_deg * M_PI / 180.0)
      .ground_from_sensor;
}

// Bins whose ray points at least 70 degrees down take the nearest known depth of the 3 x 3 bins
// around them; the others, and the unknown bins, stay as they were.
TEST(RangeImageTest, SteepRaysTakeTheNearestOfTheirNineBins) {
  const RangeImage image = RangeImage::FromCloud(RandomCloud(5, 30000), 97.5);
  const Eigen::Isometry3d mount = Mount(55.0, 6.0);
  const RangeImage steep = image.NearestAroundSteepRays(mount, 70.0 * M_PI / 180.0);
  ASSERT_EQ(steep.width(), image.width());
  ASSERT_EQ(steep.height(), image.height());
  const int w = image.width(), h = image.height();
  const float* in = image.depth_data();
  const float* out = steep.depth_data();
  int changed = 0, steep_bins = 0, kept = 0;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      const double down = RayDownDeg(image, mount, u, v);
      if (std::abs(down - 70.0) < 1e-6) continue;  // too near the limit to call.
      if (!(in[i] > 0.0f) || down < 70.0) {
        EXPECT_EQ(out[i], in[i]) << u << ", " << v;
        ++kept;
        continue;
      }
      float nearest = in[i];
      for (int y = std::max(0, v - 1); y <= std::min(h - 1, v + 1); ++y) {
        for (int x = std::max(0, u - 1); x <= std::min(w - 1, u + 1); ++x) {
          const float d = in[static_cast<size_t>(y) * w + x];
          if (d > 0.0f) nearest = std::min(nearest, d);
        }
      }
      EXPECT_EQ(out[i], nearest) << u << ", " << v;
      ++steep_bins;
      changed += out[i] != in[i] ? 1 : 0;
    }
  }
  EXPECT_GT(steep_bins, 500);
  EXPECT_GT(changed, 100);
  EXPECT_GT(kept, 500);
}

// HasSteepRays says whether any bin's ray is that steep: against every bin, on mounts whose
// steepest ray lies on the image's border, inside it (straight down), or nowhere near.
TEST(RangeImageTest, HasSteepRaysAgreesWithEveryBin) {
  const RangeImage image = RangeImage::FromCloud(RandomCloud(6, 20000), 97.5);
  // (pitch, roll) in degrees.
  const std::vector<std::pair<double, double>> mounts = {
      {0.0, 0.0},   {30.0, 10.0}, {40.0, 0.0},  {45.0, 20.0}, {60.0, -5.0}, {75.0, 0.0},
      {85.0, 30.0}, {89.9, 0.0},  {-10.0, 0.0}, {-20.0, 3.0}, {10.0, 5.0}};
  int yes = 0, no = 0;
  for (const auto& [pitch, roll] : mounts) {
    const Eigen::Isometry3d mount = Mount(pitch, roll);
    for (const double limit_deg : {50.0, 70.0, 88.0}) {
      bool any = false;
      for (int v = 0; v < image.height() && !any; ++v) {
        for (int u = 0; u < image.width() && !any; ++u) {
          any = RayDownDeg(image, mount, u, v) >= limit_deg;
        }
      }
      EXPECT_EQ(image.HasSteepRays(mount, limit_deg * M_PI / 180.0), any)
          << "pitch " << pitch << ", roll " << roll << ", limit " << limit_deg;
      (any ? yes : no) += 1;
    }
  }
  EXPECT_GT(yes, 5);
  EXPECT_GT(no, 5);
  EXPECT_FALSE(RangeImage().HasSteepRays(Mount(89.9, 0.0), 0.0));
}

}  // namespace
}  // namespace hpose
