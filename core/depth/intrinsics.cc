#include "core/depth/intrinsics.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

namespace hpose {
namespace {

// Native Kinect v1 depth resolution and its published pinhole parameters (SPEC §5).
constexpr int kNativeWidth = 640;
constexpr int kNativeHeight = 480;
constexpr double kNativeFx = 594.2;
constexpr double kNativeFy = 591.0;
constexpr double kNativeCx = 339.3;
constexpr double kNativeCy = 242.7;

constexpr int kMaxSide = 8192;
// A ray at most 84 degrees off the optical axis (tan = 10): any real lens, fish-eyes aside.
constexpr double kMaxRaySlope = 10.0;
constexpr double kMaxFocalPx = 1e6;

std::string Num(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  std::ostringstream out;  // 594.2, 1e+308: not to_string's fixed six decimals.
  out.precision(10);
  out << value;
  return out.str();
}

// Range checks of one image axis ("x": width, fx, cx). The principal point may lie outside the
// image, as a window cropped from a larger image has it (a corner window of a 640x480 frame
// puts it hundreds of pixels away), but no farther than the largest image's side; the focal
// length must keep every pixel's ray within kMaxRaySlope of the optical axis (and below
// kMaxFocalPx): beyond that the back-projected points are not a camera's and their
// coordinates can overflow downstream.
Status CheckAxis(const char* axis, int size, double f, double c) {
  const std::string fname = std::string("f") + axis, cname = std::string("c") + axis;
  if (c < -kMaxSide || c > size + kMaxSide) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "intrinsics: " + cname + " " + Num(c) + " is outside [-" +
                         std::to_string(kMaxSide) + ", " + std::to_string(size + kMaxSide) +
                         "] (the principal point must lie within " + std::to_string(kMaxSide) +
                         " px of the image)");
  }
  const double widest = std::max(std::abs(c), std::abs(size - 1 - c));
  if (f > kMaxFocalPx || widest > kMaxRaySlope * f) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "intrinsics: " + fname + " " + Num(f) + " is outside [" +
                         Num(widest / kMaxRaySlope) + ", " + Num(kMaxFocalPx) +
                         "] px (field of view between nothing and wider than 168 degrees)");
  }
  return Status::Ok();
}

}  // namespace

Intrinsics Intrinsics::KinectV1(int width, int height) {
  Intrinsics k;
  k.width = width;
  k.height = height;
  const double sx = static_cast<double>(width) / kNativeWidth;
  const double sy = static_cast<double>(height) / kNativeHeight;
  k.fx = kNativeFx * sx;
  k.fy = kNativeFy * sy;
  k.cx = kNativeCx * sx;
  k.cy = kNativeCy * sy;
  return k;
}

Status Intrinsics::Validate() const {
  if (width <= 0 || width > kMaxSide) {
    return MakeError(ErrorCode::kInvalidArgument, "intrinsics: width " + std::to_string(width) +
                                                      " is outside [1, " +
                                                      std::to_string(kMaxSide) + "]");
  }
  if (height <= 0 || height > kMaxSide) {
    return MakeError(ErrorCode::kInvalidArgument, "intrinsics: height " + std::to_string(height) +
                                                      " is outside [1, " +
                                                      std::to_string(kMaxSide) + "]");
  }
  if (!std::isfinite(fx) || fx <= 0.0) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "intrinsics: fx " + Num(fx) + " must be finite and positive");
  }
  if (!std::isfinite(fy) || fy <= 0.0) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "intrinsics: fy " + Num(fy) + " must be finite and positive");
  }
  if (!std::isfinite(cx)) {
    return MakeError(ErrorCode::kInvalidArgument, "intrinsics: cx " + Num(cx) + " is not finite");
  }
  if (!std::isfinite(cy)) {
    return MakeError(ErrorCode::kInvalidArgument, "intrinsics: cy " + Num(cy) + " is not finite");
  }
  Status st = CheckAxis("x", width, fx, cx);
  if (!st.ok()) return st;
  return CheckAxis("y", height, fy, cy);
}

}  // namespace hpose
