// The picture `hpose estimate --picture` writes (tools/match_picture.h): the humanoid close up,
// or the nearest miss with why it was refused, scaled to the template.
#include "tools/match_picture.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "core/search/estimator.h"
#include "core/stereo/rgb_image_io.h"

namespace hpose::tools {
namespace {

constexpr int kPanel = 640;  // each half of the picture.

std::string TempPng(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("hpose_match_picture_" + std::to_string(::getpid()) + "_" + name + ".png"))
      .string();
}

// A block `height` high, 0.24 m wide and 0.12 m deep, as surface points every 8 mm.
std::vector<Eigen::Vector3f> Block(double height) {
  std::vector<Eigen::Vector3f> points;
  for (double z = 0.004; z < height; z += 0.008) {
    for (double y = -0.12; y <= 0.12; y += 0.008) {
      points.emplace_back(-0.06f, static_cast<float>(y), static_cast<float>(z));
      points.emplace_back(0.06f, static_cast<float>(y), static_cast<float>(z));
    }
  }
  return points;
}

// A frame with one cluster: the block standing 2 m ahead (the sensor at the ground frame's
// origin), searched with a block template; its detection a humanoid or not.
struct Scene {
  std::vector<VoxelTemplate> templates;
  PointCloud cloud;  // sensor frame = ground frame here.
  Estimate estimate;
};

Scene BlockScene(double height, bool humanoid) {
  Scene s;
  Result<VoxelTemplate> t = MakeTemplateFromPoints(Block(height), "block", 0.016);
  EXPECT_TRUE(t.ok());
  s.templates.push_back(*t);
  for (const Eigen::Vector3f& p : Block(height))
    s.cloud.points.push_back(p + Eigen::Vector3f(2, 0, 0));
  ClusterSummary cluster;
  cluster.index = 0;
  cluster.points = static_cast<int>(s.cloud.size());
  cluster.min = Eigen::Vector3f(1.94f, -0.12f, 0.0f);
  cluster.max = Eigen::Vector3f(2.06f, 0.12f, static_cast<float>(height));
  cluster.searched = true;
  s.estimate.clusters.push_back(cluster);
  Detection d;
  d.best.template_name = "block";
  d.best.cluster_index = 0;
  d.best.pose = Pose2D{2.0, 0.0, 0.0};
  d.best.score = 52.0;
  d.best.refined = true;
  d.best.fit.fit = humanoid ? 90.0 : 41.5;
  d.score_threshold = 50.0;
  d.is_humanoid = humanoid;
  d.refused_by = humanoid ? Refusal::kNone : Refusal::kFit;
  s.estimate.detections.push_back(d);
  return s;
}

RgbImage Draw(const Scene& s, const std::string& name) {
  const std::string path = TempPng(name);
  const EstimatorOptions options;
  EXPECT_TRUE(WriteMatchPicture(s.estimate, s.templates, s.cloud, path, &options).ok());
  Result<RgbImage> img = ReadRgbImage(path);
  std::filesystem::remove(path);
  EXPECT_TRUE(img.ok());
  return img.ok() ? *img : RgbImage();
}

struct Rgb {
  int r, g, b;
};
Rgb At(const RgbImage& img, int col, int row) {
  const std::uint8_t* p = &img.pixels[(static_cast<size_t>(row) * img.width + col) * 3];
  return {p[0], p[1], p[2]};
}
// The close-ups' colours: template voxels red, cluster voxels blue, both magenta.
bool VoxelColour(const Rgb& c) {
  return (c.r == 200 && c.g == 50 && c.b == 50) || (c.r == 40 && c.g == 130 && c.b == 220) ||
         (c.r == 220 && c.g == 60 && c.b == 220);
}
bool Magenta(const Rgb& c) { return c.r == 220 && c.g == 60 && c.b == 220; }
// The light red of the nearest miss's lines (anti-aliased text: red clearly above the rest).
bool MissRed(const Rgb& c) { return c.r > 150 && c.r > c.g + 60 && c.g == c.b; }

// Rows of the right half holding voxel colours, within [row0, row1): first and last (-1: none).
std::pair<int, int> VoxelRows(const RgbImage& img, int row0, int row1) {
  int first = -1, last = -1;
  for (int row = row0; row < row1; ++row) {
    for (int col = kPanel + 1; col < 2 * kPanel; ++col) {
      if (!VoxelColour(At(img, col, row))) continue;
      if (first < 0) first = row;
      last = row;
      break;
    }
  }
  return {first, last};
}

int CountRight(const RgbImage& img, int row0, int row1, bool (*pred)(const Rgb&)) {
  int n = 0;
  for (int row = row0; row < row1; ++row) {
    for (int col = kPanel + 1; col < 2 * kPanel; ++col) n += pred(At(img, col, row));
  }
  return n;
}

TEST(MatchPictureTest, AHumanoidIsShownCloseUpWithoutAMissNote) {
  const RgbImage img = Draw(BlockScene(0.45, true), "humanoid");
  ASSERT_EQ(img.width, 2 * kPanel);
  EXPECT_GT(CountRight(img, 0, kPanel, Magenta), 100);  // template over cluster.
  EXPECT_EQ(CountRight(img, 0, 70, MissRed), 0);
}

TEST(MatchPictureTest, WithoutAHumanoidTheNearestMissIsShownWithWhyItWasRefused) {
  const RgbImage img = Draw(BlockScene(0.45, false), "miss");
  ASSERT_EQ(img.width, 2 * kPanel);
  // The miss close up as a humanoid would be...
  EXPECT_GT(CountRight(img, 0, kPanel, Magenta), 100);
  // ... under light red lines (the pose, and the fit below --min-fit wrapped over two lines).
  EXPECT_GT(CountRight(img, 0, 30, MissRed), 50);
  EXPECT_GT(CountRight(img, 30, 48, MissRed), 50);
  EXPECT_GT(CountRight(img, 48, 66, MissRed), 20);
}

TEST(MatchPictureTest, NothingSearchedLeavesTheCloseUpsEmpty) {
  Scene s = BlockScene(0.45, false);
  s.estimate.detections.clear();
  s.estimate.clusters[0].searched = false;
  const RgbImage img = Draw(s, "none");
  ASSERT_EQ(img.width, 2 * kPanel);
  EXPECT_EQ(CountRight(img, 0, kPanel, VoxelColour), 0);
  EXPECT_GT(CountRight(img, 0, kPanel, MissRed), 50);  // the note says why.
}

bool Orange(const Rgb& c) { return c.r == 255 && c.g == 140 && c.b == 40; }

TEST(MatchPictureTest, FreeLimbsThePoseWasFittedWithoutAreOrange) {
  // The block's left side (y > 0.08 m) marked as a free limb, and missing from the cluster: the
  // robot holds it elsewhere.
  Scene s = BlockScene(0.45, true);
  VoxelTemplate& t = s.templates[0];
  ASSERT_FALSE(t.surface.empty());
  t.free_limb.clear();
  for (const Eigen::Vector3f& p : t.surface) t.free_limb.push_back(p.y() > 0.08f);
  std::vector<Eigen::Vector3f> kept;
  for (const Eigen::Vector3f& p : s.cloud.points) {
    if (p.y() <= 0.08f) kept.push_back(p);
  }
  s.cloud.points = kept;
  const RgbImage fitted_with = Draw(s, "limbs_fitted");
  s.estimate.detections[0].best.free_limbs_left_out = true;
  const RgbImage left_out = Draw(s, "limbs_left_out");
  ASSERT_EQ(left_out.width, 2 * kPanel);
  ASSERT_EQ(fitted_with.width, 2 * kPanel);
  EXPECT_EQ(CountRight(fitted_with, 0, kPanel, Orange), 0);
  EXPECT_GT(CountRight(left_out, 80, kPanel, Orange), 100);  // the limb's voxels, both views.
  // The line under the pose says what orange means (anti-aliased orange text).
  const auto note = [](const Rgb& c) { return c.r > 150 && c.r > c.g + 40 && c.g > c.b + 40; };
  EXPECT_GT(CountRight(left_out, 28, 46, note), 50);
  EXPECT_EQ(CountRight(fitted_with, 28, 46, note), 0);
}

TEST(MatchPictureTest, TheCloseUpsAreScaledToTheTemplate) {
  // The side view (lower half, below its label) shows the whole body, large: a 0.45 m robot
  // over more than half the half's height, a 1.6 m one no less and not cut off at the top.
  for (double height : {0.45, 1.6}) {
    SCOPED_TRACE(height);
    const RgbImage img = Draw(BlockScene(height, true), "scaled");
    ASSERT_EQ(img.width, 2 * kPanel);
    const std::pair<int, int> side = VoxelRows(img, kPanel / 2, kPanel);
    ASSERT_GE(side.first, 0);
    EXPECT_GT(side.first, kPanel / 2 + 20);  // below "seen from the sensor".
    EXPECT_GT(side.second - side.first, 0.5 * (kPanel / 2));
    // The top view (upper half) stays within it.
    const std::pair<int, int> top = VoxelRows(img, 0, kPanel / 2);
    ASSERT_GE(top.first, 0);
    EXPECT_LT(top.second, kPanel / 2 - 10);
  }
}

}  // namespace
}  // namespace hpose::tools
