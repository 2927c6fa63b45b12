// The exact search's bounds must stay valid where two template columns share a placed cell:
// dense free space (every unoccupied cell around the cluster seen through) is where a lower
// bound that counted such a cell twice would prune the optimum away.
#include <algorithm>
#include <climits>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "tests/sanitizer_build.h"

#include "core/scoring/column_occupancy.h"
#include "core/scoring/fast_scorer.h"
#include "core/search/exact_search.h"
#include "core/search/free_space_grow.h"
#include "core/search/pose_search.h"
#include "tests/search/search_test_scenes.h"

namespace hpose {
namespace {

// Every cell within `reach` cells (x, y) of the cluster's cells and below z_top that the
// cluster does not occupy.
ClusterVoxels DenseFreeSpace(const ClusterVoxels& cluster, int reach, int z_top) {
  std::set<std::tuple<int, int, int>> occupied;
  Eigen::Vector3i lo = cluster.cells.front(), hi = lo;
  for (const Eigen::Vector3i& c : cluster.cells) {
    occupied.insert({c.x(), c.y(), c.z()});
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  ClusterVoxels free;
  free.resolution_m = cluster.resolution_m;
  for (int x = lo.x() - reach; x <= hi.x() + reach; ++x) {
    for (int y = lo.y() - reach; y <= hi.y() + reach; ++y) {
      for (int z = 0; z <= z_top; ++z) {
        if (occupied.count({x, y, z}) == 0) free.cells.emplace_back(x, y, z);
      }
    }
  }
  return free;
}

struct Scene {
  PoseLattice lattice;
  VoxelTemplate tpl;
  ClusterVoxels cluster;
  Pose2D truth;
};

Scene MakeScene(unsigned seed, int angle_steps, int subdivisions) {
  Scene s;
  s.lattice.angle_steps = angle_steps;
  s.lattice.subdivisions = subdivisions;
  const std::vector<Eigen::Vector3f> robot = testing::RandomRobotPoints(seed);
  s.tpl = *MakeTemplateFromPoints(robot, "t", s.lattice.resolution_m);
  s.truth = Pose2D{1.1, -0.1 + 0.03 * (seed % 7), DegToRad(-160.0 + 37.0 * (seed % 9))};
  s.cluster = VoxeliseCluster(testing::VisibleCluster(robot, s.truth, 0.004f, seed),
                              s.lattice.resolution_m);
  return s;
}

// Two searches found the same: optimum, counts, runner-up, and after the same work.
void ExpectSameSearch(const SearchResult& got, const SearchResult& want, const std::string& where) {
  EXPECT_EQ(got.value, want.value) << where;
  EXPECT_EQ(got.best, want.best) << where;
  EXPECT_EQ(got.hits, want.hits) << where;
  EXPECT_EQ(got.free_hits, want.free_hits) << where;
  EXPECT_EQ(got.below_min_value, want.below_min_value) << where;
  EXPECT_EQ(got.has_runner_up, want.has_runner_up) << where;
  EXPECT_EQ(got.runner_up_score, want.runner_up_score) << where;
  EXPECT_EQ(got.bounds_evaluated, want.bounds_evaluated) << where;
  EXPECT_EQ(got.poses_evaluated, want.poses_evaluated) << where;
}

// What the estimator computes free space for (core/search/estimator.cc): the box of the
// cluster's cells grown, height by height, by FreeSpaceGrow (the search's origin margin plus the
// template's reach at that height, plus two voxels). No pose a search may place (every pose of
// the exact search's region; for the paper's search every pose within its margin of the
// centroid) reaches a cell outside it; the region is not grown by much more than that (a ring
// six cells inside it is reached); and a search given only the free cells within it finds what
// it finds with every free cell around, after as many bounds.
TEST(ExactSearchBoundsTest, SearchesReadFreeSpaceWithinTheirOriginMarginAndReach) {
  for (unsigned seed = 0; seed < (testing::kSanitizerBuild ? 2u : 4u); ++seed) {
    const Scene s = MakeScene(700 + seed, 24, seed % 2 == 0 ? 4 : 2);
    ASSERT_FALSE(s.cluster.cells.empty());
    const TemplateRotations rot(s.tpl, s.lattice);
    Eigen::Vector3i lo = s.cluster.cells.front(), hi = lo;
    for (const Eigen::Vector3i& c : s.cluster.cells) {
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
    // How far outside the box of the cluster's cells (x, y) the column (x, y) lies.
    const auto outside = [&](int x, int y) {
      return std::max({0, lo.x() - x, x - hi.x(), lo.y() - y, y - hi.y()});
    };
    // The cells of layers 0 .. 45 outside the region grown by `extra` more cells a layer (every
    // cell of a layer without template voxels), within 12 cells beyond the largest growth.
    const auto ring = [&](const std::vector<int>& grow, int extra) {
      const int most = *std::max_element(grow.begin(), grow.end()) + 12;
      ClusterVoxels out;
      out.resolution_m = s.lattice.resolution_m;
      for (int x = lo.x() - most; x <= hi.x() + most; ++x) {
        for (int y = lo.y() - most; y <= hi.y() + most; ++y) {
          for (int z = 0; z <= 45; ++z) {
            const int g = z < static_cast<int>(grow.size()) ? grow[z] : -1;
            if (g >= 0 && outside(x, y) <= g + extra) continue;
            out.cells.emplace_back(x, y, z);
          }
        }
      }
      return out;
    };
    // The most cells of `free` any pose within the inclusive index box covers.
    const auto most_hits = [&](const ClusterVoxels& free, int ix0, int ix1, int iy0, int iy1) {
      const FastScorer scorer(free, s.lattice);
      int most = 0;
      for (int t = 0; t < s.lattice.angle_steps; ++t) {
        for (int ix = ix0; ix <= ix1; ++ix) {
          for (int iy = iy0; iy <= iy1; ++iy)
            most = std::max(most, scorer.Hits(rot.Get(t), ix, iy));
        }
      }
      return most;
    };
    ExactSearchOptions exact_options;
    exact_options.auto_margin_fraction = 0.25 * (seed % 3 + 1);
    const ExactSearch exact(exact_options);
    const PaperSearch paper;
    for (const PoseSearch* search :
         {static_cast<const PoseSearch*>(&exact), static_cast<const PoseSearch*>(&paper)}) {
      const std::string where =
          "seed " + std::to_string(seed) + (search == &exact ? ", exact" : ", paper");
      const std::vector<int> grow =
          FreeSpaceGrow(s.tpl, search->OriginMargin(rot), s.lattice.resolution_m);
      ASSERT_FALSE(grow.empty());
      // The template is wider at some heights than at others: the layers differ.
      EXPECT_LT(*std::min_element(grow.begin(), grow.end()),
                *std::max_element(grow.begin(), grow.end()) - 1)
          << where;
      int ix0, ix1, iy0, iy1;
      if (search == &exact) {
        const ExactSearch::Region region = exact.TranslationRegion(s.cluster, rot);
        ix0 = region.ix_min, ix1 = region.ix_max, iy0 = region.iy_min, iy1 = region.iy_max;
      } else {  // the centroid lies within the cells' box.
        const int m = static_cast<int>(std::ceil(paper.OriginMargin(rot) / s.lattice.step_m()));
        const int q = s.lattice.subdivisions;
        ix0 = lo.x() * q - m, ix1 = (hi.x() + 1) * q + m, iy0 = lo.y() * q - m,
        iy1 = (hi.y() + 1) * q + m;
      }
      EXPECT_EQ(most_hits(ring(grow, 0), ix0, ix1, iy0, iy1), 0) << where;
      EXPECT_GT(most_hits(ring(grow, -6), ix0, ix1, iy0, iy1), 0) << where;
      if (search != &exact) continue;
      // Every free cell around, and only those within the region.
      const int most = *std::max_element(grow.begin(), grow.end());
      const ClusterVoxels around = DenseFreeSpace(s.cluster, most + 4, 45);
      ClusterVoxels within;
      within.resolution_m = around.resolution_m;
      for (const Eigen::Vector3i& c : around.cells) {
        if (c.z() < static_cast<int>(grow.size()) && grow[c.z()] >= outside(c.x(), c.y()))
          within.cells.push_back(c);
      }
      ASSERT_LT(within.cells.size(), around.cells.size()) << where;
      const FastScorer scorer(s.cluster, s.lattice);
      const auto search_with = [&](const ClusterVoxels& free) {
        SearchProblem problem{&s.cluster, &scorer, &rot, {s.truth.x, s.truth.y}};
        problem.free_space = &free;
        problem.hit_weight = 2;
        return exact.Search(problem);
      };
      const SearchResult a = search_with(around);
      ExpectSameSearch(search_with(within), a, where);
      EXPECT_GT(a.free_hits, 0) << where;
    }
  }
}

// Grids made once for a cluster and shared by the searches of several templates (the estimator
// makes them per cluster) change nothing: every result and count equals the search's own
// grids', with and without free space, with a minimum value, and with the searches of two
// templates running at once on two threads.
TEST(ExactSearchBoundsTest, SharedGridsGiveTheSameSearches) {
  for (unsigned seed = 0; seed < (testing::kSanitizerBuild ? 2u : 4u); ++seed) {
    const Scene a = MakeScene(800 + seed, 36, 4), b = MakeScene(900 + seed, 36, 4);
    const TemplateRotations rot_a(a.tpl, a.lattice), rot_b(b.tpl, b.lattice);
    const ClusterVoxels free = DenseFreeSpace(a.cluster, 10, 45);
    const FastScorer scorer(a.cluster, a.lattice);
    const ExactSearch search;
    for (const bool with_free : {false, true}) {
      const ClusterVoxels* f = with_free ? &free : nullptr;
      const std::shared_ptr<const SearchGrids> grids =
          search.MakeGrids(a.cluster, f, {&rot_a, &rot_b});
      ASSERT_NE(grids, nullptr);
      for (const int min_value : {INT_MIN, 40}) {
        const TemplateRotations* rots[2] = {&rot_a, &rot_b};
        const auto search_with = [&](int k, const SearchGrids* g) {
          SearchProblem problem{&a.cluster, &scorer, rots[k], {a.truth.x, a.truth.y}};
          problem.free_space = f;
          problem.hit_weight = 2;
          problem.min_value = min_value;
          problem.grids = g;
          return search.Search(problem);
        };
        SearchResult own[2], shared[2];
        for (int k = 0; k < 2; ++k) own[k] = search_with(k, nullptr);
        std::thread other([&] { shared[1] = search_with(1, grids.get()); });
        shared[0] = search_with(0, grids.get());
        other.join();
        for (int k = 0; k < 2; ++k) {
          const std::string where = "seed " + std::to_string(seed) + " template " +
                                    std::to_string(k) + (with_free ? " with free space" : "") +
                                    " min " + std::to_string(min_value);
          ExpectSameSearch(shared[k], own[k], where);
        }
      }
    }
    // Templates of different lattices cannot share.
    PoseLattice other_lattice = a.lattice;
    other_lattice.subdivisions = 2;
    const TemplateRotations rot_c(b.tpl, other_lattice);
    EXPECT_EQ(search.MakeGrids(a.cluster, &free, {&rot_a, &rot_c}), nullptr);
  }
}

// The lower bound of free-space hits over a translation block never exceeds the exact free
// hits of any pose in the block, even where columns collide (dense free space).
TEST(ColumnOccupancyBoundsTest, FreeSpaceLowerBoundHoldsWithCollidingColumns) {
  std::mt19937 rng(17);
  for (unsigned seed = 0; seed < (testing::kSanitizerBuild ? 2u : 6u); ++seed) {
    const Scene s = MakeScene(500 + seed, 360, seed % 3 == 2 ? 3 : 4);
    ASSERT_FALSE(s.cluster.cells.empty());
    const ClusterVoxels free = DenseFreeSpace(s.cluster, 14, 45);
    const TemplateRotations rot(s.tpl, s.lattice);
    const RotatedTemplate& r0 = rot.Get(0);
    const ColumnOccupancy lower(free, s.lattice, r0.z_base, r0.z_words, 4,
                                ColumnOccupancy::Filter::kMin);
    const FastScorer exact(free, s.lattice);
    const LatticePose c = NearestLatticePose(s.lattice, s.truth);
    std::uniform_int_distribution<int> d(-24, 24), th(0, 359);
    int collisions_seen = 0;
    for (int k = 0; k < 60; ++k) {
      const RotatedTemplate& r = rot.Get(th(rng));
      const std::vector<std::uint64_t> disjoint = CellDisjointMasks(r, s.lattice.subdivisions);
      for (int level = 0; level <= 4; ++level) {
        const int a = c.ix + d(rng), b = c.iy + d(rng);
        int min_hits = INT_MAX;
        for (int i = 0; i < (1 << level); ++i) {
          for (int j = 0; j < (1 << level); ++j) {
            min_hits = std::min(min_hits, exact.Hits(r, a + i, b + j));
          }
        }
        const int bound = lower.LowerBound(r, disjoint.data(), a, b, level);
        ASSERT_LE(bound, min_hits)
            << "seed " << seed << " theta " << r.itheta << " level " << level;
        // Counting every column (the plain Bound) overshoots here: the case this guards.
        if (lower.Bound(r, a, b, level) > min_hits) ++collisions_seen;
      }
    }
    EXPECT_GT(collisions_seen, 0) << "seed " << seed << ": no colliding columns exercised";
  }
}

// The four-quarter bound equals four single bounds, for theta blocks too, both filters, every
// level, on and off the cluster's edges.
TEST(ColumnOccupancyBoundsTest, Bound4EqualsFourBounds) {
  std::mt19937 rng(23);
  for (unsigned seed = 0; seed < 6; ++seed) {
    const Scene s = MakeScene(700 + seed, 360, seed % 3 == 2 ? 3 : 4);
    const ClusterVoxels free = DenseFreeSpace(s.cluster, 6, 45);
    const TemplateRotations rot(s.tpl, s.lattice);
    const RotatedTemplate& r0 = rot.Get(0);
    for (const ColumnOccupancy::Filter f :
         {ColumnOccupancy::Filter::kMax, ColumnOccupancy::Filter::kMin}) {
      const ClusterVoxels& cells = f == ColumnOccupancy::Filter::kMax ? s.cluster : free;
      const ColumnOccupancy occ(cells, s.lattice, r0.z_base, r0.z_words, 6, f);
      const LatticePose c = NearestLatticePose(s.lattice, s.truth);
      std::uniform_int_distribution<int> d(-90, 90), th(0, 359), tl(0, 4);
      for (int k = 0; k < 200; ++k) {
        const int tlevel = tl(rng);
        const RotatedTemplate& r = rot.GetBlock(tlevel, (th(rng) >> tlevel) << tlevel);
        const int level = k % 6;
        const int a = c.ix + d(rng), b = c.iy + d(rng);
        int four[4];
        occ.Bound4(r, a, b, level, four);
        for (int i = 0; i < 2; ++i) {
          for (int j = 0; j < 2; ++j) {
            ASSERT_EQ(four[2 * i + j], occ.Bound(r, a + (i << level), b + (j << level), level))
                << "seed " << seed << " level " << level;
          }
        }
      }
    }
  }
}

// Bound by its definition: per column, its z mask against the OR (kMax) or AND (kMin, cells
// without voxels empty) of the cells its window sweeps over the block, floor_div(q + a, S) ..
// floor_div(q + a + 2^level - 1, S) per axis; every level, both filters, both layouts (the
// aligned one: one box for every level, levels of doubled windows made from the one below),
// single headings, on and off the voxels. Theta blocks: the aligned layout bounds them as the
// per-level boxes of the filtered windows do.
TEST(ColumnOccupancyBoundsTest, BoundEqualsItsDefinition) {
  std::mt19937 rng(31);
  for (unsigned seed = 0; seed < 3; ++seed) {
    const Scene s = MakeScene(850 + seed, 360, 4);
    const ClusterVoxels free = DenseFreeSpace(s.cluster, 6, 45);
    const TemplateRotations rot(s.tpl, s.lattice);
    const RotatedTemplate& r0 = rot.Get(0);
    ASSERT_EQ(r0.z_words, 1);
    const int S = s.lattice.subdivisions;
    const LatticePose c = NearestLatticePose(s.lattice, s.truth);
    ColumnOccupancy::CellRange lookups;  // every window of the blocks below starts in it.
    lookups.x_lo = c.ix / S - 60;
    lookups.x_hi = c.ix / S + 60;
    lookups.y_lo = c.iy / S - 60;
    lookups.y_hi = c.iy / S + 60;
    for (const ColumnOccupancy::Filter f :
         {ColumnOccupancy::Filter::kMax, ColumnOccupancy::Filter::kMin}) {
      const bool max_filter = f == ColumnOccupancy::Filter::kMax;
      const ClusterVoxels& cells = max_filter ? s.cluster : free;
      std::map<std::pair<int, int>, std::uint64_t> mask_at;
      for (const Eigen::Vector3i& v : cells.cells) {
        const int bit = v.z() - r0.z_base;
        if (bit >= 0 && bit < 64) mask_at[{v.x(), v.y()}] |= std::uint64_t{1} << bit;
      }
      const auto mask = [&](int x, int y) {
        const auto it = mask_at.find({x, y});
        return it == mask_at.end() ? std::uint64_t{0} : it->second;
      };
      const ColumnOccupancy plain(cells, s.lattice, r0.z_base, 1, 6, f);
      const ColumnOccupancy aligned(cells, s.lattice, r0.z_base, 1, 6, f, &lookups);
      ASSERT_TRUE(aligned.aligned());
      ASSERT_FALSE(plain.aligned());
      std::uniform_int_distribution<int> d(-25, 25), near(-10, 10), th(0, 359), tl(1, 3);
      int nonzero = 0;
      for (int k = 0; k < 120; ++k) {
        const RotatedTemplate& r = rot.Get(th(rng));
        const int level = k % 7;
        const int a = c.ix + S * near(rng) + (level < 2 ? k % S : 0);
        const int b = c.iy + S * near(rng) + (level < 2 ? (k / S) % S : 0);
        int want = 0;
        for (size_t col = 0; col < r.column_q.size(); ++col) {
          const Eigen::Vector2i q = r.column_q[col];
          std::uint64_t window = max_filter ? 0 : ~std::uint64_t{0};
          for (int x = FloorDiv(q.x() + a, S); x <= FloorDiv(q.x() + a + (1 << level) - 1, S);
               ++x) {
            for (int y = FloorDiv(q.y() + b, S); y <= FloorDiv(q.y() + b + (1 << level) - 1, S);
                 ++y) {
              window = max_filter ? (window | mask(x, y)) : (window & mask(x, y));
            }
          }
          want += __builtin_popcountll(r.column_masks[col] & window);
        }
        const std::string where = "seed " + std::to_string(seed) + " level " +
                                  std::to_string(level) + (max_filter ? " max" : " min");
        ASSERT_EQ(plain.Bound(r, a, b, level), want) << where;
        ASSERT_EQ(aligned.Bound(r, a, b, level), want) << where << " aligned";
        nonzero += want > 0 ? 1 : 0;
        // A theta block of blocks of at least S steps at multiples of S (the aligned path).
        const int tlevel = tl(rng);
        const RotatedTemplate& block = rot.GetBlock(tlevel, (th(rng) >> tlevel) << tlevel);
        const int block_level = 2 + k % 5;
        const int ba = c.ix / S * S + S * d(rng), bb = c.iy / S * S + S * d(rng);
        ASSERT_EQ(aligned.Bound(block, ba, bb, block_level),
                  plain.Bound(block, ba, bb, block_level))
            << where << " theta level " << tlevel;
      }
      EXPECT_GT(nonzero, 40) << "seed " << seed << ": the blocks missed the voxels";
    }
  }
}

// Columns that can share a placed cell keep disjoint z bits, and no voxel is invented.
TEST(ColumnOccupancyBoundsTest, CellDisjointMasksAreSubsetsAndPairwiseDisjoint) {
  const Scene s = MakeScene(42, 360, 4);
  const TemplateRotations rot(s.tpl, s.lattice);
  for (int t = 0; t < 360; t += 13) {
    const RotatedTemplate& r = rot.Get(t);
    const std::vector<std::uint64_t> m = CellDisjointMasks(r, s.lattice.subdivisions);
    ASSERT_EQ(m.size(), r.column_masks.size());
    const int words = r.z_words;
    const int n = static_cast<int>(r.column_q.size());
    int kept = 0, total = 0;
    for (int i = 0; i < n; ++i) {
      for (int w = 0; w < words; ++w) {
        EXPECT_EQ(m[i * words + w] & ~r.column_masks[i * words + w], 0u);
        kept += __builtin_popcountll(m[i * words + w]);
        total += __builtin_popcountll(r.column_masks[i * words + w]);
      }
      for (int j = i + 1; j < n; ++j) {
        const Eigen::Vector2i dq = r.column_q[j] - r.column_q[i];
        if (std::abs(dq.x()) >= s.lattice.subdivisions ||
            std::abs(dq.y()) >= s.lattice.subdivisions) {
          continue;
        }
        for (int w = 0; w < words; ++w) {
          EXPECT_EQ(m[i * words + w] & m[j * words + w], 0u) << "theta " << t;
        }
      }
    }
    EXPECT_GT(kept, 0);
    EXPECT_LE(kept, total);
  }
}

// With dense free space the exact search still equals brute force over its whole lattice,
// for the paper's weights and for hits weighted twice, with and without a minimum value.
TEST(ExactSearchBoundsTest, DenseFreeSpaceEqualsExhaustiveSearch) {
  for (unsigned seed = 0; seed < (testing::kSanitizerBuild ? 2u : 8u); ++seed) {
    const Scene s = MakeScene(600 + seed, 24, seed % 2 == 0 ? 4 : 2);
    ASSERT_FALSE(s.cluster.cells.empty());
    const ClusterVoxels free = DenseFreeSpace(s.cluster, 12, 45);
    const TemplateRotations rot(s.tpl, s.lattice);
    const FastScorer scorer(s.cluster, s.lattice);
    const FastScorer free_scorer(free, s.lattice);
    ExactSearchOptions opts;
    opts.margin_m = 0.05;
    opts.max_level = 2 + seed % 4;
    const ExactSearch search(opts);
    SearchProblem problem{&s.cluster, &scorer, &rot, {s.truth.x, s.truth.y}};
    problem.free_space = &free;
    problem.free_space_weight = 1;
    problem.hit_weight = 1 + seed % 2;
    const ExactSearch::Region region = search.TranslationRegion(s.cluster, rot);
    int best = INT_MIN;
    for (int t = 0; t < s.lattice.angle_steps; ++t) {
      for (int ix = region.ix_min; ix <= region.ix_max; ++ix) {
        for (int iy = region.iy_min; iy <= region.iy_max; ++iy) {
          best = std::max(best, problem.hit_weight * scorer.Hits(rot.Get(t), ix, iy) -
                                    free_scorer.Hits(rot.Get(t), ix, iy));
        }
      }
    }
    const SearchResult r = search.Search(problem);
    ASSERT_EQ(r.value, best) << "seed " << seed;
    EXPECT_EQ(r.value, problem.hit_weight * r.hits - r.free_hits);
    // Dense free space makes the free-space part count: the same optimum with it at every level
    // and at none, blocks of 16 headings at the top split first or last, single headings from
    // the top.
    for (const auto& [free_levels, lead] : {std::pair{31, 4}, {0, -10}}) {
      ExactSearchOptions other = opts;
      other.top_theta_level = 4;
      other.free_bound_max_level = free_levels;
      other.theta_split_ratio = 0.0;
      other.theta_split_lead = lead;
      EXPECT_EQ(ExactSearch(other).Search(problem).value, best)
          << "seed " << seed << ", free part up to level " << free_levels;
      other.top_theta_level = 0;
      EXPECT_EQ(ExactSearch(other).Search(problem).value, best)
          << "seed " << seed << ", free part up to level " << free_levels << ", single headings";
    }
    // A minimum just above and just below the optimum.
    problem.min_value = best + 1;
    const SearchResult above = search.Search(problem);
    EXPECT_TRUE(above.below_min_value) << "seed " << seed;
    EXPECT_GE(above.value_upper_bound, best);
    EXPECT_LT(above.value_upper_bound, problem.min_value);
    // Stopped below the minimum, it still reports a real pose with its exact value (not a bound,
    // not an unset pose at the origin).
    const RotatedTemplate& stopped = rot.Get(above.best.itheta);
    EXPECT_EQ(above.value, problem.hit_weight * scorer.Hits(stopped, above.best.ix, above.best.iy) -
                               free_scorer.Hits(stopped, above.best.ix, above.best.iy))
        << "seed " << seed;
    EXPECT_LE(above.value, best);
    EXPECT_GT(above.poses_evaluated, 0);
    // It gets there by one descent (four quarters or two halves a level), not by searching on:
    // it expands no more than the full search does before its optimum.
    EXPECT_LE(above.bounds_evaluated,
              r.bounds_evaluated + 4 * (opts.max_level + TemplateRotations::kThetaLevels))
        << "seed " << seed;
    EXPECT_FALSE(above.has_runner_up);
    problem.min_value = best;
    const SearchResult at = search.Search(problem);
    EXPECT_FALSE(at.below_min_value) << "seed " << seed;
    EXPECT_EQ(at.value, best) << "seed " << seed;
  }
}

}  // namespace
}  // namespace hpose
