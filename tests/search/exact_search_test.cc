// The exact search must find the maximum score of exhaustive evaluation of the same lattice.
#include "core/search/exact_search.h"

#include <algorithm>
#include <climits>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <tuple>
#include <utility>

#include <gtest/gtest.h>

#include "core/scoring/column_occupancy.h"
#include "core/scoring/fast_scorer.h"
#include "core/scoring/octomap_scorer.h"
#include "tests/sanitizer_build.h"
#include "tests/search/search_test_scenes.h"

namespace hpose {
namespace {

struct Exhaustive {
  int best_hits = -1;
  std::int64_t poses = 0;
};

Exhaustive Brute(const PoseScorer& scorer, const TemplateRotations& rot,
                 const ExactSearch::Region& r, const std::vector<int>& thetas) {
  Exhaustive e;
  for (int t : thetas) {
    for (int ix = r.ix_min; ix <= r.ix_max; ++ix) {
      for (int iy = r.iy_min; iy <= r.iy_max; ++iy) {
        e.best_hits = std::max(e.best_hits, scorer.Hits(rot.Get(t), ix, iy));
        ++e.poses;
      }
    }
  }
  return e;
}

// Random free cells around the cluster (not on it), as a sensor might see them: `count` draws
// within 20 cells across of its middle cell and in [0, z_max] up.
ClusterVoxels RandomFreeCells(const ClusterVoxels& cluster, int count, int z_max,
                              std::mt19937* rng) {
  ClusterVoxels free;
  std::uniform_int_distribution<int> dx(-20, 20), dz(0, z_max);
  const Eigen::Vector3i c0 = cluster.cells[cluster.cells.size() / 2];
  std::set<std::tuple<int, int, int>> occupied, free_set;
  for (const Eigen::Vector3i& c : cluster.cells) occupied.insert({c.x(), c.y(), c.z()});
  for (int k = 0; k < count; ++k) {
    const std::tuple<int, int, int> c{c0.x() + dx(*rng), c0.y() + dx(*rng), dz(*rng)};
    if (occupied.count(c) == 0) free_set.insert(c);
  }
  for (const auto& [x, y, z] : free_set) free.cells.emplace_back(x, y, z);
  return free;
}

// Cells (cx, cy) of a cell table with their z bits.
using CellMasks = std::map<std::pair<int, int>, std::uint64_t>;

// The cells of both with the bits both set there (cells left with none left out).
CellMasks CommonCells(const CellMasks& a, const CellMasks& b) {
  CellMasks kept;
  for (const auto& [cell, mask] : a) {
    const auto it = b.find(cell);
    if (it != b.end() && (mask & it->second) != 0) kept[cell] = mask & it->second;
  }
  return kept;
}

// The optimum of hit_weight * hits - free_weight * free hits over every heading and the region,
// and among the poses of its value the first in (itheta, ix, iy) order: the one the search
// returns, whatever its options.
struct WeightedOptimum {
  int value = INT_MIN;
  LatticePose first;
};

WeightedOptimum BruteWeighted(const PoseScorer& scorer, const PoseScorer& free_scorer,
                              const TemplateRotations& rot, const ExactSearch::Region& region,
                              int hit_weight, int free_weight) {
  WeightedOptimum o;
  for (int t = 0; t < rot.lattice().angle_steps; ++t) {
    for (int ix = region.ix_min; ix <= region.ix_max; ++ix) {
      for (int iy = region.iy_min; iy <= region.iy_max; ++iy) {
        const int v = hit_weight * scorer.Hits(rot.Get(t), ix, iy) -
                      free_weight * free_scorer.Hits(rot.Get(t), ix, iy);
        if (v > o.value) {
          o.value = v;
          o.first = LatticePose{ix, iy, t};
        }
      }
    }
  }
  return o;
}

TEST(ColumnOccupancyTest, HitsEqualReferenceAndBoundsAreUpperBounds) {
  std::mt19937 rng(5);
  for (unsigned scene = 0; scene < 12; ++scene) {
    PoseLattice lattice;
    lattice.subdivisions = scene % 4 == 3 ? 3 : 4;
    const VoxelTemplate tpl =
        *MakeTemplateFromPoints(testing::RandomRobotPoints(scene), "t", lattice.resolution_m);
    const Pose2D truth{0.9 + 0.1 * scene, -0.3 + 0.05 * scene, DegToRad(17.0 * scene)};
    const ClusterVoxels cluster = VoxeliseCluster(
        testing::VisibleCluster(testing::RandomRobotPoints(scene), truth, 0.004f, scene),
        lattice.resolution_m);
    const TemplateRotations rot(tpl, lattice);
    const OctomapScorer reference(cluster, lattice);
    const ColumnOccupancy occ(cluster, lattice, rot.Get(0).z_base, rot.Get(0).z_words, 5);
    const LatticePose c = NearestLatticePose(lattice, truth);
    std::uniform_int_distribution<int> d(-40, 40), th(0, 359);
    for (int k = 0; k < 150; ++k) {
      const int t = k % 3 == 0 ? c.itheta : th(rng);
      const int a = c.ix + d(rng), b = c.iy + d(rng);
      const RotatedTemplate& r = rot.Get(t);
      const int exact = reference.Hits(r, a, b);
      ASSERT_EQ(occ.Hits(r, a, b), exact) << "scene " << scene;
      for (int level = 1; level <= 5; ++level) {
        // The block starting here contains (a, b) ... and the bound covers every pose in it.
        const int a0 = a - (k % (1 << level)), b0 = b - ((k / 2) % (1 << level));
        ASSERT_GE(occ.Bound(r, a0, b0, level), exact) << "level " << level;
      }
    }
  }
}

// A theta block's bound covers every rotation of the block at every translation of the
// translation block: the arcs its columns sweep are part of the bound, at every level and on
// both subdivisions (power of two and not), including levels whose arcs pass the top level.
TEST(ColumnOccupancyTest, ThetaBlockBoundsCoverEveryRotationOfTheBlock) {
  std::mt19937 rng(11);
  int checked = 0, arcs_past_top = 0;
  for (unsigned scene = 0; scene < 6; ++scene) {
    PoseLattice lattice;
    lattice.subdivisions = scene % 2 == 1 ? 3 : 4;
    const VoxelTemplate tpl =
        *MakeTemplateFromPoints(testing::RandomRobotPoints(scene), "t", lattice.resolution_m);
    const Pose2D truth{1.0 + 0.1 * scene, 0.2 - 0.07 * scene, DegToRad(31.0 * scene)};
    const ClusterVoxels cluster = VoxeliseCluster(
        testing::VisibleCluster(testing::RandomRobotPoints(scene), truth, 0.004f, scene),
        lattice.resolution_m);
    const TemplateRotations rot(tpl, lattice);
    ASSERT_GT(rot.max_block_extent(), 0);
    // Hits equals the OctoMap reference (HitsEqualReferenceAndBoundsAreUpperBounds).
    const ColumnOccupancy occ(cluster, lattice, rot.Get(0).z_base, rot.Get(0).z_words, 4);
    const LatticePose c = NearestLatticePose(lattice, truth);
    std::uniform_int_distribution<int> d(-30, 30), th(0, 359), tl(1, 4), off(0, 1 << 20);
    for (int k = 0; k < 60; ++k) {
      const int tlevel = tl(rng);
      const int t0 = (th(rng) >> tlevel) << tlevel;
      const RotatedTemplate& block = rot.GetBlock(tlevel, t0);
      ASSERT_EQ(block.column_extent.size(), block.column_q.size());
      const int level = k % 5;
      const int a0 = c.ix + d(rng), b0 = c.iy + d(rng);
      const int bound = occ.Bound(block, a0, b0, level);
      int four[4];
      if (level < 4) occ.Bound4(block, a0, b0, level, four);
      for (int t = t0; t < std::min(360, t0 + (1 << tlevel)); ++t) {
        for (int s = 0; s < 4; ++s) {  // translations in the block, corners included.
          const int da = s < 2 ? (s == 0 ? 0 : (1 << level) - 1) : off(rng) % (1 << level);
          const int db = s < 2 ? (s == 0 ? 0 : (1 << level) - 1) : off(rng) % (1 << level);
          const int exact = occ.Hits(rot.Get(t), a0 + da, b0 + db);
          ASSERT_GE(bound, exact) << "scene " << scene << " tlevel " << tlevel << " level "
                                  << level;
          if (level < 4) {
            for (int q = 0; q < 4; ++q) {
              const int qa = a0 + (q / 2) * (1 << level) + da,
                        qb = b0 + (q % 2) * (1 << level) + db;
              ASSERT_GE(four[q], occ.Hits(rot.Get(t), qa, qb)) << "quarter " << q;
            }
          }
          ++checked;
        }
      }
      // The arcs are never looser than counting every voxel of the block once.
      int voxels = 0;
      for (std::uint64_t m : block.column_masks) voxels += __builtin_popcountll(m);
      EXPECT_LE(bound, voxels);
      const int widest = *std::max_element(block.column_extent.begin(), block.column_extent.end());
      if ((1 << level) - 1 + widest > (1 << 4) - 1) ++arcs_past_top;
    }
  }
  EXPECT_GT(checked, 1000);
  EXPECT_GT(arcs_past_top, 0) << "no bound had a column past the top level";
}

// The aligned layout (one box for every level, per-column cell tables) gives exactly the bounds
// of the per-level layout, for rotations and theta blocks, single and four-quarter bounds.
TEST(ColumnOccupancyTest, AlignedBoundsEqualThePerLevelOnes) {
  std::mt19937 rng(17);
  for (unsigned scene = 0; scene < 4; ++scene) {
    const PoseLattice lattice;  // 4 subdivisions.
    const VoxelTemplate tpl =
        *MakeTemplateFromPoints(testing::RandomRobotPoints(scene), "t", lattice.resolution_m);
    const Pose2D truth{1.1, -0.1 * scene, DegToRad(47.0 * scene)};
    const ClusterVoxels cluster = VoxeliseCluster(
        testing::VisibleCluster(testing::RandomRobotPoints(scene), truth, 0.004f, scene),
        lattice.resolution_m);
    const TemplateRotations rot(tpl, lattice);
    const LatticePose c = NearestLatticePose(lattice, truth);
    const int reach = 48;  // steps the tested blocks start from the truth.
    ColumnOccupancy::CellRange range;
    range.x_lo = FloorDiv(c.ix - reach, 4) + FloorDiv(rot.column_q_min().x(), 4);
    range.y_lo = FloorDiv(c.iy - reach, 4) + FloorDiv(rot.column_q_min().y(), 4);
    range.x_hi = FloorDiv(c.ix + reach + 64, 4) + FloorDiv(rot.column_q_max().x(), 4);
    range.y_hi = FloorDiv(c.iy + reach + 64, 4) + FloorDiv(rot.column_q_max().y(), 4);
    const int z_base = rot.Get(0).z_base, z_words = rot.Get(0).z_words;
    {
      // Aligned levels are written only around their voxels, in buffers that earlier levels
      // gave back (ZeroedWords): first a cluster of every cell and height of the box, so that
      // each buffer the levels below reuse was written everywhere.
      ClusterVoxels full;
      for (int y = range.y_lo - 20; y <= range.y_hi; ++y) {
        for (int x = range.x_lo - 20; x <= range.x_hi; ++x) {
          for (int z = 0; z < 64; ++z) full.cells.emplace_back(x, y, z_base + z);
        }
      }
      const ColumnOccupancy dense(full, lattice, z_base, z_words, 7, ColumnOccupancy::Filter::kMax,
                                  &range);
      const ColumnOccupancy dense_min(full, lattice, z_base, z_words, 7,
                                      ColumnOccupancy::Filter::kMin, &range);
      ASSERT_TRUE(dense.aligned() && dense_min.aligned());
    }
    const ColumnOccupancy plain(cluster, lattice, z_base, z_words, 7);
    const ColumnOccupancy aligned(cluster, lattice, z_base, z_words, 7,
                                  ColumnOccupancy::Filter::kMax, &range);
    const ColumnOccupancy plain_min(cluster, lattice, z_base, z_words, 7,
                                    ColumnOccupancy::Filter::kMin);
    const ColumnOccupancy aligned_min(cluster, lattice, z_base, z_words, 7,
                                      ColumnOccupancy::Filter::kMin, &range);
    std::uniform_int_distribution<int> d(-reach / 4, reach / 4), th(0, 359), tl(0, 4), lv(2, 6);
    for (int k = 0; k < 300; ++k) {
      const int tlevel = tl(rng);
      const RotatedTemplate& r = rot.GetBlock(tlevel, (th(rng) >> tlevel) << tlevel);
      const int level = lv(rng);
      const int a = 4 * (FloorDiv(c.ix, 4) + d(rng)), b = 4 * (FloorDiv(c.iy, 4) + d(rng));
      ASSERT_EQ(aligned.Bound(r, a, b, level), plain.Bound(r, a, b, level))
          << "scene " << scene << " tlevel " << tlevel << " level " << level;
      int x[4], y[4];
      aligned.Bound4(r, a, b, level, x);
      plain.Bound4(r, a, b, level, y);
      for (int q = 0; q < 4; ++q) ASSERT_EQ(x[q], y[q]) << "quarter " << q << " level " << level;
      if (tlevel == 0) {  // blocks of two steps at every even residue, both filters.
        const std::vector<std::uint64_t> dm = CellDisjointMasks(r, lattice.subdivisions);
        for (int ra = 0; ra < 4; ra += 2) {
          for (int rb = 0; rb < 4; rb += 2) {
            const PairBlockTable& t = rot.PairTable(r.itheta, ra, rb);
            ASSERT_EQ(aligned.PairBound(t, r.column_masks.data(), a + ra, b + rb),
                      plain.Bound(r, a + ra, b + rb, 1))
                << "residue " << ra << "," << rb;
            ASSERT_EQ(aligned_min.PairBound(t, dm.data(), a + ra, b + rb),
                      plain_min.LowerBound(r, dm.data(), a + ra, b + rb, 1));
          }
        }
      }
      if (tlevel == 0) {  // exact hits from the cell groups, at every residue.
        for (int k2 = 0; k2 < 4; ++k2) {
          const int ix = a + d(rng), iy = b + d(rng);
          const CellGroups& g = rot.Groups(r.itheta, ix & 3, iy & 3);
          ASSERT_EQ(aligned.HitsGrouped(g, ix, iy), plain.Hits(r, ix, iy)) << "scene " << scene;
          ASSERT_EQ(aligned_min.HitsGrouped(g, ix, iy), plain_min.Hits(r, ix, iy));
        }
      }
      if (tlevel == 0) {  // the free-space lower bound (AND filter) of single rotations too.
        const std::vector<std::uint64_t> masks = CellDisjointMasks(r, lattice.subdivisions);
        ASSERT_EQ(aligned_min.LowerBound(r, masks.data(), a, b, level),
                  plain_min.LowerBound(r, masks.data(), a, b, level))
            << "scene " << scene << " level " << level;
      }
    }
  }
}

// A rotation's swept cell groups over a translation block hold exactly the template voxels it
// places anywhere in the block: summed over the cluster, the cluster voxels some pose of the
// block covers (so at least the hits of every pose in it), at every level and residue; and the
// four-block pass equals four single ones.
TEST(ColumnOccupancyTest, SweptGroupsCountTheVoxelsTheBlockReaches) {
  std::mt19937 rng(23);
  for (unsigned scene = 0; scene < 3; ++scene) {
    PoseLattice lattice;
    lattice.subdivisions = scene == 2 ? 2 : 4;
    const int s = lattice.subdivisions;
    const VoxelTemplate tpl =
        *MakeTemplateFromPoints(testing::RandomRobotPoints(30 + scene), "t", lattice.resolution_m);
    const Pose2D truth{1.2, 0.1 * scene, DegToRad(-61.0 * scene)};
    const ClusterVoxels cluster = VoxeliseCluster(
        testing::VisibleCluster(testing::RandomRobotPoints(30 + scene), truth, 0.004f, scene),
        lattice.resolution_m);
    std::set<std::tuple<int, int, int>> occupied;
    for (const Eigen::Vector3i& c : cluster.cells) occupied.insert({c.x(), c.y(), c.z()});
    const TemplateRotations rot(tpl, lattice);
    const LatticePose c = NearestLatticePose(lattice, truth);
    const int reach = 12 * s;
    ColumnOccupancy::CellRange range;
    range.x_lo = FloorDiv(c.ix - reach, s) + FloorDiv(rot.column_q_min().x(), s);
    range.y_lo = FloorDiv(c.iy - reach, s) + FloorDiv(rot.column_q_min().y(), s);
    range.x_hi = FloorDiv(c.ix + reach + 64, s) + FloorDiv(rot.column_q_max().x(), s) + 1;
    range.y_hi = FloorDiv(c.iy + reach + 64, s) + FloorDiv(rot.column_q_max().y(), s) + 1;
    const ColumnOccupancy occ(cluster, lattice, rot.Get(0).z_base, rot.Get(0).z_words, 6,
                              ColumnOccupancy::Filter::kMax, &range);
    ASSERT_TRUE(occ.aligned());
    std::uniform_int_distribution<int> d(-reach / s, reach / s), th(0, 359),
        lv(1, TemplateRotations::kSweptLevels);
    int nonzero = 0;
    const std::vector<Eigen::Vector3f> centroids = tpl.VoxelSurfaceCentroids();
    for (int k = 0; k < 60; ++k) {
      const RotatedTemplate& r = rot.Get(th(rng));
      // The reference: the template's voxels rotated one by one.
      const RotatedTemplate points = RotatePoints(centroids, lattice, r.itheta);
      const int level = lv(rng), size = 1 << level, step = std::min(size, s);
      std::uniform_int_distribution<int> res(0, std::max(1, s / step) - 1);
      const int ra = step * res(rng), rb = step * res(rng);
      const int a = s * (FloorDiv(c.ix, s) + d(rng)) + ra;
      const int b = s * (FloorDiv(c.iy, s) + d(rng)) + rb;
      std::set<std::tuple<int, int, int>> reached;
      int best_hits = 0;
      for (int i = 0; i < size; ++i) {
        for (int j = 0; j < size; ++j) {
          for (const Eigen::Vector3i& q : points.sub_cells) {
            const Eigen::Vector3i cell = PlacedCell(q, a + i, b + j, s);
            if (occupied.count({cell.x(), cell.y(), cell.z()}) != 0) {
              reached.insert({cell.x(), cell.y(), cell.z()});
            }
          }
          best_hits = std::max(best_hits, occ.Hits(r, a + i, b + j));
        }
      }
      const CellGroups& g = rot.SweptGroups(r.itheta, level, ra, rb);
      const int swept = occ.HitsGrouped(g, a, b);
      ASSERT_EQ(swept, static_cast<int>(reached.size()))
          << "scene " << scene << " level " << level << " residue " << ra << "," << rb;
      EXPECT_GE(swept, best_hits);
      nonzero += swept > 0 ? 1 : 0;
      if (size % s == 0) {
        int four[4];
        occ.HitsGrouped4(g.table(), a, b, size / s, four);
        for (int q = 0; q < 4; ++q) {
          EXPECT_EQ(four[q], occ.HitsGrouped(g, a + (q / 2) * size, b + (q % 2) * size))
              << "quarter " << q;
        }
      }
    }
    EXPECT_GT(nonzero, 10) << "scene " << scene;
  }
}

// A theta block's swept cell groups hold, cell by cell, the union of its rotations' groups
// (their swept groups over translation blocks, their exact groups at single translations): so
// its bound is at least every pose's hits in the block; its common groups the cells and bits
// all its rotations share at a translation. Tables made ahead (MakeTables) equal those made on
// first use.
TEST(ColumnOccupancyTest, ThetaBlockSweptGroupsUniteTheirRotations) {
  PoseLattice lattice;
  lattice.angle_steps = 90;  // blocks of 16 at the end hold only the 10 headings left.
  const int s = lattice.subdivisions;
  const VoxelTemplate tpl =
      *MakeTemplateFromPoints(testing::RandomRobotPoints(77), "t", lattice.resolution_m);
  const TemplateRotations lazy(tpl, lattice);
  const TemplateRotations ahead(tpl, lattice);
  ahead.MakeTables(TemplateRotations::kThetaLevels - 1, 0, 50);
  ahead.MakeTables(TemplateRotations::kThetaLevels - 1, 50, lattice.angle_steps);
  using Cells = CellMasks;
  const auto cells_of = [](const CellGroups& g) {
    Cells out;
    g.ForEachCell([&](int cx, int cy, std::uint64_t mask) {
      EXPECT_TRUE(out.emplace(std::pair{cx, cy}, mask).second) << "a cell listed twice";
    });
    return out;
  };
  int checked = 0, common_cells = 0;
  for (int t = 1; t < TemplateRotations::kThetaLevels; ++t) {
    for (int first = 0; first < lattice.angle_steps; first += 1 << t) {
      if (first % 7 != 0 && first + (1 << t) < lattice.angle_steps) continue;  // a sample.
      for (int level = 0; level <= TemplateRotations::kSweptLevels; ++level) {
        const int step = level == 0 ? 1 : std::min(1 << level, s);
        for (int ra = 0; ra < s; ra += step) {
          for (int rb = 0; rb < s; rb += step) {
            Cells expected;
            for (int i = first; i < std::min(first + (1 << t), lattice.angle_steps); ++i) {
              const CellGroups& g =
                  level == 0 ? lazy.Groups(i, ra, rb) : lazy.SweptGroups(i, level, ra, rb);
              for (const auto& [cell, mask] : cells_of(g)) expected[cell] |= mask;
            }
            const CellGroups& block = lazy.SweptBlockGroups(t, first, level, ra, rb);
            ASSERT_EQ(cells_of(block), expected)
                << "theta level " << t << " block " << first << " level " << level << " residue "
                << ra << "," << rb;
            if (level == 0) {  // the common cells: in every rotation, the bits all set.
              Cells common;
              bool first_rotation = true;
              for (int i = first; i < std::min(first + (1 << t), lattice.angle_steps); ++i) {
                const Cells own = cells_of(lazy.Groups(i, ra, rb));
                common = first_rotation ? own : CommonCells(common, own);
                first_rotation = false;
              }
              EXPECT_EQ(cells_of(lazy.CommonBlockGroups(t, first, ra, rb)), common)
                  << "theta level " << t << " block " << first << " residue " << ra << "," << rb;
              EXPECT_EQ(ahead.CommonBlockGroups(t, first, ra, rb).words,
                        lazy.CommonBlockGroups(t, first, ra, rb).words);
              common_cells += static_cast<int>(common.size());
            }
            const CellGroups& made = ahead.SweptBlockGroups(t, first, level, ra, rb);
            EXPECT_EQ(made.words, block.words);
            EXPECT_EQ(made.runs, block.runs);
            ++checked;
          }
        }
      }
    }
  }
  EXPECT_GT(checked, 300);
  EXPECT_GT(common_cells, 100);
  EXPECT_GT(lazy.block_extent(4), lazy.block_extent(1));
  EXPECT_GT(lazy.block_extent(1), 0);
  EXPECT_EQ(lazy.block_extent(0), 0);
}

// A theta block's common pair cells are, cell by cell, the z bits every rotation of the block
// places there at all four translations of a block of 2 x 2 steps (from the voxels themselves),
// at three subdivisions; made ahead (MakeTables) or on first use, and through the directory
// (CommonPairTable), the same tables.
TEST(ColumnOccupancyTest, CommonPairCellsAreThoseEveryPoseOfTheBlockPlaces) {
  int checked = 0, common_cells = 0;
  for (const int s : {2, 4, 8}) {
    PoseLattice lattice;
    lattice.angle_steps = 90;  // the last block of 16 holds only the 10 headings left.
    lattice.subdivisions = s;
    const VoxelTemplate tpl =
        *MakeTemplateFromPoints(testing::RandomRobotPoints(78), "t", lattice.resolution_m);
    const TemplateRotations lazy(tpl, lattice);
    const TemplateRotations ahead(tpl, lattice);
    ahead.MakeTables(TemplateRotations::kThetaLevels - 1, 0, lattice.angle_steps);
    // The reference: the template's voxels rotated one by one, at every heading.
    std::vector<RotatedTemplate> reference;
    const std::vector<Eigen::Vector3f> centroids = tpl.VoxelSurfaceCentroids();
    for (int i = 0; i < lattice.angle_steps; ++i) {
      reference.push_back(RotatePoints(centroids, lattice, i));
    }
    const auto placed = [&](int itheta, int ix, int iy) {
      CellMasks out;
      const RotatedTemplate& r = reference[itheta];
      for (const Eigen::Vector3i& q : r.sub_cells) {
        const Eigen::Vector3i c = PlacedCell(q, ix, iy, s);
        out[{c.x(), c.y()}] |= std::uint64_t{1} << (c.z() - r.z_base);
      }
      return out;
    };
    for (int t = 0; t < TemplateRotations::kThetaLevels; ++t) {
      for (int first = 0; first < lattice.angle_steps; first += 1 << t) {
        if (first % 11 != 0 && first + (1 << t) < lattice.angle_steps) continue;  // a sample.
        for (int ra = 0; ra < s; ra += std::min(2, s)) {
          for (int rb = 0; rb < s; rb += std::min(2, s)) {
            CellMasks expected;
            bool first_pose = true;
            for (int i = first; i < std::min(first + (1 << t), lattice.angle_steps); ++i) {
              for (int da = 0; da < 2; ++da) {
                for (int db = 0; db < 2; ++db) {
                  const CellMasks own = placed(i, ra + da, rb + db);
                  expected = first_pose ? own : CommonCells(expected, own);
                  first_pose = false;
                }
              }
            }
            CellMasks got;
            const CellGroups& g = lazy.CommonPairGroups(t, first, ra, rb);
            g.ForEachCell([&](int cx, int cy, std::uint64_t mask) {
              EXPECT_TRUE(got.emplace(std::pair{cx, cy}, mask).second) << "a cell listed twice";
            });
            ASSERT_EQ(got, expected) << "s " << s << " theta level " << t << " block " << first
                                     << " residue " << ra << "," << rb;
            EXPECT_EQ(ahead.CommonPairGroups(t, first, ra, rb).words, g.words);
            const CellTable table = lazy.CommonPairTable(t, first, ra, rb);
            EXPECT_EQ(table.words, g.words.data());
            EXPECT_EQ(table.runs, g.runs);
            EXPECT_EQ(table.prefetch_words, CellTable::PrefetchWords(g.words.size()));
            common_cells += static_cast<int>(expected.size());
            ++checked;
          }
        }
      }
    }
  }
  EXPECT_GT(checked, 100);
  EXPECT_GT(common_cells, 200);
}

// The directory of SweptTable and CommonTable returns each table's own words, run count and
// size (those of SweptBlockGroups and CommonBlockGroups), on first use (the slow way, which
// enters it) and after, for every theta level, block, translation level and residue, at three
// subdivisions.
TEST(ColumnOccupancyTest, TableDirectoryGivesEveryTableItsOwn) {
  int checked = 0;
  for (const int s : {2, 4, 8}) {
    PoseLattice lattice;
    lattice.angle_steps = 40;  // the last block of 16 holds 8 headings.
    lattice.subdivisions = s;
    const VoxelTemplate tpl =
        *MakeTemplateFromPoints(testing::RandomRobotPoints(5), "t", lattice.resolution_m);
    const TemplateRotations rot(tpl, lattice);
    for (int pass = 0; pass < 2; ++pass) {
      for (int t = 0; t < TemplateRotations::kThetaLevels; ++t) {
        for (int first = 0; first < lattice.angle_steps; first += 1 << t) {
          for (int level = 0; level <= TemplateRotations::kSweptLevels; ++level) {
            const int step = level == 0 ? 1 : std::min(1 << level, s);
            for (int ra = 0; ra < s; ra += step) {
              for (int rb = 0; rb < s; rb += step) {
                const CellTable got = rot.SweptTable(t, first, level, ra, rb);
                const CellGroups& want = rot.SweptBlockGroups(t, first, level, ra, rb);
                ASSERT_EQ(got.words, want.words.data())
                    << "s " << s << " theta level " << t << " block " << first << " level " << level
                    << " residue " << ra << "," << rb << " pass " << pass;
                ASSERT_EQ(got.runs, want.runs);
                ASSERT_EQ(got.prefetch_words, CellTable::PrefetchWords(want.words.size()));
                ASSERT_EQ(got.mask_bytes, want.mask_bytes);
                ++checked;
                if (level != 0) continue;
                const CellTable common = rot.CommonTable(t, first, ra, rb);
                const CellGroups& common_want = rot.CommonBlockGroups(t, first, ra, rb);
                ASSERT_EQ(common.words, common_want.words.data())
                    << "s " << s << " theta level " << t << " block " << first << " residue " << ra
                    << "," << rb << " pass " << pass;
                ASSERT_EQ(common.runs, common_want.runs);
                ASSERT_EQ(common.prefetch_words,
                          CellTable::PrefetchWords(common_want.words.size()));
                ASSERT_EQ(common.mask_bytes, rot.mask_bytes());
              }
            }
          }
        }
      }
    }
  }
  EXPECT_GT(checked, 3000);
}

// The cell tables keep each mask in the bytes the template's highest z cell needs: a template
// under 64 cells tall takes fewer than 8, and every table's cells read back (ForEachCell) within
// that width and with the masks of the columns landing in them (Groups at residue (0, 0)).
TEST(ColumnOccupancyTest, CellTablesKeepMasksInTheTemplatesBytes) {
  PoseLattice lattice;
  lattice.angle_steps = 16;
  const VoxelTemplate tpl =
      *MakeTemplateFromPoints(testing::RandomRobotPoints(9), "t", lattice.resolution_m);
  const TemplateRotations rot(tpl, lattice);
  std::uint64_t any = 0;
  for (const std::uint64_t m : rot.Get(0).column_masks) any |= m;
  ASSERT_NE(any, 0u);
  const int height = 64 - __builtin_clzll(any);  // z cells from the lowest.
  EXPECT_EQ(rot.mask_bytes(), (height + 7) / 8);
  ASSERT_LT(rot.mask_bytes(), 8);  // so below, a shift by 8 * width drops the width's bits.
  const int s = lattice.subdivisions;
  for (int itheta = 0; itheta < lattice.angle_steps; ++itheta) {
    const RotatedTemplate& r = rot.Get(itheta);
    std::map<std::pair<int, int>, std::uint64_t> want;
    for (size_t c = 0; c < r.column_q.size(); ++c) {
      want[{FloorDiv(r.column_q[c].x(), s), FloorDiv(r.column_q[c].y(), s)}] |= r.column_masks[c];
    }
    const CellGroups& g = rot.Groups(itheta, 0, 0);
    EXPECT_EQ(g.mask_bytes, rot.mask_bytes());
    EXPECT_EQ(g.cells(), static_cast<int>(want.size()));
    std::map<std::pair<int, int>, std::uint64_t> got;
    g.ForEachCell([&](int cx, int cy, std::uint64_t mask) {
      EXPECT_EQ(mask >> (8 * g.mask_bytes), 0u);
      got[{cx, cy}] = mask;
    });
    ASSERT_EQ(got, want) << "rotation " << itheta;
  }
}

// A random robot (RandomRobotPoints(points)) as a template and as the cluster a sensor sees of it
// at `truth` (5 mm noise drawn from `seed`), both on the lattice's voxels.
std::pair<VoxelTemplate, ClusterVoxels> PlantRobot(unsigned points, const Pose2D& truth,
                                                   unsigned seed, const PoseLattice& lattice) {
  return {*MakeTemplateFromPoints(testing::RandomRobotPoints(points), "t", lattice.resolution_m),
          VoxeliseCluster(
              testing::VisibleCluster(testing::RandomRobotPoints(points), truth, 0.005f, seed),
              lattice.resolution_m)};
}

// Under the sanitizers every third scene (still every max_level and both subdivisions): the
// brute force over the lattice is what takes the time there.
constexpr unsigned kSceneStep = hpose::testing::kSanitizerBuild ? 3 : 1;

TEST(ExactSearchTest, EqualsExhaustiveSearchOnRandomScenes) {
  for (unsigned scene = 0; scene < 16; scene += kSceneStep) {
    PoseLattice lattice;
    lattice.angle_steps = 24;  // 15 deg: small enough to brute-force the whole lattice.
    lattice.subdivisions = scene % 2 == 0 ? 4 : 2;
    const Pose2D truth{1.0 + 0.13 * scene, 0.4 - 0.07 * scene, DegToRad(-170.0 + 23.0 * scene)};
    const auto [tpl, cluster] = PlantRobot(100 + scene, truth, scene, lattice);
    const TemplateRotations rot(tpl, lattice);
    const FastScorer scorer(cluster, lattice);
    ExactSearchOptions opts;
    opts.margin_m = 0.06;  // keeps the brute force small.
    opts.max_level = 1 + scene % 5;
    const ExactSearch search(opts);
    SearchProblem problem{&cluster, &scorer, &rot, {truth.x, truth.y}};
    const SearchResult r = search.Search(problem);
    opts.swept_bounds = false;  // the column bounds alone find the same optimum.
    const SearchResult by_columns = ExactSearch(opts).Search(problem);
    opts.swept_bounds = true;
    opts.top_theta_level = 0;  // so do single headings from the top.
    const SearchResult single = ExactSearch(opts).Search(problem);
    const ExactSearch::Region region = search.TranslationRegion(cluster, rot);
    std::vector<int> all(lattice.angle_steps);
    for (int t = 0; t < lattice.angle_steps; ++t) all[t] = t;
    const Exhaustive brute = Brute(scorer, rot, region, all);
    ASSERT_EQ(r.hits, brute.best_hits) << "scene " << scene;
    EXPECT_EQ(by_columns.hits, brute.best_hits) << "scene " << scene;
    EXPECT_EQ(single.hits, brute.best_hits) << "scene " << scene;
    EXPECT_EQ(scorer.Hits(rot.Get(r.best.itheta), r.best.ix, r.best.iy), r.hits);
    EXPECT_GE(r.best.ix, region.ix_min);
    EXPECT_LE(r.best.iy, region.iy_max);
    // Runner-up: exhaustive over thetas more than 30 degrees from the best.
    std::vector<int> far;
    for (int t = 0; t < lattice.angle_steps; ++t) {
      if (std::abs(AngleDiff(t * lattice.angle_step_rad(),
                             r.best.itheta * lattice.angle_step_rad())) > DegToRad(30)) {
        far.push_back(t);
      }
    }
    const Exhaustive brute_far = Brute(scorer, rot, region, far);
    ASSERT_TRUE(r.has_runner_up);
    EXPECT_NEAR(r.runner_up_score, 100.0 * brute_far.best_hits / scorer.cluster_voxels(), 1e-9);
    EXPECT_NEAR(single.runner_up_score, r.runner_up_score, 1e-9) << "scene " << scene;
    EXPECT_GT(std::abs(AngleDiff(r.runner_up_pose.theta, r.pose.theta)), DegToRad(30));
    EXPECT_LT(r.poses_evaluated + r.bounds_evaluated, brute.poses);
  }
}

// With a runner_up_window the runner-up is the exhaustive one whenever its value is within the
// window of the optimum's, and otherwise there is none, with an upper bound of every other
// heading's score that lies below the window; the optimum is the same either way. So too for a
// search stopped below a min_value and lowered.
TEST(ExactSearchTest, RunnerUpWithinAWindowEqualsExhaustiveSearch) {
  int found = 0, not_found = 0;
  for (unsigned scene = 0; scene < 8; scene += kSceneStep) {
    PoseLattice lattice;
    lattice.angle_steps = 24;
    const Pose2D truth{1.2, -0.2 + 0.05 * scene, DegToRad(-160.0 + 41.0 * scene)};
    const auto [tpl, cluster] = PlantRobot(700 + scene, truth, scene, lattice);
    const TemplateRotations rot(tpl, lattice);
    const FastScorer scorer(cluster, lattice);
    ExactSearchOptions opts;
    opts.margin_m = 0.06;
    const ExactSearch search(opts);
    const SearchProblem problem{&cluster, &scorer, &rot, {truth.x, truth.y}};
    const SearchResult whole = search.Search(problem);
    std::vector<int> far;
    for (int t = 0; t < lattice.angle_steps; ++t) {
      if (std::abs(AngleDiff(t * lattice.angle_step_rad(),
                             whole.best.itheta * lattice.angle_step_rad())) > DegToRad(30)) {
        far.push_back(t);
      }
    }
    const int runner_up = Brute(scorer, rot, search.TranslationRegion(cluster, rot), far).best_hits;
    const int gap = whole.value - runner_up;
    ASSERT_GE(gap, 0) << "scene " << scene;
    const double n = scorer.cluster_voxels();
    for (const int window : {0, gap - 1, gap, gap + 1, 3 * gap + 5}) {
      if (window < 0) continue;
      SCOPED_TRACE(::testing::Message() << "scene " << scene << ", window " << window);
      SearchProblem windowed = problem;
      windowed.runner_up_window = window;
      SearchResult direct = search.Search(windowed);
      // The same through a stop above the optimum, lowered to no min_value.
      windowed.min_value = whole.value + 1;
      SearchResult lowered;
      std::unique_ptr<StoppedSearch> stopped;
      ASSERT_EQ(search.SearchBest(windowed, &lowered, &stopped), nullptr);
      ASSERT_NE(stopped, nullptr);
      std::unique_ptr<RunnerUpSearch> rest =
          stopped->Lower(std::numeric_limits<int>::min(), &lowered);
      ASSERT_NE(rest, nullptr);
      rest->Find(&lowered);
      for (const SearchResult* r : {&direct, &lowered}) {
        EXPECT_EQ(r->value, whole.value);
        EXPECT_EQ(r->best.itheta, whole.best.itheta);
        EXPECT_EQ(r->best.ix, whole.best.ix);
        EXPECT_EQ(r->best.iy, whole.best.iy);
        if (window >= gap) {
          ASSERT_TRUE(r->has_runner_up);
          EXPECT_NEAR(r->runner_up_score, 100.0 * runner_up / n, 1e-9);
          EXPECT_EQ(r->runner_up_score, whole.runner_up_score);
          EXPECT_EQ(r->runner_up_pose.theta, whole.runner_up_pose.theta);
        } else {
          EXPECT_FALSE(r->has_runner_up);
          EXPECT_GE(r->runner_up_score, 100.0 * runner_up / n - 1e-9);
          EXPECT_LT(r->runner_up_score, 100.0 * (whole.value - window) / n);
        }
      }
      EXPECT_LE(direct.bounds_evaluated, whole.bounds_evaluated);
      (window >= gap ? found : not_found) += 1;
    }
  }
  EXPECT_GT(found, 0);
  EXPECT_GT(not_found, 0);
}

// The runner-up's search left for later (SearchBest, then RunnerUpSearch::Find) finds what one
// Search finds, with the same counts, however many such searches wait at once and whatever other
// searches run meanwhile (each keeps its own queue).
TEST(ExactSearchTest, RunnerUpFoundLaterEqualsOneSearch) {
  std::mt19937 rng(5);
  PoseLattice lattice;
  lattice.angle_steps = 24;
  struct Scene {
    std::unique_ptr<TemplateRotations> rot;
    ClusterVoxels cluster, free;
    std::unique_ptr<FastScorer> scorer;
    SearchProblem problem;
  };
  std::vector<Scene> scenes(4);
  for (unsigned k = 0; k < scenes.size(); ++k) {
    Scene& sc = scenes[k];
    const VoxelTemplate tpl =
        *MakeTemplateFromPoints(testing::RandomRobotPoints(300 + k), "t", lattice.resolution_m);
    const Pose2D truth{1.2, -0.1, DegToRad(-120.0 + 70.0 * k)};
    sc.cluster = VoxeliseCluster(
        testing::VisibleCluster(testing::RandomRobotPoints(300 + k), truth, 0.004f, k),
        lattice.resolution_m);
    ASSERT_FALSE(sc.cluster.cells.empty());
    sc.free = RandomFreeCells(sc.cluster, 2000, 40, &rng);
    sc.rot = std::make_unique<TemplateRotations>(tpl, lattice);
    sc.scorer = std::make_unique<FastScorer>(sc.cluster, lattice);
    sc.problem = SearchProblem{&sc.cluster, sc.scorer.get(), sc.rot.get(), {truth.x, truth.y}};
    sc.problem.free_space = &sc.free;
  }
  ExactSearchOptions opts;
  opts.margin_m = 0.08;
  const ExactSearch search(opts);
  std::vector<SearchResult> whole;
  for (const Scene& sc : scenes) whole.push_back(search.Search(sc.problem));

  std::vector<SearchResult> later(scenes.size());
  std::vector<std::unique_ptr<RunnerUpSearch>> pending;
  for (size_t k = 0; k < scenes.size(); ++k) {
    pending.push_back(search.SearchBest(scenes[k].problem, &later[k]));
    ASSERT_NE(pending.back(), nullptr) << "scene " << k;
    EXPECT_FALSE(later[k].has_runner_up) << "scene " << k;
    EXPECT_EQ(later[k].value, whole[k].value) << "scene " << k;
    EXPECT_EQ(later[k].best.itheta, whole[k].best.itheta) << "scene " << k;
    EXPECT_EQ(later[k].best.ix, whole[k].best.ix) << "scene " << k;
    EXPECT_EQ(later[k].best.iy, whole[k].best.iy) << "scene " << k;
    EXPECT_LT(later[k].bounds_evaluated, whole[k].bounds_evaluated) << "scene " << k;
  }
  // Other searches while those wait, then the runner-ups in the reverse order.
  for (size_t k = 0; k < scenes.size(); ++k) {
    EXPECT_EQ(search.Search(scenes[k].problem).runner_up_score, whole[k].runner_up_score);
  }
  for (size_t k = scenes.size(); k-- > 0;) {
    pending[k]->Find(&later[k]);
    pending[k].reset();
    const SearchResult& a = later[k];
    const SearchResult& b = whole[k];
    ASSERT_TRUE(b.has_runner_up) << "scene " << k;
    EXPECT_TRUE(a.has_runner_up) << "scene " << k;
    EXPECT_EQ(a.runner_up_score, b.runner_up_score) << "scene " << k;
    EXPECT_EQ(a.runner_up_pose.x, b.runner_up_pose.x) << "scene " << k;
    EXPECT_EQ(a.runner_up_pose.y, b.runner_up_pose.y) << "scene " << k;
    EXPECT_EQ(a.runner_up_pose.theta, b.runner_up_pose.theta) << "scene " << k;
    EXPECT_EQ(a.poses_evaluated, b.poses_evaluated) << "scene " << k;
    EXPECT_EQ(a.bounds_evaluated, b.bounds_evaluated) << "scene " << k;
  }
}

// A search stopped below a min_value and lowered (SearchBest's StoppedSearch) gives what one
// search down to the lower value gives: the same optimum, pose and runner-up, or the same stop
// when the lower value is still above the optimum. Stopped at once (no pose evaluated yet, the
// best evaluated found by descending) or after some work, lowered once or after a second stop.
TEST(ExactSearchTest, LoweredStoppedSearchEqualsOneStraightDown) {
  std::mt19937 rng(17);
  PoseLattice lattice;
  lattice.angle_steps = 24;
  ExactSearchOptions opts;
  opts.margin_m = 0.08;
  const ExactSearch search(opts);
  int lowered_to_optimum = 0;
  for (unsigned k = 0; k < 4; ++k) {
    const VoxelTemplate tpl =
        *MakeTemplateFromPoints(testing::RandomRobotPoints(500 + k), "t", lattice.resolution_m);
    const Pose2D truth{1.1, 0.1, DegToRad(-100.0 + 60.0 * k)};
    const ClusterVoxels cluster = VoxeliseCluster(
        testing::VisibleCluster(testing::RandomRobotPoints(500 + k), truth, 0.004f, k),
        lattice.resolution_m);
    ASSERT_FALSE(cluster.cells.empty()) << "scene " << k;
    const ClusterVoxels free = RandomFreeCells(cluster, 2000, 40, &rng);
    const TemplateRotations rot(tpl, lattice);
    const FastScorer scorer(cluster, lattice);
    SearchProblem problem{&cluster, &scorer, &rot, {truth.x, truth.y}};
    problem.free_space = &free;
    problem.hit_weight = 2;
    const int optimum = search.Search(problem).value;
    // min_values: far above (stopped at once), just above the optimum, then lowered.
    const std::vector<std::pair<int, int>> steps = {{10 * optimum + 100, optimum - 5},
                                                    {optimum + 1, optimum - 5},
                                                    {optimum + 1, optimum},
                                                    {optimum + 3, optimum + 1}};
    for (const auto& [high, low] : steps) {
      SCOPED_TRACE(::testing::Message() << "scene " << k << ", " << high << " -> " << low);
      SearchProblem first = problem;
      first.min_value = high;
      SearchResult r;
      std::unique_ptr<StoppedSearch> stopped;
      EXPECT_EQ(search.SearchBest(first, &r, &stopped), nullptr);
      ASSERT_TRUE(r.below_min_value);
      ASSERT_NE(stopped, nullptr);
      SearchResult lowered;
      std::unique_ptr<RunnerUpSearch> runner_up = stopped->Lower(low, &lowered);
      SearchProblem straight = problem;
      straight.min_value = low;
      const SearchResult direct = search.Search(straight);
      EXPECT_EQ(lowered.below_min_value, direct.below_min_value);
      if (direct.below_min_value) {
        EXPECT_EQ(runner_up, nullptr);
        EXPECT_LT(lowered.value_upper_bound, low);
        EXPECT_LE(lowered.value, optimum);  // a real pose's value, not the optimum's bound.
        EXPECT_GE(lowered.value_upper_bound, optimum);
        continue;
      }
      ++lowered_to_optimum;
      ASSERT_NE(runner_up, nullptr);
      runner_up->Find(&lowered);
      EXPECT_EQ(lowered.value, optimum);
      EXPECT_EQ(lowered.value, direct.value);
      EXPECT_EQ(lowered.best.itheta, direct.best.itheta);
      EXPECT_EQ(lowered.best.ix, direct.best.ix);
      EXPECT_EQ(lowered.best.iy, direct.best.iy);
      EXPECT_EQ(lowered.has_runner_up, direct.has_runner_up);
      EXPECT_EQ(lowered.runner_up_score, direct.runner_up_score);
      EXPECT_EQ(lowered.runner_up_pose.theta, direct.runner_up_pose.theta);
      EXPECT_GE(lowered.bounds_evaluated, r.bounds_evaluated);  // both parts counted.
    }
  }
  EXPECT_EQ(lowered_to_optimum, 12);
}

// With free-space evidence the value is hits - w * free hits; still equal to brute force.
TEST(ExactSearchTest, WithFreeSpaceEqualsExhaustiveSearch) {
  std::mt19937 rng(11);
  for (unsigned scene = 0; scene < 10; scene += kSceneStep) {
    PoseLattice lattice;
    lattice.angle_steps = 24;
    const VoxelTemplate tpl =
        *MakeTemplateFromPoints(testing::RandomRobotPoints(400 + scene), "t", lattice.resolution_m);
    const Pose2D truth{1.0, 0.1, DegToRad(-150.0 + 33.0 * scene)};
    const ClusterVoxels cluster = VoxeliseCluster(
        testing::VisibleCluster(testing::RandomRobotPoints(400 + scene), truth, 0.004f, scene),
        lattice.resolution_m);
    ASSERT_FALSE(cluster.cells.empty()) << "scene " << scene;
    const ClusterVoxels free = RandomFreeCells(cluster, 3000, 40, &rng);
    const TemplateRotations rot(tpl, lattice);
    const FastScorer scorer(cluster, lattice);
    const FastScorer free_scorer(free, lattice);
    ExactSearchOptions opts;
    opts.margin_m = 0.05;
    opts.max_level = 2 + scene % 4;
    const ExactSearch search(opts);
    SearchProblem problem{&cluster, &scorer, &rot, {truth.x, truth.y}};
    problem.free_space = &free;
    problem.free_space_weight = 1 + scene % 2;
    problem.hit_weight = 1 + scene % 3;
    const SearchResult r = search.Search(problem);
    const WeightedOptimum brute =
        BruteWeighted(scorer, free_scorer, rot, search.TranslationRegion(cluster, rot),
                      problem.hit_weight, problem.free_space_weight);
    const int best = brute.value;
    const LatticePose& first_best = brute.first;
    const auto same_pose = [&](const SearchResult& x) {
      return x.best.ix == first_best.ix && x.best.iy == first_best.iy &&
             x.best.itheta == first_best.itheta;
    };
    ASSERT_EQ(r.value, best) << "scene " << scene;
    EXPECT_TRUE(same_pose(r)) << "scene " << scene;
    opts.swept_bounds = false;
    EXPECT_EQ(ExactSearch(opts).Search(problem).value, best) << "scene " << scene;
    // The free-space part at no level, at every level, below one cell; blocks of 16 headings at
    // the top, split first always, never, or while the rotation's sweep is comparable to the
    // block: the same optimum.
    opts.swept_bounds = true;
    opts.top_theta_level = 4;
    opts.theta_split_ratio = 0.0;
    for (const auto& [free_levels, lead] : {std::pair{0, 0}, {31, 4}, {1, -10}, {2, 31}}) {
      opts.free_bound_max_level = free_levels;
      opts.theta_split_lead = lead;
      const SearchResult other = ExactSearch(opts).Search(problem);
      EXPECT_EQ(other.value, best) << "scene " << scene << ", free part up to level " << free_levels
                                   << ", theta lead " << lead;
      EXPECT_TRUE(same_pose(other)) << "scene " << scene << ", theta lead " << lead;
    }
    // Theta blocks split as soon as their arc passes a lattice step, at the default ratio, or
    // only at single translations; from blocks of 2, 16 headings or single ones: the same
    // optimum.
    opts.free_bound_max_level = 2;
    for (const int top : {0, 1, 4}) {
      for (const double ratio : {0.25, 4.0, 1e9}) {
        opts.top_theta_level = top;
        opts.theta_split_ratio = ratio;
        for (const auto& [common, pairs] : {std::pair{false, false}, {true, false}, {true, true}}) {
          opts.theta_block_free_part = common;
          opts.theta_block_pair_free_part = pairs;
          const SearchResult other = ExactSearch(opts).Search(problem);
          EXPECT_EQ(other.value, best)
              << "scene " << scene << ", top theta level " << top << ", ratio " << ratio
              << ", common cells " << common << ", over pairs of steps " << pairs;
          EXPECT_TRUE(same_pose(other)) << "scene " << scene << ", top theta level " << top;
        }
      }
    }
    EXPECT_EQ(r.value, problem.hit_weight * r.hits - problem.free_space_weight * r.free_hits);
    EXPECT_NEAR(r.score, 100.0 * r.value / (problem.hit_weight * scorer.cluster_voxels()), 1e-9);
  }
}

// A cluster the template covers whole from many poses (a low box, as the feet of something the
// image border cuts off) with the free space the sensor saw around it: the hits alone leave
// thousands of blocks above the optimum, and the theta blocks' free part over pairs of steps
// refutes many of them. The same optimum as exhaustive evaluation, with fewer bounds.
TEST(ExactSearchTest, PairFreePartRefutesBlocksAroundASmallClusterExactly) {
  PoseLattice lattice;
  lattice.angle_steps = 48;
  const VoxelTemplate tpl =
      *MakeTemplateFromPoints(testing::RandomRobotPoints(5), "t", lattice.resolution_m);
  const TemplateRotations rot(tpl, lattice);
  ClusterVoxels cluster, free;
  const int x0 = 62, y0 = 6;  // about (1.0, 0.1) m.
  for (int x = 0; x < 6; ++x) {
    for (int y = 0; y < 8; ++y) {
      for (int z = 0; z < 3; ++z) {
        if (x == 0 || y == 0 || y == 7 || z == 2) cluster.cells.emplace_back(x0 + x, y0 + y, z);
      }
    }
  }
  for (int x = -14; x < 20; ++x) {  // the air around the box, up to where the view ends.
    for (int y = -14; y < 22; ++y) {
      if (x >= 0 && x < 6 && y >= 0 && y < 8) continue;
      for (int z = 0; z < 6; ++z) free.cells.emplace_back(x0 + x, y0 + y, z);
    }
  }
  const FastScorer scorer(cluster, lattice);
  const FastScorer free_scorer(free, lattice);
  ExactSearchOptions opts;
  opts.margin_m = 0.06;
  const ExactSearch search(opts);
  SearchProblem problem{&cluster, &scorer, &rot, {(x0 + 3) * 0.016, (y0 + 4) * 0.016}};
  problem.free_space = &free;
  const SearchResult with = search.Search(problem);
  opts.theta_block_pair_free_part = false;
  const SearchResult without = ExactSearch(opts).Search(problem);
  const WeightedOptimum brute =
      BruteWeighted(scorer, free_scorer, rot, search.TranslationRegion(cluster, rot),
                    problem.hit_weight, problem.free_space_weight);
  for (const SearchResult* r : {&with, &without}) {
    EXPECT_EQ(r->value, brute.value);
    EXPECT_EQ(r->best.ix, brute.first.ix);
    EXPECT_EQ(r->best.iy, brute.first.iy);
    EXPECT_EQ(r->best.itheta, brute.first.itheta);
  }
  EXPECT_LT(with.bounds_evaluated, without.bounds_evaluated);
}

// A template taller than 64 z cells (two-word columns) is searched as the sum of its slabs of
// 64 cells: the slabs split its voxels without changing any pose's counts, and the search
// over them equals exhaustive evaluation of the whole template, as does the two-word path.
TEST(ExactSearchTest, TallTemplateSearchedBySlabsEqualsExhaustiveSearch) {
  std::mt19937 rng(29);
  for (unsigned scene = 0; scene < 6; scene += kSceneStep) {
    PoseLattice lattice;
    lattice.angle_steps = 24;
    // Stretched upwards: 3 times (even scenes: 1.1-2.3 m, two or three slabs), or to 1.1 m
    // (odd ones: a second slab of a few cells).
    std::vector<Eigen::Vector3f> points = testing::RandomRobotPoints(700 + scene);
    float height = 0.0f;
    for (const Eigen::Vector3f& p : points) height = std::max(height, p.z());
    const float stretch = scene % 2 == 0 ? 3.0f : 1.1f / height;
    for (Eigen::Vector3f& p : points) p.z() *= stretch;
    const VoxelTemplate tpl = *MakeTemplateFromPoints(points, "tall", lattice.resolution_m);
    const TemplateRotations rot(tpl, lattice);
    ASSERT_GT(rot.z_words(), 1) << "scene " << scene;
    ASSERT_FALSE(rot.has_cell_groups());
    ASSERT_EQ(rot.slabs().size(), static_cast<size_t>(rot.z_words())) << "scene " << scene;
    // A slab holds the column view only: its voxels are its columns' bits.
    size_t slab_voxels = 0;
    for (const std::unique_ptr<TemplateRotations>& slab : rot.slabs()) {
      EXPECT_EQ(slab->z_words(), 1);
      EXPECT_TRUE(slab->has_cell_groups());
      EXPECT_TRUE(slab->Get(0).sub_cells.empty());
      for (const std::uint64_t m : slab->Get(0).column_masks)
        slab_voxels += __builtin_popcountll(m);
    }
    EXPECT_EQ(slab_voxels, rot.voxels());

    const Pose2D truth{1.2, -0.1, DegToRad(-160.0 + 61.0 * scene)};
    const ClusterVoxels cluster = VoxeliseCluster(
        testing::VisibleCluster(points, truth, 0.004f, scene), lattice.resolution_m);
    ASSERT_FALSE(cluster.cells.empty());
    int top = 0;
    for (const Eigen::Vector3i& c : cluster.cells) top = std::max(top, c.z());
    const ClusterVoxels free = RandomFreeCells(cluster, 6000, top + 2, &rng);  // up to its top.
    const FastScorer scorer(cluster, lattice);
    const FastScorer free_scorer(free, lattice);

    // Every slab's counts add up to the whole template's, pose by pose: a slab's from its
    // column view (the distinct cells its columns' bits land in).
    std::set<std::tuple<int, int, int>> in_cluster, in_free;
    for (const Eigen::Vector3i& c : cluster.cells) in_cluster.insert({c.x(), c.y(), c.z()});
    for (const Eigen::Vector3i& c : free.cells) in_free.insert({c.x(), c.y(), c.z()});
    const auto column_hits = [&](const RotatedTemplate& r, int ix, int iy,
                                 const std::set<std::tuple<int, int, int>>& cells) {
      std::set<std::tuple<int, int, int>> placed;
      for (size_t c = 0; c < r.column_q.size(); ++c) {
        const int x = FloorDiv(r.column_q[c].x() + ix, lattice.subdivisions);
        const int y = FloorDiv(r.column_q[c].y() + iy, lattice.subdivisions);
        for (int bit = 0; bit < 64; ++bit) {
          if ((r.column_masks[c] >> bit & 1) == 0) continue;
          if (cells.count({x, y, r.z_base + bit}) != 0) placed.insert({x, y, r.z_base + bit});
        }
      }
      return static_cast<int>(placed.size());
    };
    std::uniform_int_distribution<int> it(0, lattice.angle_steps - 1), off(-40, 40);
    const int ix0 = static_cast<int>(std::lround(truth.x / lattice.step_m()));
    const int iy0 = static_cast<int>(std::lround(truth.y / lattice.step_m()));
    for (int k = 0; k < 50; ++k) {
      const int t = it(rng), ix = ix0 + off(rng), iy = iy0 + off(rng);
      int hits = 0, free_hits = 0;
      for (const std::unique_ptr<TemplateRotations>& slab : rot.slabs()) {
        hits += column_hits(slab->Get(t), ix, iy, in_cluster);
        free_hits += column_hits(slab->Get(t), ix, iy, in_free);
      }
      EXPECT_EQ(hits, scorer.Hits(rot.Get(t), ix, iy)) << "scene " << scene;
      EXPECT_EQ(free_hits, free_scorer.Hits(rot.Get(t), ix, iy)) << "scene " << scene;
    }

    ExactSearchOptions opts;
    opts.margin_m = 0.05;
    opts.max_level = 2 + scene % 4;
    const ExactSearch search(opts);
    SearchProblem problem{&cluster, &scorer, &rot, {truth.x, truth.y}};
    problem.free_space = &free;
    problem.free_space_weight = 1 + scene % 2;
    problem.hit_weight = 2;
    const SearchResult r = search.Search(problem);
    opts.slabs = false;
    const SearchResult two_words = ExactSearch(opts).Search(problem);
    const WeightedOptimum brute =
        BruteWeighted(scorer, free_scorer, rot, search.TranslationRegion(cluster, rot),
                      problem.hit_weight, problem.free_space_weight);
    const int best = brute.value;
    const LatticePose& first_best = brute.first;
    ASSERT_EQ(r.value, best) << "scene " << scene;
    EXPECT_EQ(r.best.ix, first_best.ix) << "scene " << scene;
    EXPECT_EQ(r.best.iy, first_best.iy) << "scene " << scene;
    EXPECT_EQ(r.best.itheta, first_best.itheta) << "scene " << scene;
    EXPECT_EQ(r.hits, scorer.Hits(rot.Get(r.best.itheta), r.best.ix, r.best.iy));
    EXPECT_EQ(r.free_hits, free_scorer.Hits(rot.Get(r.best.itheta), r.best.ix, r.best.iy));
    EXPECT_EQ(r.value, problem.hit_weight * r.hits - problem.free_space_weight * r.free_hits);
    EXPECT_EQ(two_words.value, best) << "scene " << scene;
    EXPECT_EQ(two_words.best.itheta, r.best.itheta) << "scene " << scene;
    EXPECT_EQ(two_words.best.ix, r.best.ix) << "scene " << scene;
    EXPECT_EQ(two_words.best.iy, r.best.iy) << "scene " << scene;
    EXPECT_EQ(two_words.has_runner_up, r.has_runner_up) << "scene " << scene;
    EXPECT_NEAR(two_words.runner_up_score, r.runner_up_score, 1e-9) << "scene " << scene;
  }
}

TEST(ExactSearchTest, FindsThePlantedPoseOnTheFullLattice) {
  for (unsigned scene = 0; scene < 4; ++scene) {
    const PoseLattice lattice;  // 1 deg x 4 mm.
    const std::vector<Eigen::Vector3f> robot = testing::RandomRobotPoints(200 + scene);
    const VoxelTemplate tpl = *MakeTemplateFromPoints(robot, "t", lattice.resolution_m);
    const Pose2D truth{1.2, -0.2 + 0.1 * scene, DegToRad(-135.0 + 80.0 * scene)};
    const ClusterVoxels cluster =
        VoxeliseCluster(testing::VisibleCluster(robot, truth, 0.002f, scene), 0.016);
    const TemplateRotations rot(tpl, lattice);
    const FastScorer scorer(cluster, lattice);
    const SearchResult r = ExactSearch().Search({&cluster, &scorer, &rot, {truth.x, truth.y}});
    const LatticePose t = NearestLatticePose(lattice, truth);
    // Nothing on the lattice scores better than the optimum, in particular not the truth.
    EXPECT_GE(r.hits, scorer.Hits(rot.Get(t.itheta), t.ix, t.iy));
    EXPECT_LT(std::hypot(r.pose.x - truth.x, r.pose.y - truth.y), 0.03) << scene;
    EXPECT_LT(std::abs(AngleDiff(r.pose.theta, truth.theta)), DegToRad(8)) << scene;
  }
}

// A cluster of three voxels: a great many poses cover all three. Of those the search returns
// the lowest (itheta, ix, iy), whatever the options that shape its bounds (which blocks it
// splits, in which order), and so does the runner-up among its headings.
TEST(ExactSearchTest, TiesGoToTheLowestHeadingAndTranslation) {
  PoseLattice lattice;
  lattice.angle_steps = 24;
  const VoxelTemplate tpl =
      *MakeTemplateFromPoints(testing::RandomRobotPoints(5), "t", lattice.resolution_m);
  ClusterVoxels cluster;
  cluster.resolution_m = lattice.resolution_m;
  cluster.cells = {{60, 3, 10}, {60, 3, 11}, {61, 3, 20}};
  const TemplateRotations rot(tpl, lattice);
  const FastScorer scorer(cluster, lattice);
  ExactSearchOptions opts;
  opts.margin_m = 0.08;
  const ExactSearch::Region region = ExactSearch(opts).TranslationRegion(cluster, rot);
  int best = -1, ties = 0;
  LatticePose first_best;
  for (int t = 0; t < lattice.angle_steps; ++t) {
    for (int ix = region.ix_min; ix <= region.ix_max; ++ix) {
      for (int iy = region.iy_min; iy <= region.iy_max; ++iy) {
        const int v = scorer.Hits(rot.Get(t), ix, iy);
        if (v > best) {
          best = v;
          first_best = LatticePose{ix, iy, t};
          ties = 0;
        }
        ties += v == best ? 1 : 0;
      }
    }
  }
  ASSERT_GT(ties, 10) << "the scene should have many optima";
  SearchProblem problem{&cluster, &scorer, &rot, {0.97, 0.05}};
  for (const int top : {0, 2, 4}) {
    for (const double ratio : {0.0, 0.25, 4.0, 1e9}) {
      for (const bool swept : {false, true}) {
        opts.top_theta_level = top;
        opts.theta_split_ratio = ratio;
        opts.swept_bounds = swept;
        const SearchResult r = ExactSearch(opts).Search(problem);
        ASSERT_EQ(r.hits, best);
        EXPECT_EQ(r.best.itheta, first_best.itheta)
            << "top " << top << " ratio " << ratio << " swept " << swept;
        EXPECT_EQ(r.best.ix, first_best.ix)
            << "top " << top << " ratio " << ratio << " swept " << swept;
        EXPECT_EQ(r.best.iy, first_best.iy)
            << "top " << top << " ratio " << ratio << " swept " << swept;
      }
    }
  }
}

TEST(ExactSearchTest, EmptyClusterFindsNothing) {
  const PoseLattice lattice;
  const VoxelTemplate tpl =
      *MakeTemplateFromPoints(testing::RandomRobotPoints(1), "t", lattice.resolution_m);
  const TemplateRotations rot(tpl, lattice);
  const ClusterVoxels empty;
  const FastScorer scorer(empty, lattice);
  const SearchResult r = ExactSearch().Search({&empty, &scorer, &rot, {1.0, 0.0}});
  EXPECT_EQ(r.hits, 0);
  EXPECT_EQ(r.score, 0.0);
  EXPECT_FALSE(r.has_runner_up);
}

}  // namespace
}  // namespace hpose
