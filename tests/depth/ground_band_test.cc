#include "core/depth/ground_band.h"

#include <cmath>
#include <cstring>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

namespace hpose {
namespace {

// A sensor 0.6-1.2 m up, pitched down, over random points: some NaN or infinite, some exactly
// on the band's limits (through the inverse transform), counts with and without a remainder of
// sixteen.
struct Scene {
  PointCloud cloud;
  GroundBand band;
};

Scene RandomScene(unsigned seed, int n) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Scene s;
  const Eigen::Matrix3f r = (Eigen::AngleAxisf(0.3f * u(rng), Eigen::Vector3f::UnitZ()) *
                             Eigen::AngleAxisf(-1.9f + 0.2f * u(rng), Eigen::Vector3f::UnitX()))
                                .toRotationMatrix();
  s.band.rotation = r;
  s.band.translation = Eigen::Vector3f(0.05f * u(rng), 0.05f * u(rng), 0.9f + 0.3f * u(rng));
  s.band.z_min = 0.02f;
  s.band.z_max = 1.6f;
  s.band.range2 = 3.5f * 3.5f;
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3f p(2.0f * u(rng), 1.5f * u(rng), 2.5f + 2.0f * u(rng));
    if (i % 37 == 0) p.x() = NAN;
    if (i % 53 == 0) p.z() = INFINITY;
    if (i % 29 == 0) {  // a point whose height lands on (or within a rounding of) a limit.
      const Eigen::Vector3f g(u(rng), u(rng), i % 58 == 0 ? s.band.z_min : s.band.z_max);
      p = r.transpose() * (g - s.band.translation);
    }
    s.cloud.points.push_back(p);
  }
  return s;
}

TEST(GroundBandTest, KeepsWhatTheDefinitionKeepsInOrder) {
  const Scene s = RandomScene(3, 5000);
  std::vector<Eigen::Vector3f> out;
  std::vector<int> index;
  SelectGroundBand(s.cloud, s.band, &out, &index);
  ASSERT_EQ(out.size(), index.size());
  size_t k = 0;
  for (size_t i = 0; i < s.cloud.points.size(); ++i) {
    const Eigen::Vector3f& p = s.cloud.points[i];
    if (!p.allFinite()) continue;
    const Eigen::Vector3f g = s.band.rotation * p + s.band.translation;
    if (g.z() < s.band.z_min || g.z() > s.band.z_max) continue;
    if (g.head<2>().squaredNorm() > s.band.range2) continue;
    ASSERT_LT(k, out.size());
    EXPECT_EQ(index[k], static_cast<int>(i));
    EXPECT_EQ(out[k], g) << "point " << i;
    ++k;
  }
  EXPECT_EQ(k, out.size());
  EXPECT_GT(k, 1000u);
  EXPECT_LT(k, s.cloud.points.size() - 500);
}

// An empty cloud adds nothing (and what the output held stays); a cloud shorter than sixteen
// points takes the scalar loop alone.
TEST(GroundBandTest, EmptyAndShortClouds) {
  const Scene s = RandomScene(5, 7);
  std::vector<Eigen::Vector3f> out(2, Eigen::Vector3f::Ones());
  std::vector<int> index(2, 4);
  SelectGroundBand(PointCloud(), s.band, &out, &index);
  EXPECT_EQ(out.size(), 2u);
  EXPECT_EQ(index, std::vector<int>(2, 4));
  std::vector<Eigen::Vector3f> ref;
  SelectGroundBand(s.cloud, s.band, &out);
  SelectGroundBandScalar(s.cloud, s.band, &ref);
  ASSERT_EQ(out.size(), 2 + ref.size());
  for (size_t k = 0; k < ref.size(); ++k) EXPECT_EQ(out[2 + k], ref[k]);
}

// The vector paths against the scalar reference, to the bit, appending after what the output
// already holds: the dispatched one (AVX-512 or AVX2, whichever the CPU has) and AVX2's.
void ExpectEqualToTheScalarReference(void (*select)(const PointCloud&, const GroundBand&,
                                                    std::vector<Eigen::Vector3f>*,
                                                    std::vector<int>*),
                                     const char* name) {
  size_t compared = 0;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    const Scene s = RandomScene(seed, 20000 + 5 * static_cast<int>(seed));
    std::vector<Eigen::Vector3f> fast(3, Eigen::Vector3f::Ones()), ref = fast;
    std::vector<int> fast_index(3, -1), ref_index = fast_index;
    select(s.cloud, s.band, &fast, &fast_index);
    SelectGroundBandScalar(s.cloud, s.band, &ref, &ref_index);
    ASSERT_EQ(fast.size(), ref.size()) << name << " seed " << seed;
    EXPECT_EQ(fast_index, ref_index) << name << " seed " << seed;
    EXPECT_EQ(std::memcmp(fast.data(), ref.data(), ref.size() * sizeof(Eigen::Vector3f)), 0)
        << name << " seed " << seed;
    // Without indices: the same points.
    std::vector<Eigen::Vector3f> alone;
    select(s.cloud, s.band, &alone, nullptr);
    ASSERT_EQ(alone.size() + 3, ref.size()) << name;
    EXPECT_EQ(std::memcmp(alone.data(), ref.data() + 3, alone.size() * sizeof(Eigen::Vector3f)), 0)
        << name;
    compared += ref.size() - 3;
  }
  EXPECT_GT(compared, 40000u) << name;
}

TEST(GroundBandTest, VectorisedEqualsTheScalarReferenceToTheBit) {
  if (!GroundBandVectorised()) {
    GTEST_SKIP() << "no AVX-512 or AVX2 on this CPU: SelectGroundBand is the scalar loop itself";
  }
  ExpectEqualToTheScalarReference(SelectGroundBand, "dispatched");
}

TEST(GroundBandTest, EightPointsAStepEqualTheScalarReferenceToTheBit) {
  if (!GroundBandAvx2Available()) GTEST_SKIP() << "no AVX2 on this CPU";
  ExpectEqualToTheScalarReference(SelectGroundBandAvx2, "avx2");
}

}  // namespace
}  // namespace hpose
