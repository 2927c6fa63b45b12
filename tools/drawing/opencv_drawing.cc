// The drawing module: the functions of tools/drawing/drawing_api.h, drawn with OpenCV's imgproc
// on a matrix header over the caller's pixels. Built as a loadable module (hpose-drawing.so).

#include <opencv2/imgproc.hpp>

#include "tools/drawing/drawing_api.h"

namespace {

cv::Mat Wrap(const HposeDrawTarget* t) {
  return cv::Mat(t->height, t->width, CV_8UC3, t->bgr, t->stride);
}

cv::Scalar Colour(const double* c) { return cv::Scalar(c[0], c[1], c[2]); }

// OpenCV reports bad arguments as exceptions; none may cross into the program, and a shape it
// refuses is left undrawn.
template <typename Draw>
void Guarded(Draw draw) noexcept {
  try {
    draw();
  } catch (...) {
  }
}

void Line(const HposeDrawTarget* t, int x0, int y0, int x1, int y1, const double* colour,
          int thickness, int kind) {
  Guarded([&] {
    cv::Mat img = Wrap(t);
    cv::line(img, cv::Point(x0, y0), cv::Point(x1, y1), Colour(colour), thickness, kind);
  });
}

void Circle(const HposeDrawTarget* t, int x, int y, int radius, const double* colour, int thickness,
            int kind) {
  Guarded([&] {
    cv::Mat img = Wrap(t);
    cv::circle(img, cv::Point(x, y), radius, Colour(colour), thickness, kind);
  });
}

void Rectangle(const HposeDrawTarget* t, int x0, int y0, int x1, int y1, const double* colour,
               int thickness, int kind) {
  Guarded([&] {
    cv::Mat img = Wrap(t);
    cv::rectangle(img, cv::Point(x0, y0), cv::Point(x1, y1), Colour(colour), thickness, kind);
  });
}

void ArrowedLine(const HposeDrawTarget* t, int x0, int y0, int x1, int y1, const double* colour,
                 int thickness, int kind, double tip_length) {
  Guarded([&] {
    cv::Mat img = Wrap(t);
    cv::arrowedLine(img, cv::Point(x0, y0), cv::Point(x1, y1), Colour(colour), thickness, kind, 0,
                    tip_length);
  });
}

void Marker(const HposeDrawTarget* t, int x, int y, const double* colour, int shape, int size,
            int thickness) {
  Guarded([&] {
    cv::Mat img = Wrap(t);
    const int type = shape == kHposeMarkerTriangleUp ? cv::MARKER_TRIANGLE_UP : cv::MARKER_CROSS;
    cv::drawMarker(img, cv::Point(x, y), Colour(colour), type, size, thickness);
  });
}

void Text(const HposeDrawTarget* t, const char* text, int x, int y, double scale,
          const double* colour, int thickness, int kind) {
  Guarded([&] {
    cv::Mat img = Wrap(t);
    cv::putText(img, text, cv::Point(x, y), cv::FONT_HERSHEY_SIMPLEX, scale, Colour(colour),
                thickness, kind);
  });
}

void TextSize(const char* text, double scale, int thickness, int* width, int* height,
              int* baseline) {
  *width = *height = *baseline = 0;
  Guarded([&] {
    const cv::Size size =
        cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, thickness, baseline);
    *width = size.width;
    *height = size.height;
  });
}

constexpr HposeDrawingApi kApi = {kHposeDrawingApiVersion,
                                  sizeof(HposeDrawingApi),
                                  &Line,
                                  &Circle,
                                  &Rectangle,
                                  &ArrowedLine,
                                  &Marker,
                                  &Text,
                                  &TextSize};

}  // namespace

extern "C" __attribute__((visibility("default"))) const HposeDrawingApi* hpose_drawing_api_v1() {
  return &kApi;
}
