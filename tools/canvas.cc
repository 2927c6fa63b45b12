#include "tools/canvas.h"

#include <algorithm>
#include <cmath>

#include "tools/drawing/drawing_api.h"
#include "tools/drawing_module.h"

namespace hpose::tools {
namespace {

int Kind(LineKind kind) { return kind == LineKind::kSmooth ? kHposeLineAntialiased : kHposeLine8; }

// A colour channel as a byte: rounded, halves away from zero, and clamped.
std::uint8_t ChannelByte(double v) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
}

}  // namespace

PxBox PxBox::Spanning(Px a, Px b) {
  const int x0 = std::min(a.x, b.x), y0 = std::min(a.y, b.y);
  return {x0, y0, std::max(a.x, b.x) - x0, std::max(a.y, b.y) - y0};
}

Result<Canvas> Canvas::Create(int width, int height, const Bgr& background) {
  if (width <= 0 || height <= 0) {
    return MakeError(ErrorCode::kInvalidArgument, "a picture of " + std::to_string(width) + " x " +
                                                      std::to_string(height) + " pixels");
  }
  Result<const HposeDrawingApi*> api = LoadDrawingModule();
  if (!api.ok()) return api.error();
  Canvas c;
  c.api_ = *api;
  c.full_width_ = c.width_ = width;
  c.full_height_ = c.height_ = height;
  c.pixels_ = std::make_shared<std::vector<std::uint8_t>>(static_cast<size_t>(width) * height * 3);
  const std::uint8_t bgr[3] = {ChannelByte(background.b), ChannelByte(background.g),
                               ChannelByte(background.r)};
  for (size_t i = 0; i < c.pixels_->size(); i += 3) {
    std::copy(bgr, bgr + 3, c.pixels_->data() + i);
  }
  return c;
}

Canvas Canvas::Region(const PxBox& box) const {
  Canvas r = *this;
  const int x0 = std::clamp(box.x, 0, width_), y0 = std::clamp(box.y, 0, height_);
  const int x1 = std::clamp(box.x + std::max(box.width, 0), x0, width_);
  const int y1 = std::clamp(box.y + std::max(box.height, 0), y0, height_);
  r.left_ = left_ + x0;
  r.top_ = top_ + y0;
  r.width_ = x1 - x0;
  r.height_ = y1 - y0;
  return r;
}

void Canvas::FillTarget(HposeDrawTarget* t) const {
  const size_t stride = static_cast<size_t>(full_width_) * 3;
  t->bgr = pixels_->data() + top_ * stride + static_cast<size_t>(left_) * 3;
  t->width = width_;
  t->height = height_;
  t->stride = stride;
}

template <typename Draw>
void Canvas::DrawWith(const Bgr& colour, Draw draw) const {
  if (width_ == 0 || height_ == 0) return;
  HposeDrawTarget t;
  FillTarget(&t);
  const double c[3] = {colour.b, colour.g, colour.r};
  draw(&t, c);
}

void Canvas::SetPixel(Px p, std::uint8_t b, std::uint8_t g, std::uint8_t r) {
  if (p.x < 0 || p.y < 0 || p.x >= width_ || p.y >= height_) return;
  std::uint8_t* px =
      pixels_->data() + (static_cast<size_t>(top_ + p.y) * full_width_ + left_ + p.x) * 3;
  px[0] = b;
  px[1] = g;
  px[2] = r;
}

void Canvas::SetPixel(Px p, const Bgr& colour) {
  SetPixel(p, ChannelByte(colour.b), ChannelByte(colour.g), ChannelByte(colour.r));
}

void Canvas::Line(Px a, Px b, const Bgr& colour, int thickness, LineKind kind) {
  DrawWith(colour, [&](const HposeDrawTarget* t, const double* c) {
    api_->line(t, a.x, a.y, b.x, b.y, c, thickness, Kind(kind));
  });
}

void Canvas::Circle(Px centre, int radius, const Bgr& colour, int thickness, LineKind kind) {
  DrawWith(colour, [&](const HposeDrawTarget* t, const double* c) {
    api_->circle(t, centre.x, centre.y, radius, c, thickness, Kind(kind));
  });
}

void Canvas::Rectangle(Px a, Px b, const Bgr& colour, int thickness, LineKind kind) {
  DrawWith(colour, [&](const HposeDrawTarget* t, const double* c) {
    api_->rectangle(t, a.x, a.y, b.x, b.y, c, thickness, Kind(kind));
  });
}

void Canvas::Rectangle(const PxBox& box, const Bgr& colour, int thickness, LineKind kind) {
  if (box.width <= 0 || box.height <= 0) return;
  Rectangle(Px(box.x, box.y), Px(box.x + box.width - 1, box.y + box.height - 1), colour, thickness,
            kind);
}

void Canvas::ArrowedLine(Px from, Px to, const Bgr& colour, int thickness, LineKind kind,
                         double tip_length) {
  DrawWith(colour, [&](const HposeDrawTarget* t, const double* c) {
    api_->arrowed_line(t, from.x, from.y, to.x, to.y, c, thickness, Kind(kind), tip_length);
  });
}

void Canvas::Marker(Px at, const Bgr& colour, MarkerShape shape, int size, int thickness) {
  DrawWith(colour, [&](const HposeDrawTarget* t, const double* c) {
    api_->marker(t, at.x, at.y, c,
                 shape == MarkerShape::kTriangleUp ? kHposeMarkerTriangleUp : kHposeMarkerCross,
                 size, thickness);
  });
}

void Canvas::Text(const std::string& text, Px origin, double scale, const Bgr& colour,
                  int thickness, LineKind kind) {
  DrawWith(colour, [&](const HposeDrawTarget* t, const double* c) {
    api_->text(t, text.c_str(), origin.x, origin.y, scale, c, thickness, Kind(kind));
  });
}

TextBox Canvas::MeasureText(const std::string& text, double scale, int thickness) const {
  TextBox box;
  api_->text_size(text.c_str(), scale, thickness, &box.width, &box.height, &box.baseline);
  return box;
}

DecodedImage Canvas::ToRgb() const {
  DecodedImage rgb;
  rgb.width = full_width_;
  rgb.height = full_height_;
  rgb.channels = 3;
  rgb.bits_per_sample = 8;
  rgb.bytes.resize(pixels_->size());
  for (size_t i = 0; i < pixels_->size(); i += 3) {
    rgb.bytes[i] = (*pixels_)[i + 2];
    rgb.bytes[i + 1] = (*pixels_)[i + 1];
    rgb.bytes[i + 2] = (*pixels_)[i];
  }
  return rgb;
}

Bgr BgrFromHsv(double hue_deg, double saturation, double value) {
  const double h = std::fmod(std::fmod(hue_deg, 360.0) + 360.0, 360.0) / 60.0;
  const double c = value * saturation;
  const double x = c * (1.0 - std::abs(std::fmod(h, 2.0) - 1.0));
  const double m = value - c;
  double r = 0, g = 0, b = 0;
  switch (static_cast<int>(h)) {
    case 0:
      r = c, g = x;
      break;
    case 1:
      r = x, g = c;
      break;
    case 2:
      g = c, b = x;
      break;
    case 3:
      g = x, b = c;
      break;
    case 4:
      r = x, b = c;
      break;
    default:
      r = c, b = x;
      break;
  }
  return {255.0 * (b + m), 255.0 * (g + m), 255.0 * (r + m)};
}

}  // namespace hpose::tools
