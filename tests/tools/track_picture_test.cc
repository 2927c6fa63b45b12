#include "tools/track_picture.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "core/stereo/rgb_image_io.h"

namespace hpose::tools {
namespace {

std::string TempPng(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("hpose_track_picture_" + std::to_string(::getpid()) + "_" + name + ".png"))
      .string();
}

// A robot walking a circle of 0.4 m about (1.8, 0.3), found in every frame but 10..14.
std::vector<TrackPoint> Circle() {
  std::vector<TrackPoint> track;
  for (int i = 0; i < 60; ++i) {
    TrackPoint p;
    p.time_s = 100.0 + i / 30.0;
    const double a = 2.0 * kPi * i / 60;
    p.found = i < 10 || i >= 15;
    p.pose = Pose2D{1.8 + 0.4 * std::cos(a), 0.3 + 0.4 * std::sin(a), NormalizeAngle(a + kPi / 2)};
    p.score = 60.0 + 10.0 * std::sin(a);
    p.heading_ambiguous = i == 30;
    track.push_back(p);
  }
  return track;
}

struct Rgb {
  int r, g, b;
};
Rgb At(const RgbImage& img, int col, int row) {
  const std::uint8_t* p = &img.pixels[(static_cast<size_t>(row) * img.width + col) * 3];
  return {p[0], p[1], p[2]};
}
// The path's colours run from blue to red; the background, grid and labels are grey.
bool Coloured(const Rgb& c) { return std::max({c.r, c.g, c.b}) - std::min({c.r, c.g, c.b}) > 40; }
// Whether a track colour lies within `radius` pixels of (col, row).
bool ColouredNear(const RgbImage& img, int col, int row, int radius) {
  for (int dr = -radius; dr <= radius; ++dr) {
    for (int dc = -radius; dc <= radius; ++dc) {
      if (Coloured(At(img, col + dc, row + dr))) return true;
    }
  }
  return false;
}

TEST(TrackPictureTest, TheTopViewShowsTheSensorAndEveryFoundPose) {
  const std::vector<TrackPoint> track = Circle();
  const TrackTopView v = FitTrackTopView(track);
  const auto inside = [&](double x, double y) {
    return v.Col(y) > v.left && v.Col(y) < v.left + v.size && v.Row(x) > v.top &&
           v.Row(x) < v.top + v.size;
  };
  EXPECT_TRUE(inside(0.0, 0.0));
  for (const TrackPoint& p : track) EXPECT_TRUE(inside(p.pose.x, p.pose.y)) << p.time_s;
  // +x up the picture, +y to its left, one scale for both.
  EXPECT_LT(v.Row(2.0), v.Row(1.0));
  EXPECT_LT(v.Col(0.5), v.Col(0.0));
  EXPECT_NEAR(v.Row(1.0) - v.Row(2.0), v.Col(0.0) - v.Col(1.0), 1);
}

TEST(TrackPictureTest, ThePathIsDrawnWhereThePosesAreAndNowhereElse) {
  const std::vector<TrackPoint> track = Circle();
  const std::string path = TempPng("circle");
  ASSERT_TRUE(WriteTrackPicture(track, "circle", path).ok());
  const Result<RgbImage> img = ReadRgbImage(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(img.ok()) << img.error().ToString();
  EXPECT_EQ(img->width, kTrackPictureWidth);
  EXPECT_EQ(img->height, kTrackPictureHeight);
  const TrackTopView v = FitTrackTopView(track);
  for (const TrackPoint& p : track) {
    if (!p.found) continue;
    EXPECT_TRUE(ColouredNear(*img, v.Col(p.pose.y), v.Row(p.pose.x), 1)) << p.time_s;
  }
  // Nothing is drawn in the circle's middle, between it and the sensor, or beyond it.
  EXPECT_FALSE(ColouredNear(*img, v.Col(0.3), v.Row(1.8), 6));
  EXPECT_FALSE(ColouredNear(*img, v.Col(0.3), v.Row(0.9), 6));
  EXPECT_FALSE(ColouredNear(*img, v.Col(-0.4), v.Row(1.8), 6));
}

// Whether the truth's pale green lies within `radius` pixels of (col, row).
bool TruthNear(const RgbImage& img, int col, int row, int radius) {
  for (int dr = -radius; dr <= radius; ++dr) {
    for (int dc = -radius; dc <= radius; ++dc) {
      const Rgb c = At(img, col + dc, row + dr);
      if (c.g > 180 && c.r < c.g - 40 && c.b < c.g - 40) return true;
    }
  }
  return false;
}

TEST(TrackPictureTest, TheTruthIsDrawnBeneathWhereTheRobotStood) {
  // The robot truly walked a circle 0.5 m further from the sensor than the one estimated, and
  // its truth reaches beyond every estimate: the view takes it in.
  std::vector<TrackPoint> track = Circle();
  for (TrackPoint& p : track) {
    p.has_truth = true;
    p.truth = Pose2D{p.pose.x + 0.5, p.pose.y, p.pose.theta};
  }
  const TrackTopView v = FitTrackTopView(track);
  EXPECT_GT(v.Row(2.8), v.top);  // the truth's farthest point, 2.7 m.
  const std::string path = TempPng("truth");
  ASSERT_TRUE(WriteTrackPicture(track, "truth", path).ok());
  const Result<RgbImage> img = ReadRgbImage(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(img.ok());
  int truth_seen = 0;
  for (const TrackPoint& p : track)
    truth_seen += TruthNear(*img, v.Col(p.truth.y), v.Row(p.truth.x), 1);
  EXPECT_GE(truth_seen, 55);  // of 60: where the estimated path crosses it, it is drawn over.
  // Not where nothing stood: the middle of the true circle, and the estimates' own middle.
  EXPECT_FALSE(TruthNear(*img, v.Col(0.3), v.Row(2.3), 6));
  EXPECT_FALSE(TruthNear(*img, v.Col(0.3), v.Row(1.8), 6));
  // Without a truth nothing is drawn in its colour.
  const std::string plain = TempPng("plain");
  ASSERT_TRUE(WriteTrackPicture(Circle(), "plain", plain).ok());
  const Result<RgbImage> without = ReadRgbImage(plain);
  std::filesystem::remove(plain);
  ASSERT_TRUE(without.ok());
  int pale_green = 0;
  for (int row = 0; row < without->height; ++row) {
    for (int col = 0; col < without->width; ++col) pale_green += TruthNear(*without, col, row, 0);
  }
  EXPECT_EQ(pale_green, 0);
}

TEST(TrackPictureTest, ATrackWithoutAHumanoidIsDrawnWithoutAPath) {
  std::vector<TrackPoint> track = Circle();
  for (TrackPoint& p : track) p.found = false;
  const std::string path = TempPng("none");
  ASSERT_TRUE(WriteTrackPicture(track, "none", path).ok());
  const Result<RgbImage> img = ReadRgbImage(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(img.ok());
  const TrackTopView v = FitTrackTopView(track);
  int coloured = 0;
  for (int row = v.top; row < v.top + v.size; ++row) {
    for (int col = v.left; col < v.left + v.size; ++col) coloured += Coloured(At(*img, col, row));
  }
  // The "no humanoid found" note is drawn in a pale red; no path colours beyond it.
  EXPECT_LT(coloured, 3000);
  EXPECT_GT(coloured, 100);
  // The view is of the floor ahead of the sensor, and the note leaves the sensor clear.
  EXPECT_GT(v.Row(0.0), v.top + v.size / 2);
  EXPECT_LT(v.Row(1.0), v.top + v.size / 2);
  EXPECT_FALSE(ColouredNear(*img, v.Col(0.0), v.Row(0.0), 20));
  EXPECT_TRUE(WriteTrackPicture({}, "empty", path).ok());
  std::filesystem::remove(path);
  EXPECT_FALSE(WriteTrackPicture(track, "x", "/nonexistent-dir/track.png").ok());
}

}  // namespace
}  // namespace hpose::tools
