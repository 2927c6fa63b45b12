#include "core/depth/neighbour_sampler.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace hpose {
namespace {

std::vector<Eigen::Vector3f> RandomBox(int n, const Eigen::Vector3f& size, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < n; ++i) {
    points.emplace_back(size.x() * unit(rng) - 0.5f * size.x(), size.y() * unit(rng),
                        size.z() * unit(rng) + 0.7f);
  }
  return points;
}

bool Contains(const std::vector<int>& v, int x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}

// Every draw is a pair of distinct neighbours from the listed ones, and a draw fails exactly
// when fewer than two are listed.
TEST(NeighbourSamplerTest, DrawsOnlyNeighboursAndFailsOnlyWithoutTwo) {
  const std::vector<Eigen::Vector3f> points = RandomBox(600, {3.0f, 0.8f, 3.0f}, 7);
  NeighbourSampler sampler(points, 0.25f);
  std::mt19937 rng(1);
  std::vector<int> listed;
  int isolated = 0;
  for (int centre = 0; centre < static_cast<int>(points.size()); ++centre) {
    sampler.Neighbours(centre, &listed);
    for (int draw = 0; draw < 5; ++draw) {
      int a = -1, b = -1;
      const bool ok = sampler.DrawPair(centre, &rng, &a, &b);
      ASSERT_EQ(ok, listed.size() >= 2) << "centre " << centre;
      if (!ok) {
        ++isolated;
        continue;
      }
      EXPECT_NE(a, b);
      EXPECT_NE(a, centre);
      EXPECT_NE(b, centre);
      EXPECT_TRUE(Contains(listed, a)) << "centre " << centre << " drew " << a;
      EXPECT_TRUE(Contains(listed, b)) << "centre " << centre << " drew " << b;
    }
  }
  EXPECT_GT(isolated, 0);  // the sparse cloud has points with fewer than two neighbours.
}

// Every neighbour is drawn about equally often (each draw of a pair picks one of n in 2/n),
// wherever in the 27 cells around the centre it lies.
TEST(NeighbourSamplerTest, DrawsEveryNeighbourEvenly) {
  const std::vector<Eigen::Vector3f> points = RandomBox(3000, {2.0f, 2.0f, 2.0f}, 11);
  const float radius = 0.4f;
  NeighbourSampler sampler(points, radius);
  std::mt19937 rng(3);
  for (const int centre : {0, 1, 2}) {
    std::vector<int> listed;
    sampler.Neighbours(centre, &listed);
    ASSERT_GE(listed.size(), 30u);
    const int draws = 400 * static_cast<int>(listed.size());
    std::map<int, int> count;
    for (int d = 0; d < draws; ++d) {
      int a = -1, b = -1;
      ASSERT_TRUE(sampler.DrawPair(centre, &rng, &a, &b));
      ++count[a];
      ++count[b];
    }
    EXPECT_EQ(count.size(), listed.size()) << "some neighbour was never drawn";
    const double expected = 2.0 * draws / listed.size();  // 800
    for (const int i : listed) {
      EXPECT_NEAR(count[i], expected, 6.0 * std::sqrt(expected)) << "neighbour " << i;
    }
  }
}

// Two neighbours among many points of the same cells that are not: the draws that miss give
// way to the list, which finds them.
TEST(NeighbourSamplerTest, FindsTheFewNeighboursAmongManyPointsOfTheCells) {
  std::vector<Eigen::Vector3f> points;
  points.emplace_back(0.5f, 0.5f, 0.5f);  // the centre, in the middle of its cell.
  points.emplace_back(0.5f, 0.5f, 0.6f);
  points.emplace_back(0.6f, 0.5f, 0.5f);
  for (int i = 0; i < 400; ++i) {  // corners of the 27 cells, all farther than the radius.
    const float t = 0.001f * i;
    points.emplace_back(-0.95f + t, -0.95f, -0.95f);
    points.emplace_back(1.95f - t, 1.95f, 1.95f);
  }
  NeighbourSampler sampler(points, 1.0f);
  std::mt19937 rng(5);
  for (int d = 0; d < 20; ++d) {
    int a = -1, b = -1;
    ASSERT_TRUE(sampler.DrawPair(0, &rng, &a, &b));
    EXPECT_EQ(std::min(a, b), 1);
    EXPECT_EQ(std::max(a, b), 2);
  }
  std::vector<Eigen::Vector3f> one_neighbour(points.begin(), points.begin() + 2);
  for (int i = 3; i < 50; ++i) one_neighbour.push_back(points[i]);
  NeighbourSampler lonely(one_neighbour, 1.0f);
  int a = -1, b = -1;
  EXPECT_FALSE(lonely.DrawPair(0, &rng, &a, &b));
}

// Points beyond the cells' 21-bit range share the outermost cells and still find each other.
TEST(NeighbourSamplerTest, FarPointsAreClampedIntoTheOutermostCells) {
  const std::vector<Eigen::Vector3f> points = {{5.0e5f, 0.0f, 0.0f},
                                               {5.0e5f + 0.125f, 0.0f, 0.0f},
                                               {5.0e5f, 0.125f, 0.0f},
                                               {-5.0e5f, 0.0f, 0.0f},
                                               {0.0f, 0.0f, 0.0f}};
  NeighbourSampler sampler(points, 0.2f);
  std::mt19937 rng(9);
  int a = -1, b = -1;
  ASSERT_TRUE(sampler.DrawPair(0, &rng, &a, &b));
  EXPECT_EQ(std::min(a, b), 1);
  EXPECT_EQ(std::max(a, b), 2);
  EXPECT_FALSE(sampler.DrawPair(3, &rng, &a, &b));
  EXPECT_FALSE(sampler.DrawPair(4, &rng, &a, &b));
}

}  // namespace
}  // namespace hpose
