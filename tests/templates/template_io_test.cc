#include "core/templates/template_io.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

namespace hpose {
namespace {

namespace fs = std::filesystem;

class TemplateIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hpose_tpl_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  static VoxelTemplate RandomTemplate(int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> xy(-0.2f, 0.2f), z(0.0f, 0.6f);
    std::vector<Eigen::Vector3f> pts;
    for (int i = 0; i < n; ++i) pts.emplace_back(xy(rng), xy(rng), z(rng));
    return *MakeTemplateFromPoints(pts, "rand", 0.016, "random", "unit test");
  }

  fs::path dir_;
};

TEST_F(TemplateIoTest, RoundTripKeepsEveryVoxelAndTheSidecar) {
  const VoxelTemplate t = RandomTemplate(3000, 1);
  ASSERT_TRUE(SaveTemplate(t, Path("t.bt")).ok());
  EXPECT_TRUE(fs::exists(Path("t.json")));
  Result<VoxelTemplate> back = LoadTemplate(Path("t.bt"));
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(back->name, "rand");
  EXPECT_EQ(back->variant, "random");
  EXPECT_EQ(back->source, "unit test");
  EXPECT_DOUBLE_EQ(back->resolution_m, 0.016);
  ASSERT_EQ(back->voxels.size(), t.voxels.size());
  for (size_t i = 0; i < t.voxels.size(); ++i) {
    EXPECT_LT((back->voxels[i] - t.voxels[i]).norm(), 1e-5) << i;
  }
}

TEST_F(TemplateIoTest, DenseBlocksSurvivePruning) {
  // A solid block makes OctoMap prune 8 children into one node; loading must expand it again.
  std::vector<Eigen::Vector3f> pts;
  for (int x = 0; x < 8; ++x)
    for (int y = 0; y < 8; ++y)
      for (int z = 0; z < 8; ++z)
        pts.emplace_back(0.016f * x + 0.008f, 0.016f * y + 0.008f, 0.016f * z + 0.008f);
  const VoxelTemplate t = *MakeTemplateFromPoints(pts, "block", 0.016);
  ASSERT_TRUE(SaveTemplate(t, Path("block.bt")).ok());
  Result<VoxelTemplate> back = LoadTemplate(Path("block.bt"));
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->voxels.size(), 512u);
}

TEST_F(TemplateIoTest, MissingFileIsNotFound) {
  Result<VoxelTemplate> r = LoadTemplate(Path("nope.bt"));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kNotFound);
  EXPECT_NE(r.error().message.find("nope.bt"), std::string::npos);
}

TEST_F(TemplateIoTest, GarbageAndTruncatedTreesAreDataLoss) {
  { std::ofstream(Path("garbage.bt")) << "this is not an octree\n\x01\x02"; }
  Result<VoxelTemplate> r = LoadTemplate(Path("garbage.bt"));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kDataLoss);

  const VoxelTemplate t = RandomTemplate(2000, 2);
  ASSERT_TRUE(SaveTemplate(t, Path("full.bt")).ok());
  const auto size = fs::file_size(Path("full.bt"));
  fs::copy_file(Path("full.bt"), Path("cut.bt"));
  fs::resize_file(Path("cut.bt"), size / 2);
  r = LoadTemplate(Path("cut.bt"));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kDataLoss) << r.error().ToString();
}

// OctoMap's reader recurses once per inner node without checking depth or the end of the
// data: nodes that all claim children, far past the tree's 16 levels or past the end of the
// file, are refused before it reads them (no stack overflow), naming the problem.
TEST_F(TemplateIoTest, NestedOrEndlessNodeDataIsDataLoss) {
  const std::string header =
      "# Octomap OcTree binary file\n#\nid OcTree\nsize 100\nres 0.016\ndata\n";
  {
    std::ofstream deep(Path("deep.bt"), std::ios::binary);
    deep << header;
    for (int i = 0; i < 200000; ++i) deep << '\xff' << '\xff';  // every child has children.
  }
  Result<VoxelTemplate> r = LoadTemplate(Path("deep.bt"));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kDataLoss);
  EXPECT_NE(r.error().message.find("16 levels"), std::string::npos) << r.error().message;
  {
    std::ofstream endless(Path("endless.bt"), std::ios::binary);
    endless << header << '\x03' << '\x00' << '\x03' << '\x00';  // children promised, none given.
  }
  r = LoadTemplate(Path("endless.bt"));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kDataLoss);
  EXPECT_NE(r.error().message.find("ends early"), std::string::npos) << r.error().message;
  // Headers OctoMap reads token by token (found by fuzzing): "data" after a value on the same
  // line, or a value on the line after its key. The deep node stream must be found there too.
  for (const std::string& odd_header :
       {std::string("# Octomap OcTree binary file\nid OcTree size 100 res 0.016 data\n"),
        std::string("# Octomap OcTree binary file\nid\nOcTree\nsize\n100\nres 0.016\n  data\n")}) {
    {
      std::ofstream deep(Path("odd.bt"), std::ios::binary | std::ios::trunc);
      deep << odd_header;
      for (int i = 0; i < 200000; ++i) deep << '\xff' << '\xff';
    }
    r = LoadTemplate(Path("odd.bt"));
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kDataLoss);
    EXPECT_NE(r.error().message.find("16 levels"), std::string::npos) << r.error().message;
  }
  // A real template still loads.
  ASSERT_TRUE(SaveTemplate(RandomTemplate(300, 5), Path("fine.bt")).ok());
  EXPECT_TRUE(LoadTemplate(Path("fine.bt")).ok());
}

// A pruned *free* leaf near the root stands for 8^15 voxels: loading must not expand it (a
// fuzzed file ran out of memory there). Root: child 0 an inner node, children 1-7 free leaves;
// then a chain of inner nodes down to one occupied voxel at depth 16. 24 nodes in all.
// One pruned occupied leaf at `depth` stands for 8^(16 - depth) voxels of 16 mm.
std::string OnePrunedOccupiedLeaf(int depth) {
  std::string out = "# Octomap OcTree binary file\nid OcTree\nsize " + std::to_string(depth + 1) +
                    "\nres 0.016\ndata\n";
  for (int d = 0; d < depth - 1; ++d) out += std::string("\x03\x00", 2);  // child 0 inner.
  out += std::string("\x02\x00", 2);  // child 0 an occupied leaf.
  return out;
}

// A fuzzed file held a leaf of two million voxels, and loading it took a minute under the
// sanitizers; a million is the limit now, and what loads comes back in coordinate order.
TEST_F(TemplateIoTest, LargePrunedLeavesLoadInOrderUpToTheLimit) {
  std::ofstream(Path("two_million.bt"), std::ios::binary) << OnePrunedOccupiedLeaf(9);
  const Result<VoxelTemplate> over = LoadTemplate(Path("two_million.bt"));
  ASSERT_FALSE(over.ok());
  EXPECT_EQ(over.error().code, ErrorCode::kOutOfRange);
  EXPECT_NE(over.error().message.find("expands to 2097152 occupied voxels, more than the 1000000"),
            std::string::npos)
      << over.error().message;

  std::ofstream(Path("block.bt"), std::ios::binary) << OnePrunedOccupiedLeaf(10);
  const Result<VoxelTemplate> block = LoadTemplate(Path("block.bt"));
  ASSERT_TRUE(block.ok()) << block.error().ToString();
  ASSERT_EQ(block->voxels.size(), 262144u);  // 64^3
  for (size_t i = 1; i < block->voxels.size(); ++i) {
    const Eigen::Vector3f& a = block->voxels[i - 1];
    const Eigen::Vector3f& b = block->voxels[i];
    ASSERT_LT(std::tie(a.x(), a.y(), a.z()), std::tie(b.x(), b.y(), b.z())) << i;
  }
  const Eigen::Vector3f extent = block->voxels.back() - block->voxels.front();
  EXPECT_NEAR(extent.x(), 63 * 0.016, 1e-4);
  EXPECT_NEAR(extent.z(), 63 * 0.016, 1e-4);
}

TEST_F(TemplateIoTest, PrunedFreeLeavesAreNotExpanded) {
  {
    std::ofstream out(Path("free.bt"), std::ios::binary);
    out << "# Octomap OcTree binary file\nid OcTree\nsize 24\nres 0.016\ndata\n";
    out << '\x57' << '\x55';                                           // 11 01 01 01 | 01 01 01 01
    for (int depth = 1; depth < 15; ++depth) out << '\x03' << '\x00';  // child 0 inner.
    out << '\x02' << '\x00';                                           // child 0 an occupied voxel.
  }
  const Result<VoxelTemplate> r = LoadTemplate(Path("free.bt"));
  ASSERT_TRUE(r.ok()) << r.error().ToString();
  EXPECT_EQ(r->voxels.size(), 1u);
}

TEST_F(TemplateIoTest, SidecarIsValidated) {
  const VoxelTemplate t = RandomTemplate(500, 3);
  ASSERT_TRUE(SaveTemplate(t, Path("s.bt")).ok());
  std::ofstream(Path("s.json")) << "{\"format\":\"hpose-template\",\"version\":1,"
                                   "\"resolution_m\":0.016,\"colour\":\"red\"}";
  Result<VoxelTemplate> r = LoadTemplate(Path("s.bt"));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("colour"), std::string::npos);

  std::ofstream(Path("s.json")) << "{\"format\":\"hpose-template\",\"version\":1,"
                                   "\"resolution_m\":0.02}";
  r = LoadTemplate(Path("s.bt"));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);

  std::ofstream(Path("s.json")) << "{\"format\":";
  r = LoadTemplate(Path("s.bt"));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kDataLoss);
}

TEST_F(TemplateIoTest, WithoutSidecarTheNameIsTheStem) {
  const VoxelTemplate t = RandomTemplate(500, 4);
  ASSERT_TRUE(SaveTemplate(t, Path("robot7.bt")).ok());
  fs::remove(Path("robot7.json"));
  Result<VoxelTemplate> r = LoadTemplate(Path("robot7.bt"));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->name, "robot7");
}

TEST_F(TemplateIoTest, SaveRejectsWrongExtensionAndKeepsOldFileOnFailure) {
  const VoxelTemplate t = RandomTemplate(500, 5);
  EXPECT_EQ(SaveTemplate(t, Path("t.octree")).error().code, ErrorCode::kInvalidArgument);
  ASSERT_TRUE(SaveTemplate(t, Path("keep.bt")).ok());
  VoxelTemplate empty = t;
  empty.voxels.clear();
  EXPECT_FALSE(SaveTemplate(empty, Path("keep.bt")).ok());
  EXPECT_TRUE(LoadTemplate(Path("keep.bt")).ok());
  // A directory that does not exist: error, no crash.
  EXPECT_FALSE(SaveTemplate(t, Path("no/such/dir/t.bt")).ok());
}

}  // namespace
}  // namespace hpose

namespace hpose {
namespace {

class TemplateSurfaceIoTest : public TemplateIoTest {};

TEST_F(TemplateSurfaceIoTest, SurfacePointsRoundTripToATenthOfAMillimetre) {
  const VoxelTemplate t = RandomTemplate(3000, 5);
  ASSERT_FALSE(t.surface.empty());
  ASSERT_TRUE(SaveTemplate(t, Path("s.bt")).ok());
  Result<VoxelTemplate> back = LoadTemplate(Path("s.bt"));
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  ASSERT_EQ(back->surface.size(), t.surface.size());
  for (size_t i = 0; i < t.surface.size(); ++i) {
    EXPECT_LT((back->surface[i] - t.surface[i]).cwiseAbs().maxCoeff(), 0.5e-4 + 1e-7) << i;
  }
}

TEST_F(TemplateSurfaceIoTest, FreeLimbMarksRoundTripAndAreOnlyWrittenWhenSomeAreSet) {
  VoxelTemplate t = RandomTemplate(3000, 9);
  ASSERT_TRUE(SaveTemplate(t, Path("n.bt")).ok());
  Result<VoxelTemplate> back = LoadTemplate(Path("n.bt"));
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_TRUE(back->free_limb.empty());
  t.free_limb.assign(t.surface.size(), 0);
  ASSERT_TRUE(SaveTemplate(t, Path("z.bt")).ok());
  back = LoadTemplate(Path("z.bt"));
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_TRUE(back->free_limb.empty());  // none marked: nothing to say.
  for (size_t i = 0; i < t.surface.size(); ++i) t.free_limb[i] = t.surface[i].z() > 0.3f;
  ASSERT_TRUE(SaveTemplate(t, Path("m.bt")).ok());
  back = LoadTemplate(Path("m.bt"));
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(back->free_limb, t.free_limb);
}

TEST_F(TemplateSurfaceIoTest, CorruptFreeLimbMarksAreRefusedByName) {
  const VoxelTemplate t = RandomTemplate(3, 10);
  ASSERT_EQ(t.surface.size(), 3u);
  for (const std::string& bad :
       {std::string("\"01\""), std::string("\"0101\""), std::string("\"01x\""),
        std::string("[0, 1, 0]"), std::string("7")}) {
    ASSERT_TRUE(SaveTemplate(t, Path("f.bt")).ok());
    std::ofstream(Path("f.json")) << "{\"format\": \"hpose-template\", \"version\": 3, "
                                     "\"resolution_m\": 0.016, \"surface_0.1mm\": "
                                     "[0, 0, 100, 300, 0, 100, 0, 300, 100], \"free_limb\": "
                                  << bad << "}\n";
    Result<VoxelTemplate> back = LoadTemplate(Path("f.bt"));
    ASSERT_FALSE(back.ok()) << bad;
    EXPECT_NE(back.error().message.find("'free_limb'"), std::string::npos) << back.error().message;
  }
}

TEST_F(TemplateSurfaceIoTest, VersionOneSidecarsWithoutSurfaceStillLoad) {
  const VoxelTemplate t = RandomTemplate(500, 6);
  ASSERT_TRUE(SaveTemplate(t, Path("v1.bt")).ok());
  std::ofstream(Path("v1.json"))
      << "{\"format\": \"hpose-template\", \"version\": 1, \"name\": \"old\", \"resolution_m\": "
         "0.016}\n";
  Result<VoxelTemplate> back = LoadTemplate(Path("v1.bt"));
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(back->name, "old");
  EXPECT_TRUE(back->surface.empty());
  // Without a surface the search and the refinement use the voxel centres.
  EXPECT_EQ(back->VoxelSurfaceCentroids().size(), back->voxels.size());
  EXPECT_EQ(&back->SurfaceOrVoxels(), &back->voxels);
}

TEST_F(TemplateSurfaceIoTest, CorruptSurfaceArraysAreRefusedByName) {
  const VoxelTemplate t = RandomTemplate(500, 7);
  for (const std::string& bad :
       {std::string("[1, 2]"), std::string("[1, 2, \"x\"]"), std::string("{}"),
        std::string("[1, 2, 3.5]"), std::string("[1, 2, [3]]"), std::string("[1, {}, 3]"),
        std::string("[1, 2, 100000001]"), std::string("[1, 2, -100000001]"),
        std::string("[1, 2, 18446744073709551615]"), std::string("[1, 2, null]"), std::string("7"),
        std::string("[1, 2, 3] , \"surface_0.1mm\": 5")}) {
    ASSERT_TRUE(SaveTemplate(t, Path("c.bt")).ok());
    std::ofstream(Path("c.json"))
        << "{\"format\": \"hpose-template\", \"version\": 2, \"resolution_m\": 0.016, "
           "\"surface_0.1mm\": "
        << bad << "}\n";
    Result<VoxelTemplate> back = LoadTemplate(Path("c.bt"));
    ASSERT_FALSE(back.ok()) << bad;
    EXPECT_NE(back.error().message.find("surface_0.1mm"), std::string::npos)
        << back.error().message;
  }
}

// The entry named is the first bad one, counting entries of any kind; a key given twice counts
// by its last value, as in any JSON document.
TEST_F(TemplateSurfaceIoTest, SurfaceEntriesAreNamedAndTheLastKeyCounts) {
  const VoxelTemplate t = RandomTemplate(500, 8);
  ASSERT_TRUE(SaveTemplate(t, Path("e.bt")).ok());
  const std::string head =
      "{\"format\": \"hpose-template\", \"version\": 2, \"resolution_m\": 0.016, ";
  std::ofstream(Path("e.json")) << head << "\"surface_0.1mm\": [1, [2, 3], 4, 5.5, 6, 7]}\n";
  Result<VoxelTemplate> back = LoadTemplate(Path("e.bt"));
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().message.find("entry 1 is not an integer"), std::string::npos)
      << back.error().message;

  std::ofstream(Path("e.json")) << head
                                << "\"surface_0.1mm\": [1, 2], \"surface_0.1mm\": [10, -20, 30, "
                                   "40, 50, 60], \"surface_points\": 2}\n";
  back = LoadTemplate(Path("e.bt"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->surface.size(), 2u);
  EXPECT_NEAR(back->surface[0].y(), -0.002f, 1e-7f);
  EXPECT_NEAR(back->surface[1].z(), 0.006f, 1e-7f);

  std::ofstream(Path("e.json")) << "[" << head << "\"surface_0.1mm\": []}]\n";
  back = LoadTemplate(Path("e.bt"));
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().message.find("not a JSON object"), std::string::npos)
      << back.error().message;
}

TEST_F(TemplateSurfaceIoTest, SurfaceCentroidsStayInTheirVoxelColumns) {
  const VoxelTemplate t = RandomTemplate(4000, 8);
  const std::vector<Eigen::Vector3f> c = t.VoxelSurfaceCentroids();
  ASSERT_EQ(c.size(), t.voxels.size());
  for (size_t i = 0; i < c.size(); ++i) {
    // Same height as the voxel centre, and across the floor within the voxel's column.
    EXPECT_FLOAT_EQ(c[i].z(), t.voxels[i].z());
    EXPECT_LE((c[i].head<2>() - t.voxels[i].head<2>()).cwiseAbs().maxCoeff(),
              0.5f * t.resolution_m + 1e-6f);
  }
  // The surface is the input reduced to half-voxel cells: no two points share a cell.
  std::set<std::tuple<int, int, int>> cells;
  for (const Eigen::Vector3f& p : t.surface) {
    const Eigen::Vector3f q = p / static_cast<float>(t.SurfaceCellM());
    cells.insert({static_cast<int>(std::floor(q.x())), static_cast<int>(std::floor(q.y())),
                  static_cast<int>(std::floor(q.z()))});
  }
  EXPECT_EQ(cells.size(), t.surface.size());
}

}  // namespace
}  // namespace hpose
