// The fast scorer must give exactly the reference (OctoMap) scorer's hit count for any cluster,
// template and pose.
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "tests/sanitizer_build.h"

#include "core/scoring/fast_scorer.h"
#include "core/scoring/octomap_scorer.h"
#include "core/scoring/pose_scorer.h"

namespace hpose {
namespace {

// A random blobby "object": points around a few random centres, so that templates and clusters
// overlap partially at many poses.
std::vector<Eigen::Vector3f> RandomBlob(std::mt19937& rng, int n, float spread) {
  std::uniform_real_distribution<float> u(-spread, spread), h(0.0f, 0.6f);
  std::normal_distribution<float> g(0.0f, 0.04f);
  std::vector<Eigen::Vector3f> centres;
  for (int i = 0; i < 4; ++i) centres.emplace_back(u(rng), u(rng), h(rng));
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3f& c = centres[i % centres.size()];
    pts.emplace_back(c.x() + g(rng), c.y() + g(rng), std::max(0.0f, c.z() + g(rng)));
  }
  return pts;
}

// The points of a voxelisation trial: around the origin (negative cells), blobs dense (the bits
// path) and sparse (the sort), with a NaN in every third trial and in the next one a point
// kilometres away (cell -1 250 000: the packing cannot hold it, the axis-by-axis sort).
std::vector<Eigen::Vector3f> VoxelisationTrialPoints(std::mt19937& rng, int trial) {
  const float spread[3] = {0.05f, 0.5f, 6.0f};
  std::vector<Eigen::Vector3f> pts = RandomBlob(rng, 500 + 100 * trial, spread[(trial / 3) % 3]);
  if (trial % 3 == 1) pts.emplace_back(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.1f);
  if (trial % 3 == 2) pts.emplace_back(-20000.0f, 30000.0f, 0.2f);
  return pts;
}

double VoxelisationTrialResolution(int trial) { return trial % 2 == 0 ? 0.016 : 0.01; }

// VoxeliseCluster (cells packed into words, then a bit per cell of their box or a sort) against
// a set of CellOf's cells, in (x, y, z) order, NaNs skipped.
TEST(ScorerEquivalenceTest, VoxeliseClusterEqualsTheSortedDistinctCells) {
  std::mt19937 rng(77);
  for (int trial = 0; trial < 36; ++trial) {
    const std::vector<Eigen::Vector3f> pts = VoxelisationTrialPoints(rng, trial);
    const double res = VoxelisationTrialResolution(trial);
    std::set<std::tuple<int, int, int>> expected;
    for (const Eigen::Vector3f& p : pts) {
      if (!p.allFinite()) continue;
      const Eigen::Vector3i c = CellOf(p, res);
      expected.insert({c.x(), c.y(), c.z()});
    }
    const ClusterVoxels v = VoxeliseCluster(pts, res);
    ASSERT_EQ(v.cells.size(), expected.size()) << "trial " << trial;
    size_t i = 0;
    for (const auto& [x, y, z] : expected) {
      ASSERT_EQ(v.cells[i], Eigen::Vector3i(x, y, z)) << "trial " << trial << " cell " << i;
      ++i;
    }
  }
}

// ... and with two_points_a_cell, against the CellOf cells that two or more points fall in, on
// the same three paths; a point kilometres away is a lone one, and a pair of them counts.
TEST(ScorerEquivalenceTest, VoxeliseClusterKeepsTheCellsOfTwoPointsOrMore) {
  std::mt19937 rng(78);
  for (int trial = 0; trial < 36; ++trial) {
    std::vector<Eigen::Vector3f> pts = VoxelisationTrialPoints(rng, trial);
    if (trial % 6 == 5) pts.emplace_back(-20000.0f, 30000.0f, 0.2f);  // now a pair.
    const double res = VoxelisationTrialResolution(trial);
    std::map<std::tuple<int, int, int>, int> counts;
    for (const Eigen::Vector3f& p : pts) {
      if (!p.allFinite()) continue;
      const Eigen::Vector3i c = CellOf(p, res);
      ++counts[{c.x(), c.y(), c.z()}];
    }
    std::vector<Eigen::Vector3i> expected;
    size_t lone = 0;
    for (const auto& [cell, n] : counts) {
      if (n >= 2) expected.emplace_back(std::get<0>(cell), std::get<1>(cell), std::get<2>(cell));
      lone += n == 1 ? 1 : 0;
    }
    ASSERT_GT(lone, 0u) << "trial " << trial << ": no lone point to leave out";
    ASSERT_FALSE(expected.empty()) << "trial " << trial;
    const ClusterVoxels v = VoxeliseCluster(pts, res, true);
    EXPECT_EQ(v.cells, expected) << "trial " << trial;
    EXPECT_EQ(v.cells.size() + lone, VoxeliseCluster(pts, res).cells.size()) << "trial " << trial;
  }
}

TEST(ScorerEquivalenceTest, FastEqualsReferenceOnRandomScenes) {
  std::mt19937 rng(2024);
  int compared = 0;
  int nonzero = 0;
  const int scenes = testing::kSanitizerBuild ? 6 : 40;
  for (int scene = 0; scene < scenes; ++scene) {
    PoseLattice lattice;
    lattice.subdivisions = (scene % 3 == 0) ? 3 : 4;  // also a non power of two.
    lattice.angle_steps = (scene % 5 == 0) ? 72 : 360;
    const std::vector<Eigen::Vector3f> tpl_pts = RandomBlob(rng, 800, 0.15f);
    const VoxelTemplate tpl = *MakeTemplateFromPoints(tpl_pts, "t", lattice.resolution_m);
    // The cluster sits somewhere on the floor, possibly at negative coordinates.
    std::uniform_real_distribution<float> off(-2.0f, 2.0f);
    const Eigen::Vector3f shift(off(rng), off(rng), 0.0f);
    std::vector<Eigen::Vector3f> cluster_pts = RandomBlob(rng, 600, 0.15f);
    for (auto& p : cluster_pts) p += shift;
    const ClusterVoxels cluster = VoxeliseCluster(cluster_pts, lattice.resolution_m);
    const OctomapScorer reference(cluster, lattice);
    const FastScorer fast(cluster, lattice);
    ASSERT_EQ(reference.cluster_voxels(), fast.cluster_voxels());
    std::uniform_int_distribution<int> th(0, lattice.angle_steps - 1);
    std::uniform_int_distribution<int> d(-60, 60);
    const int cx = static_cast<int>(std::lround(shift.x() / lattice.step_m()));
    const int cy = static_cast<int>(std::lround(shift.y() / lattice.step_m()));
    for (int k = 0; k < 100; ++k) {
      const RotatedTemplate r = RotateTemplate(tpl, lattice, th(rng));
      const int ix = cx + d(rng);
      const int iy = cy + d(rng);
      const int ref_hits = reference.Hits(r, ix, iy);
      ASSERT_EQ(fast.Hits(r, ix, iy), ref_hits)
          << "scene " << scene << " theta " << r.itheta << " ix " << ix << " iy " << iy;
      EXPECT_DOUBLE_EQ(fast.Score(r, ix, iy), reference.Score(r, ix, iy));
      ++compared;
      nonzero += ref_hits > 0;
    }
  }
  EXPECT_EQ(compared, 100 * scenes);
  EXPECT_GT(nonzero, 25 * scenes);  // the comparison exercised real overlaps, not only misses.
}

TEST(ScorerEquivalenceTest, DuplicatePlacementsCountOnce) {
  // Two template voxels that land in the same cluster cell after rotation count once.
  PoseLattice lattice;
  lattice.subdivisions = 1;
  VoxelTemplate tpl;
  tpl.name = "t";
  tpl.voxels = {{0.004f, 0.004f, 0.008f}, {0.012f, 0.004f, 0.008f}};  // same 16 mm cell.
  const RotatedTemplate r = RotateTemplate(tpl, lattice, 0);
  const ClusterVoxels cluster = VoxeliseCluster({{0.001f, 0.001f, 0.001f}}, 0.016);
  EXPECT_EQ(OctomapScorer(cluster, lattice).Hits(r, 0, 0), 1);
  EXPECT_EQ(FastScorer(cluster, lattice).Hits(r, 0, 0), 1);
  EXPECT_DOUBLE_EQ(FastScorer(cluster, lattice).Score(r, 0, 0), 100.0);
}

TEST(ScorerEquivalenceTest, EmptyClusterScoresZero) {
  PoseLattice lattice;
  VoxelTemplate tpl;
  tpl.name = "t";
  tpl.voxels = {{0.0f, 0.0f, 0.1f}};
  const RotatedTemplate r = RotateTemplate(tpl, lattice, 0);
  const ClusterVoxels empty;
  EXPECT_EQ(MakePoseScorer(ScorerKind::kFast, empty, lattice)->Score(r, 0, 0), 0.0);
  EXPECT_EQ(MakePoseScorer(ScorerKind::kOctomapReference, empty, lattice)->Score(r, 0, 0), 0.0);
}

}  // namespace
}  // namespace hpose
