// The pictures' canvas against OpenCV's drawing called directly: the drawing module must pass
// every shape through unchanged (positions, colour order, thickness, line kind, regions).

#include "tools/canvas.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <string>

#include "tools/drawing_module.h"

namespace hpose::tools {
namespace {

Canvas MakeCanvas(int width, int height, const Bgr& background) {
  Result<Canvas> made = Canvas::Create(width, height, background);
  EXPECT_TRUE(made.ok()) << made.error().ToString();
  return *std::move(made);
}

// The canvas's pixels back in OpenCV's blue-green-red order.
cv::Mat AsBgr(const Canvas& canvas) {
  const DecodedImage rgb = canvas.ToRgb();
  cv::Mat out(rgb.height, rgb.width, CV_8UC3);
  for (int v = 0; v < rgb.height; ++v) {
    for (int u = 0; u < rgb.width; ++u) {
      const std::uint8_t* p = rgb.bytes.data() + (static_cast<size_t>(v) * rgb.width + u) * 3;
      out.at<cv::Vec3b>(v, u) = cv::Vec3b(p[2], p[1], p[0]);
    }
  }
  return out;
}

int DifferentPixels(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  cv::Mat any;
  cv::cvtColor(diff, any, cv::COLOR_BGR2GRAY);
  return cv::countNonZero(any);
}

TEST(CanvasTest, TheModuleLoadsFromTheBuildTree) {
  const std::vector<std::string> where = DrawingModuleCandidates();
  ASSERT_FALSE(where.empty());
  EXPECT_NE(where.back().find("hpose-drawing.so"), std::string::npos) << where.back();
  EXPECT_TRUE(LoadDrawingModule().ok()) << LoadDrawingModule().error().ToString();
}

TEST(CanvasTest, EveryShapeEqualsOpenCvsOwnDrawing) {
  const Bgr back(30, 40, 50), a(200, 60, 10), b(12, 230, 99), c(250, 250, 0);
  Canvas canvas = MakeCanvas(320, 200, back);
  cv::Mat ref(200, 320, CV_8UC3, cv::Scalar(30, 40, 50));
  const auto s = [](const Bgr& x) { return cv::Scalar(x.b, x.g, x.r); };

  canvas.Line(Px(5, 7), Px(300, 150), a);
  cv::line(ref, cv::Point(5, 7), cv::Point(300, 150), s(a));
  canvas.Line(Px(-20, 190), Px(400, 20), b, 2, LineKind::kSmooth);
  cv::line(ref, cv::Point(-20, 190), cv::Point(400, 20), s(b), 2, cv::LINE_AA);
  canvas.Circle(Px(60, 60), 25, c, 2, LineKind::kSmooth);
  cv::circle(ref, cv::Point(60, 60), 25, s(c), 2, cv::LINE_AA);
  canvas.Circle(Px(100, 40), 3, a, kFilled);
  cv::circle(ref, cv::Point(100, 40), 3, s(a), cv::FILLED);
  canvas.Rectangle(Px(150, 20), Px(120, 60), b, 1);
  cv::rectangle(ref, cv::Point(150, 20), cv::Point(120, 60), s(b), 1);
  canvas.Rectangle(PxBox{200, 100, 30, 20}, c, kFilled);
  cv::rectangle(ref, cv::Rect(200, 100, 30, 20), s(c), cv::FILLED);
  canvas.Rectangle(PxBox::Spanning(Px(250, 90), Px(240, 70)), a, 1);
  cv::rectangle(ref, cv::Rect(cv::Point(250, 90), cv::Point(240, 70)), s(a), 1);
  canvas.ArrowedLine(Px(20, 180), Px(90, 120), a, 2, LineKind::kSmooth, 0.3);
  cv::arrowedLine(ref, cv::Point(20, 180), cv::Point(90, 120), s(a), 2, cv::LINE_AA, 0, 0.3);
  canvas.Marker(Px(280, 40), b, MarkerShape::kTriangleUp, 16, 2);
  cv::drawMarker(ref, cv::Point(280, 40), s(b), cv::MARKER_TRIANGLE_UP, 16, 2);
  canvas.Marker(Px(280, 90), c, MarkerShape::kCross, 12, 1);
  cv::drawMarker(ref, cv::Point(280, 90), s(c), cv::MARKER_CROSS, 12, 1);
  canvas.Text("x 1.25 m  theta -30 deg", Px(10, 140), 0.45, c);
  cv::putText(ref, "x 1.25 m  theta -30 deg", cv::Point(10, 140), cv::FONT_HERSHEY_SIMPLEX, 0.45,
              s(c), 1, cv::LINE_AA);
  canvas.SetPixel(Px(0, 0), 1, 2, 3);
  ref.at<cv::Vec3b>(0, 0) = cv::Vec3b(1, 2, 3);

  // The same region of both: shapes drawn on it are clipped to it and placed from its corner.
  Canvas region = canvas.Region(PxBox{160, 120, 100, 60});
  cv::Mat ref_region = ref(cv::Rect(160, 120, 100, 60));
  EXPECT_EQ(region.width(), 100);
  EXPECT_EQ(region.height(), 60);
  region.Circle(Px(90, 50), 30, b, kFilled, LineKind::kSmooth);
  cv::circle(ref_region, cv::Point(90, 50), 30, s(b), cv::FILLED, cv::LINE_AA);
  region.Text("clipped text", Px(40, 20), 0.6, a);
  cv::putText(ref_region, "clipped text", cv::Point(40, 20), cv::FONT_HERSHEY_SIMPLEX, 0.6, s(a), 1,
              cv::LINE_AA);
  region.SetPixel(Px(5, 5), 9, 8, 7);
  region.SetPixel(Px(6, 5), Bgr(9.5, -3.0, 300.0));  // rounded and clamped to bytes.
  ref_region.at<cv::Vec3b>(5, 6) = cv::Vec3b(10, 0, 255);
  region.SetPixel(Px(100, 5), 9, 8, 7);  // outside the region: ignored.
  region.SetPixel(Px(-1, 5), 9, 8, 7);
  ref_region.at<cv::Vec3b>(5, 5) = cv::Vec3b(9, 8, 7);

  const cv::Mat drawn = AsBgr(canvas);
  EXPECT_EQ(DifferentPixels(drawn, ref), 0);
  // And something was drawn at all.
  EXPECT_GT(DifferentPixels(drawn, cv::Mat(200, 320, CV_8UC3, cv::Scalar(30, 40, 50))), 2000);
  EXPECT_EQ(drawn.at<cv::Vec3b>(125, 165), cv::Vec3b(9, 8, 7));
}

TEST(CanvasTest, TextSizesAreOpenCvs) {
  const Canvas canvas = MakeCanvas(10, 10, Bgr(0, 0, 0));
  for (const double scale : {0.4, 0.7, 1.0}) {
    const std::string text = "no humanoid found in any frame";
    const TextBox box = canvas.MeasureText(text, scale, 1);
    int baseline = 0;
    const cv::Size ref = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
    EXPECT_EQ(box.width, ref.width);
    EXPECT_EQ(box.height, ref.height);
    EXPECT_EQ(box.baseline, baseline);
    EXPECT_GT(box.width, box.height);
  }
}

TEST(CanvasTest, RegionsAreCutToTheCanvas) {
  Canvas canvas = MakeCanvas(50, 40, Bgr(0, 0, 0));
  const Canvas inside = canvas.Region(PxBox{40, 30, 30, 30});
  EXPECT_EQ(inside.width(), 10);
  EXPECT_EQ(inside.height(), 10);
  Canvas outside = canvas.Region(PxBox{60, 10, 5, 5});
  EXPECT_EQ(outside.width(), 0);
  outside.Rectangle(PxBox{0, 0, 5, 5}, Bgr(255, 255, 255), kFilled);  // nothing to draw on.
  outside.Text("x", Px(0, 4), 1.0, Bgr(255, 255, 255));
  const DecodedImage rgb = canvas.ToRgb();
  EXPECT_EQ(rgb.width, 50);
  EXPECT_EQ(rgb.height, 40);
  for (const std::uint8_t v : rgb.bytes) ASSERT_EQ(v, 0);
}

TEST(CanvasTest, BadSizesAreRefused) {
  const Result<Canvas> none = Canvas::Create(0, 10, Bgr(0, 0, 0));
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().message.find("0 x 10"), std::string::npos) << none.error().message;
  EXPECT_FALSE(Canvas::Create(10, -3, Bgr(0, 0, 0)).ok());
}

TEST(CanvasTest, ColoursAreRgbInTheImage) {
  const Canvas canvas = MakeCanvas(2, 1, Bgr(10, 20, 30));
  const DecodedImage rgb = canvas.ToRgb();
  ASSERT_EQ(rgb.bytes.size(), 6u);
  EXPECT_EQ(rgb.bytes[0], 30);
  EXPECT_EQ(rgb.bytes[1], 20);
  EXPECT_EQ(rgb.bytes[2], 10);
  EXPECT_EQ(rgb.channels, 3);
  EXPECT_EQ(rgb.bits_per_sample, 8);
}

// BgrFromHsv against OpenCV's 8-bit conversion (hue in steps of 2 degrees), rounded.
TEST(CanvasTest, HsvColoursMatchOpenCvs) {
  int checked = 0;
  for (int h = 0; h < 180; h += 7) {
    for (const int sat : {0, 128, 230, 255}) {
      for (const int val : {0, 90, 200, 255}) {
        cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(h, sat, val)), bgr;
        cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
        const cv::Vec3b ref = bgr.at<cv::Vec3b>(0, 0);
        const Bgr mine = BgrFromHsv(2.0 * h, sat / 255.0, val / 255.0);
        EXPECT_NEAR(mine.b, ref[0], 0.51) << h << " " << sat << " " << val;
        EXPECT_NEAR(mine.g, ref[1], 0.51) << h << " " << sat << " " << val;
        EXPECT_NEAR(mine.r, ref[2], 0.51) << h << " " << sat << " " << val;
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 26 * 16);
}

}  // namespace
}  // namespace hpose::tools
