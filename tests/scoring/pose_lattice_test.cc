#include "core/scoring/pose_lattice.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "core/scoring/gather_sums.h"

namespace hpose {
namespace {

TEST(FloorDivTest, MatchesMathematicalFloor) {
  for (int a = -40; a <= 40; ++a) {
    for (int b : {1, 2, 3, 4, 7, 8}) {
      EXPECT_EQ(FloorDiv(a, b), static_cast<int>(std::floor(static_cast<double>(a) / b)))
          << a << "/" << b;
    }
  }
}

TEST(PoseLatticeTest, PoseConversionsRoundTrip) {
  const PoseLattice lattice;
  EXPECT_DOUBLE_EQ(lattice.step_m(), 0.004);
  const LatticePose p{-25, 250, 270};
  const Pose2D pose = ToPose(lattice, p);
  EXPECT_NEAR(pose.x, -0.1, 1e-12);
  EXPECT_NEAR(pose.y, 1.0, 1e-12);
  EXPECT_NEAR(pose.theta, -kPi / 2, 1e-12);
  EXPECT_EQ(NearestLatticePose(lattice, pose), p);
  EXPECT_EQ(WrapAngleIndex(lattice, -1), 359);
  EXPECT_EQ(WrapAngleIndex(lattice, 720), 0);
  EXPECT_NEAR(ToPose(lattice, {0, 0, 180}).theta, kPi, 1e-12);
}

TEST(PoseLatticeTest, ValidateNamesTheBadField) {
  PoseLattice l;
  l.subdivisions = 0;
  ASSERT_FALSE(l.Validate().ok());
  EXPECT_NE(l.Validate().error().message.find("subdivisions"), std::string::npos);
  l = PoseLattice();
  l.resolution_m = -1;
  EXPECT_FALSE(l.Validate().ok());
}

// The placed cell equals floor((R p + t) / resolution) computed directly, except where R p + t
// lies within rounding distance of a cell boundary (the quantisation of R p decides there).
TEST(PoseLatticeTest, PlacedCellIsTheCellOfTheTransformedPoint) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.3f, 0.3f), h(0.0f, 0.6f);
  for (int subdivisions : {1, 2, 4, 8}) {
    PoseLattice lattice;
    lattice.subdivisions = subdivisions;
    VoxelTemplate tpl;
    tpl.name = "t";
    for (int i = 0; i < 300; ++i) tpl.voxels.emplace_back(u(rng), u(rng), h(rng));
    int checked = 0;
    for (int itheta : {0, 1, 45, 90, 133, 180, 359}) {
      const RotatedTemplate r = RotateTemplate(tpl, lattice, itheta);
      const double th = itheta * lattice.angle_step_rad();
      for (int ix : {-300, -17, 0, 5, 251}) {
        for (int iy : {-99, 0, 3, 400}) {
          for (size_t k = 0; k < tpl.voxels.size(); ++k) {
            const Eigen::Vector3f& p = tpl.voxels[k];
            const double x = std::cos(th) * p.x() - std::sin(th) * p.y() + ix * lattice.step_m();
            const double y = std::sin(th) * p.x() + std::cos(th) * p.y() + iy * lattice.step_m();
            const double fx = x / lattice.resolution_m, fy = y / lattice.resolution_m;
            if (std::abs(fx - std::round(fx)) < 1e-6 || std::abs(fy - std::round(fy)) < 1e-6) {
              continue;
            }
            const Eigen::Vector3i c = PlacedCell(r.sub_cells[k], ix, iy, subdivisions);
            ASSERT_EQ(c.x(), static_cast<int>(std::floor(fx)));
            ASSERT_EQ(c.y(), static_cast<int>(std::floor(fy)));
            ASSERT_EQ(c.z(), static_cast<int>(std::floor(p.z() / lattice.resolution_m)));
            ++checked;
          }
        }
      }
    }
    EXPECT_GT(checked, 30000);
  }
}

TEST(TemplateRotationsTest, PrecomputesEveryAngle) {
  VoxelTemplate tpl;
  tpl.name = "t";
  tpl.voxels = {{0.1f, 0.0f, 0.2f}, {0.0f, 0.05f, 0.3f}};
  const PoseLattice lattice;
  const TemplateRotations rot(tpl, lattice);
  EXPECT_EQ(rot.Get(90).itheta, 90);
  // 90 degrees turns +x into +y: q = floor(0.1 * 4 / 0.016) = 25 on the y axis.
  const auto has_column = [](const RotatedTemplate& r, int qx, int qy) {
    return std::find(r.column_q.begin(), r.column_q.end(), Eigen::Vector2i(qx, qy)) !=
           r.column_q.end();
  };
  EXPECT_TRUE(has_column(rot.Get(90), 0, 25));
  EXPECT_TRUE(has_column(rot.Get(0), 25, 0));
  // The rim: the far corner (26, 1) of the sub-voxel cell (25, 0), 4 mm steps.
  EXPECT_NEAR(rot.rim_radius_m(), std::hypot(26 * 0.004, 1 * 0.004), 1e-12);
}

// Cell tables' run headers hold cells up to kRunMaxX (4 095) from the template's origin: a
// template reaching farther (here 4.2 m on a lattice of 1 mm voxels: 4 200 cells) goes without
// them, by the columns' path, and one within reach (2.5 m, swept over 16 headings at most 3 100
// cells) keeps them.
TEST(TemplateRotationsTest, TablesOnlyForTemplatesWithinARunHeadersReach) {
  PoseLattice lattice;
  lattice.resolution_m = 0.001;
  ASSERT_TRUE(lattice.Validate().ok());
  for (const float far : {2.5f, 4.2f}) {
    const std::vector<Eigen::Vector3f> points = {{0.1f, 0.0f, 0.2f}, {far, 0.0f, 0.2f}};
    const TemplateRotations rot("t", 0.2, points, lattice);
    EXPECT_EQ(rot.has_cell_groups(), far < 4.0f) << far << " m";
  }
}

// The *IfMade getters read the tables' directory and make nothing: a table is there once its
// getter has made it, or once MakeTables has made every one (which enters each in the
// directory), and it is the getter's own table: the same words, runs and prefetch length as the
// tables themselves (the directory packs them in one word).
TEST(TemplateRotationsTest, TablesIfMadeAreThoseTheGettersMade) {
  VoxelTemplate tpl;
  tpl.name = "t";
  tpl.voxels = {{0.1f, 0.0f, 0.2f}, {0.0f, 0.05f, 0.3f}, {-0.06f, 0.02f, 0.1f}};
  PoseLattice lattice;
  lattice.angle_steps = 90;
  const int s = lattice.subdivisions;
  const TemplateRotations lazy(tpl, lattice);
  ASSERT_TRUE(lazy.has_cell_groups());
  const auto same = [](const CellTable& a, const CellTable& b) {
    return a.words == b.words && a.runs == b.runs && a.prefetch_words == b.prefetch_words &&
           a.mask_bytes == b.mask_bytes;
  };
  EXPECT_EQ(lazy.SweptTableIfMade(2, 4, 1, 2, 0).words, nullptr);
  EXPECT_EQ(lazy.SweptTableIfMade(2, 4, 1, 2, 0).prefetch_words, 0);
  EXPECT_EQ(lazy.CommonTableIfMade(3, 8, 1, 3).words, nullptr);
  EXPECT_EQ(lazy.CommonPairTableIfMade(1, 6, 0, 2).words, nullptr);
  EXPECT_EQ(lazy.SweptTableIfMade(0, 5, 0, 1, 1).words, nullptr);
  const CellTable swept = lazy.SweptTable(2, 4, 1, 2, 0);
  ASSERT_NE(swept.words, nullptr);
  EXPECT_TRUE(same(lazy.SweptTableIfMade(2, 4, 1, 2, 0), swept));
  const CellTable common = lazy.CommonTable(3, 8, 1, 3);
  EXPECT_TRUE(same(lazy.CommonTableIfMade(3, 8, 1, 3), common));
  const CellTable pair = lazy.CommonPairTable(1, 6, 0, 2);
  EXPECT_TRUE(same(lazy.CommonPairTableIfMade(1, 6, 0, 2), pair));
  // Asking made nothing else: the neighbouring blocks' and residues' tables are still absent.
  EXPECT_EQ(lazy.SweptTableIfMade(2, 8, 1, 2, 0).words, nullptr);
  EXPECT_EQ(lazy.SweptTableIfMade(2, 4, 1, 0, 0).words, nullptr);
  EXPECT_EQ(lazy.CommonTableIfMade(3, 16, 1, 3).words, nullptr);
  EXPECT_EQ(lazy.CommonPairTableIfMade(1, 8, 0, 2).words, nullptr);

  const TemplateRotations ahead(tpl, lattice);
  ahead.MakeTables(TemplateRotations::kThetaLevels - 1, 0, 40);
  ahead.MakeTables(TemplateRotations::kThetaLevels - 1, 40, lattice.angle_steps);
  int checked = 0;
  for (int t = 0; t < TemplateRotations::kThetaLevels; ++t) {
    for (int first = 0; first < lattice.angle_steps; first += 1 << t) {
      for (int level = 0; level <= TemplateRotations::kSweptLevels; ++level) {
        const int step = std::min(1 << level, s);
        for (int ra = 0; ra < s; ra += step) {
          for (int rb = 0; rb < s; rb += step) {
            const CellTable made = ahead.SweptTableIfMade(t, first, level, ra, rb);
            ASSERT_NE(made.words, nullptr) << t << " " << first << " " << level;
            EXPECT_TRUE(same(made, ahead.SweptBlockGroups(t, first, level, ra, rb).table()));
            ++checked;
          }
        }
      }
      for (int ra = 0; ra < s; ++ra) {
        for (int rb = 0; rb < s; ++rb) {
          const CellTable made = ahead.CommonTableIfMade(t, first, ra, rb);
          ASSERT_NE(made.words, nullptr) << t << " " << first;
          EXPECT_TRUE(same(made, ahead.CommonBlockGroups(t, first, ra, rb).table()));
          if ((ra | rb) % 2 != 0) continue;
          const CellTable pair_made = ahead.CommonPairTableIfMade(t, first, ra, rb);
          ASSERT_NE(pair_made.words, nullptr) << t << " " << first;
          EXPECT_TRUE(same(pair_made, ahead.CommonPairGroups(t, first, ra, rb).table()));
        }
      }
    }
  }
  EXPECT_GT(checked, 1000);
}

// Two rotated templates have the same column view: angle, columns and their masks, ranges.
void ExpectSameColumns(const RotatedTemplate& a, const RotatedTemplate& b, const std::string& at) {
  EXPECT_EQ(a.itheta, b.itheta) << at;
  EXPECT_EQ(a.column_q, b.column_q) << at;
  EXPECT_EQ(a.column_masks, b.column_masks) << at;
  EXPECT_EQ(a.q_min, b.q_min) << at;
  EXPECT_EQ(a.q_max, b.q_max) << at;
  EXPECT_EQ(a.z_base, b.z_base) << at;
  EXPECT_EQ(a.z_words, b.z_words) << at;
}

// TemplateRotations computes per column of the template (points of equal x, y) what
// RotatePoints computes per point: the same rotated template at every angle.
TEST(TemplateRotationsTest, EqualsRotatingEveryPoint) {
  VoxelTemplate tpl;
  tpl.name = "t";
  tpl.resolution_m = 0.016;
  for (int i = 0; i < 40; ++i) {
    const float x = 0.013f * static_cast<float>(i % 7) - 0.04f;
    const float y = 0.017f * static_cast<float>(i % 5) - 0.03f;
    tpl.voxels.emplace_back(x, y, 0.016f * static_cast<float>(i % 11));
    tpl.voxels.emplace_back(x, y, 0.016f * static_cast<float>(i % 11) + 0.5f);
  }
  const PoseLattice lattice;
  const TemplateRotations rot(tpl, lattice);
  const std::vector<Eigen::Vector3f> points = tpl.VoxelSurfaceCentroids();
  EXPECT_EQ(rot.voxels(), points.size());
  for (int t = 0; t < lattice.angle_steps; t += 7) {
    const RotatedTemplate a = RotatePoints(points, lattice, t);
    const RotatedTemplate& b = rot.Get(t);
    EXPECT_TRUE(b.sub_cells.empty()) << t;  // the column view only.
    ExpectSameColumns(a, b, "rotation " + std::to_string(t));
  }
}

// ForEachPlacedVoxel reads a rotation's column view: every distinct sub-cell of RotatePoints,
// once, also where two template voxels land on the same sub-cell and for templates taller than
// one 64-bit word.
TEST(TemplateRotationsTest, PlacedVoxelsAreTheDistinctSubCells) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.12f, 0.12f);
  std::uniform_real_distribution<float> h(0.0f, 1.6f);  // 100 z cells: two words.
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 400; ++i) points.emplace_back(u(rng), u(rng), h(rng));
  points.push_back(points[7]);  // the same sub-cell twice.
  const PoseLattice lattice;
  for (int t : {0, 13, 90, 200, 359}) {
    const RotatedTemplate r = RotatePoints(points, lattice, t);
    ASSERT_GT(r.z_words, 1);
    std::vector<std::tuple<int, int, int>> want, got;
    for (const Eigen::Vector3i& q : r.sub_cells) want.emplace_back(q.x(), q.y(), q.z());
    std::sort(want.begin(), want.end());
    want.erase(std::unique(want.begin(), want.end()), want.end());
    ASSERT_LT(want.size(), r.sub_cells.size()) << t;
    ForEachPlacedVoxel(r, [&](const Eigen::Vector3i& q) { got.emplace_back(q.x(), q.y(), q.z()); });
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, want) << t;
  }
}

// A tall template's slabs are cut from its own rotations and theta blocks; each must equal the
// TemplateRotations of the slab's points built on their own (the reference): same columns,
// masks, extents, free-space masks and ranges, here with a slab whose lowest cell lies above
// its word's first and a gap of more than 64 cells (a word with no slab).
TEST(TemplateRotationsTest, SlabsEqualRotationsOfTheirOwnPoints) {
  PoseLattice lattice;
  lattice.angle_steps = 40;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> xy(-0.12f, 0.12f);
  std::vector<Eigen::Vector3f> points;
  const auto add = [&](int z_lo, int z_hi, int count) {
    std::uniform_int_distribution<int> z(z_lo, z_hi);
    for (int i = 0; i < count; ++i) {
      points.emplace_back(xy(rng), xy(rng), (static_cast<float>(z(rng)) + 0.5f) * 0.016f);
    }
  };
  add(0, 70, 300);     // word 0 and the start of word 1 (z cells 64-70)
  add(200, 240, 200);  // word 3 from cell 8 of it (none in cells 71-199: word 2 is empty)
  const TemplateRotations rot("t", 3.3, points, lattice);
  ASSERT_EQ(rot.z_words(), 4);
  // Cut the points as the slabs are: at every 64th cell from the lowest.
  int z_base = INT_MAX;
  for (const Eigen::Vector3f& p : points) z_base = std::min(z_base, CellOf(p, 0.016).z());
  std::vector<std::vector<Eigen::Vector3f>> cut(4);
  for (const Eigen::Vector3f& p : points) cut[(CellOf(p, 0.016).z() - z_base) / 64].push_back(p);
  ASSERT_TRUE(cut[2].empty());
  cut.erase(cut.begin() + 2);
  ASSERT_EQ(rot.slabs().size(), 3u);
  const auto same = [](const RotatedTemplate& a, const RotatedTemplate& b, const std::string& at) {
    ExpectSameColumns(a, b, at);
    EXPECT_EQ(a.column_extent, b.column_extent) << at;
    EXPECT_EQ(a.column_cxe, b.column_cxe) << at;
    EXPECT_EQ(a.column_cy, b.column_cy) << at;
  };
  for (size_t k = 0; k < 3; ++k) {
    const TemplateRotations& slab = *rot.slabs()[k];
    const TemplateRotations ref("t", 3.3, cut[k], lattice);
    const std::string name = "slab " + std::to_string(k);
    EXPECT_EQ(slab.z_words(), 1) << name;
    EXPECT_TRUE(slab.has_cell_groups()) << name;
    EXPECT_EQ(slab.max_block_extent(), ref.max_block_extent()) << name;
    EXPECT_EQ(slab.column_q_min(), ref.column_q_min()) << name;
    EXPECT_EQ(slab.column_q_max(), ref.column_q_max()) << name;
    for (int i = 0; i < lattice.angle_steps; ++i) {
      same(slab.Get(i), ref.Get(i), name + " rotation " + std::to_string(i));
      EXPECT_EQ(slab.DisjointMasks(i), ref.DisjointMasks(i)) << name << " rotation " << i;
    }
    for (int t = 1; t < TemplateRotations::kThetaLevels; ++t) {
      EXPECT_EQ(slab.block_extent(t), ref.block_extent(t)) << name << " level " << t;
      for (int first = 0; first < lattice.angle_steps; first += 1 << t) {
        same(slab.GetBlock(t, first), ref.GetBlock(t, first),
             name + " block " + std::to_string(t) + "/" + std::to_string(first));
      }
    }
  }
  // Slab 1 starts 64 cells above the lowest point; slab 2 at its first point, 8 cells into
  // its word.
  EXPECT_EQ(rot.slabs()[1]->Get(0).z_base, z_base + 64);
  EXPECT_EQ(rot.slabs()[2]->Get(0).z_base, z_base + 200);
}

}  // namespace
}  // namespace hpose
