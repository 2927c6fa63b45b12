#include "core/stereo/color_segmenter.h"

#include <cmath>

#include <gtest/gtest.h>

namespace hpose {
namespace {

// Paints an anti-aliased disc (coverage by 8x8 supersampling) of `rgb` over the image.
void PaintDisc(RgbImage* img, double cx, double cy, double r, const std::array<int, 3>& rgb) {
  for (int y = 0; y < img->height; ++y) {
    for (int x = 0; x < img->width; ++x) {
      int inside = 0;
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
          const double sx = x - 0.5 + (i + 0.5) / 8, sy = y - 0.5 + (j + 0.5) / 8;
          inside += (sx - cx) * (sx - cx) + (sy - cy) * (sy - cy) <= r * r;
        }
      if (inside == 0) continue;
      const double a = inside / 64.0;
      std::uint8_t* p = img->at(x, y);
      for (int c = 0; c < 3; ++c)
        p[c] = static_cast<std::uint8_t>(std::lround(a * rgb[c] + (1 - a) * p[c]));
    }
  }
}

RgbImage Field(int w, int h) {
  RgbImage img(w, h);
  for (size_t i = 0; i < img.pixels.size(); i += 3) {
    img.pixels[i] = 60;
    img.pixels[i + 1] = 110;
    img.pixels[i + 2] = 65;
  }
  return img;
}

const HsvRange kBlue{205, 250, 0.45, 1, 0.15, 1};
const HsvRange kOrange{8, 40, 0.5, 1, 0.15, 1};

TEST(ColorSegmenterTest, FindsBlobsPerClassWithSubpixelCentroids) {
  RgbImage img = Field(160, 100);
  PaintDisc(&img, 40.3, 30.7, 9.0, {35, 70, 190});
  PaintDisc(&img, 110.6, 60.2, 6.0, {35, 70, 190});
  PaintDisc(&img, 80.25, 80.4, 7.0, {225, 105, 25});
  PaintDisc(&img, 140, 20, 1.0, {35, 70, 190});  // too small: noise.
  auto seg = ColorSegmenter::Create({kBlue, kOrange});
  ASSERT_TRUE(seg.ok());
  const auto blobs = seg->Segment(img);
  ASSERT_EQ(blobs.size(), 2u);
  ASSERT_EQ(blobs[0].size(), 2u);
  ASSERT_EQ(blobs[1].size(), 1u);
  EXPECT_GT(blobs[0][0].area_px, blobs[0][1].area_px);  // sorted by area.
  EXPECT_NEAR(blobs[0][0].centroid_px.x(), 40.3, 0.03);
  EXPECT_NEAR(blobs[0][0].centroid_px.y(), 30.7, 0.03);
  EXPECT_NEAR(blobs[0][1].centroid_px.x(), 110.6, 0.03);
  EXPECT_NEAR(blobs[0][1].centroid_px.y(), 60.2, 0.03);
  EXPECT_NEAR(blobs[1][0].centroid_px.x(), 80.25, 0.03);
  EXPECT_NEAR(blobs[1][0].centroid_px.y(), 80.4, 0.03);
  // The refined centroid is closer to the truth than the binary mask's.
  const double refined = (blobs[0][1].centroid_px - Eigen::Vector2d(110.6, 60.2)).norm();
  const double mask = (blobs[0][1].mask_centroid_px - Eigen::Vector2d(110.6, 60.2)).norm();
  EXPECT_LE(refined, mask + 1e-9);
  EXPECT_GE(blobs[0][0].min_x, 30);
  EXPECT_LE(blobs[0][0].max_x, 50);
}

TEST(ColorSegmenterTest, HueRangeWrapsThroughZero) {
  auto seg = ColorSegmenter::Create({HsvRange{340, 15, 0.5, 1, 0.2, 1}});
  ASSERT_TRUE(seg.ok());
  EXPECT_EQ(seg->Classify(220, 30, 40), 0);     // red, hue ~357.
  EXPECT_EQ(seg->Classify(220, 60, 30), 0);     // red-orange, hue ~8.
  EXPECT_EQ(seg->Classify(30, 60, 220), -1);    // blue.
  EXPECT_EQ(seg->Classify(120, 120, 120), -1);  // grey: no saturation.
}

TEST(ColorSegmenterTest, InvalidRangesAndOptionsAreRejected) {
  auto bad_sat = ColorSegmenter::Create({HsvRange{0, 10, 0.8, 0.2, 0, 1}});
  ASSERT_FALSE(bad_sat.ok());
  EXPECT_EQ(bad_sat.error().code, ErrorCode::kInvalidArgument);
  EXPECT_FALSE(ColorSegmenter::Create({HsvRange{0, 400, 0, 1, 0, 1}}).ok());
  EXPECT_FALSE(ColorSegmenter::Create({HsvRange{std::nan(""), 10, 0, 1, 0, 1}}).ok());
  EXPECT_FALSE(ColorSegmenter::Create({}).ok());
  ColorSegmenterOptions opt;
  opt.connectivity = 6;
  EXPECT_FALSE(ColorSegmenter::Create({kBlue}, opt).ok());
}

TEST(ColorSegmenterTest, EmptyFieldHasNoBlobs) {
  auto seg = ColorSegmenter::Create({kBlue, kOrange});
  ASSERT_TRUE(seg.ok());
  const auto blobs = seg->Segment(Field(64, 48));
  EXPECT_TRUE(blobs[0].empty());
  EXPECT_TRUE(blobs[1].empty());
}

}  // namespace
}  // namespace hpose
