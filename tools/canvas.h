#ifndef HPOSE_TOOLS_CANVAS_H_
#define HPOSE_TOOLS_CANVAS_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/io/decoded_image.h"

struct HposeDrawingApi;
struct HposeDrawTarget;

namespace hpose::tools {

// A pixel position: x to the right, y down.
struct Px {
  int x = 0;
  int y = 0;
  constexpr Px() = default;
  constexpr Px(int x_, int y_) : x(x_), y(y_) {}
  friend constexpr Px operator+(Px a, Px b) { return {a.x + b.x, a.y + b.y}; }
  friend constexpr Px operator-(Px a, Px b) { return {a.x - b.x, a.y - b.y}; }
  friend constexpr Px operator*(Px a, int k) { return {a.x * k, a.y * k}; }
  friend constexpr bool operator==(Px a, Px b) { return a.x == b.x && a.y == b.y; }
};

// A box of pixels: its top-left corner and size; it holds [x, x + width) x [y, y + height).
struct PxBox {
  int x = 0;
  int y = 0;
  int width = 0;
  int height = 0;
  // The box between two corners, whichever way round (as OpenCV's Rect(Point, Point)).
  static PxBox Spanning(Px a, Px b);
};

// A colour: blue, green, red in 0..255 (OpenCV's order, which the pictures were written in).
struct Bgr {
  double b = 0.0;
  double g = 0.0;
  double r = 0.0;
  constexpr Bgr() = default;
  constexpr Bgr(double b_, double g_, double r_) : b(b_), g(g_), r(r_) {}
};

// How a line's pixels are chosen: 8-connected, or anti-aliased.
enum class LineKind { kSharp, kSmooth };
enum class MarkerShape { kCross, kTriangleUp };
inline constexpr int kFilled = -1;  // a thickness that fills the shape.

struct TextBox {
  int width = 0;
  int height = 0;    // above the baseline.
  int baseline = 0;  // below it.
};

// An 8-bit colour picture that the programs draw on for people. The drawing is OpenCV's, done
// by the drawing module (tools/drawing/drawing_api.h), which the first canvas loads: a program
// that draws nothing loads no OpenCV. Shapes are clipped to the canvas; a region is a canvas
// over part of another's pixels, which clips what is drawn on it to that part.
class Canvas {
 public:
  // A `width` x `height` picture of `background`. Fails when the drawing module cannot be
  // loaded, saying where it was looked for.
  static Result<Canvas> Create(int width, int height, const Bgr& background);

  // The part `box` of this canvas (cut to it), drawing on the same pixels.
  Canvas Region(const PxBox& box) const;

  int width() const { return width_; }
  int height() const { return height_; }

  // Sets one pixel; positions outside the canvas are ignored. A Bgr's channels are rounded (halves
  // away from zero) and clamped to [0, 255], as Create's background is.
  void SetPixel(Px p, std::uint8_t b, std::uint8_t g, std::uint8_t r);
  void SetPixel(Px p, const Bgr& colour);

  void Line(Px a, Px b, const Bgr& colour, int thickness = 1, LineKind kind = LineKind::kSharp);
  void Circle(Px centre, int radius, const Bgr& colour, int thickness = 1,
              LineKind kind = LineKind::kSharp);
  // Corners `a` and `b` both drawn.
  void Rectangle(Px a, Px b, const Bgr& colour, int thickness = 1,
                 LineKind kind = LineKind::kSharp);
  // The box's pixels: nothing for an empty box.
  void Rectangle(const PxBox& box, const Bgr& colour, int thickness = 1,
                 LineKind kind = LineKind::kSharp);
  // `tip_length`: the head's length as a share of the arrow's.
  void ArrowedLine(Px from, Px to, const Bgr& colour, int thickness, LineKind kind,
                   double tip_length);
  void Marker(Px at, const Bgr& colour, MarkerShape shape, int size, int thickness);
  // Text in OpenCV's simplex Hershey font, `origin` its baseline's left end; `scale` 1 draws
  // it at the font's own size.
  void Text(const std::string& text, Px origin, double scale, const Bgr& colour, int thickness = 1,
            LineKind kind = LineKind::kSmooth);
  TextBox MeasureText(const std::string& text, double scale, int thickness = 1) const;

  // The whole picture (not only a region's part) as 8-bit red, green, blue.
  DecodedImage ToRgb() const;

 private:
  Canvas() = default;
  void FillTarget(HposeDrawTarget* target) const;
  // Calls draw(target, colour as three doubles) unless the canvas is empty.
  template <typename Draw>
  void DrawWith(const Bgr& colour, Draw draw) const;

  const HposeDrawingApi* api_ = nullptr;
  std::shared_ptr<std::vector<std::uint8_t>> pixels_;  // the whole picture, blue-green-red.
  int full_width_ = 0;
  int full_height_ = 0;
  int left_ = 0;  // this canvas's part of the picture.
  int top_ = 0;
  int width_ = 0;
  int height_ = 0;
};

// A colour from hue (0..360 degrees), saturation and value (0..1).
Bgr BgrFromHsv(double hue_deg, double saturation, double value);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CANVAS_H_
