#include "core/depth/intrinsics.h"

#include <cmath>
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

std::string Num(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return std::to_string(value);
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
  return Status::Ok();
}

}  // namespace hpose
