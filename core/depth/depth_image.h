#ifndef HPOSE_CORE_DEPTH_DEPTH_IMAGE_H_
#define HPOSE_CORE_DEPTH_DEPTH_IMAGE_H_

#include <cstdint>
#include <vector>

namespace hpose {

// A depth image in millimetres along the optical axis (z), row-major; 0 = no reading.
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> mm;  // width * height values.

  DepthImage() = default;
  DepthImage(int w, int h) : width(w), height(h), mm(static_cast<size_t>(w) * h, 0) {}

  std::uint16_t at(int u, int v) const { return mm[static_cast<size_t>(v) * width + u]; }
  std::uint16_t& at(int u, int v) { return mm[static_cast<size_t>(v) * width + u]; }
};

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_DEPTH_IMAGE_H_
