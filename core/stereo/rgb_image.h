#ifndef HPOSE_CORE_STEREO_RGB_IMAGE_H_
#define HPOSE_CORE_STEREO_RGB_IMAGE_H_

#include <cstdint>
#include <vector>

namespace hpose {

// An 8-bit colour image, rows top to bottom, pixels left to right, 3 bytes per pixel in the
// order R, G, B. Kept free of OpenCV so that headers stay light; core/stereo wraps it without
// copying where it needs OpenCV.
struct RgbImage {
  int width = 0;                     // pixels.
  int height = 0;                    // pixels.
  std::vector<std::uint8_t> pixels;  // size width * height * 3.

  RgbImage() = default;
  RgbImage(int w, int h) : width(w), height(h), pixels(static_cast<size_t>(w) * h * 3, 0) {}

  bool empty() const { return width <= 0 || height <= 0; }
  // True when the buffer size matches width and height.
  bool valid() const {
    return width > 0 && height > 0 && pixels.size() == static_cast<size_t>(width) * height * 3;
  }
  std::uint8_t* at(int x, int y) { return &pixels[(static_cast<size_t>(y) * width + x) * 3]; }
  const std::uint8_t* at(int x, int y) const {
    return &pixels[(static_cast<size_t>(y) * width + x) * 3];
  }
};

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_RGB_IMAGE_H_
