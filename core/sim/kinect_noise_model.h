#ifndef HPOSE_CORE_SIM_KINECT_NOISE_MODEL_H_
#define HPOSE_CORE_SIM_KINECT_NOISE_MODEL_H_

#include <cstdint>
#include <vector>

#include "core/common/status.h"

namespace hpose {

// The Kinect v1 depth error model of SPEC section 5. Units: metres, radians, pixels.
struct KinectNoiseOptions {
  // false: no random noise and no quantisation; the range and incidence limits still apply.
  bool noise_enabled = true;
  double axial_sigma_per_m = 1.425e-3;  // sigma_z = axial_sigma_per_m * z^2 (Khoshelham 2012).
  double lateral_sigma_px = 0.8;        // std of the sampling ray's jitter, each image axis.
  bool quantise_disparity = true;       // snap depth to the 11-bit disparity grid.
  double min_range_m = 0.8;             // nearer readings are dropped (0).
  double max_range_m = 4.0;             // farther readings are dropped (0).
  double max_incidence_rad = 1.3963;    // 80 degrees: steeper (grazing) surfaces give no reading.
  // Share of the axial error's and the ray jitter's variance that is spatially correlated: that
  // part is the mean of independent normals over the (2 correlation_radius_px + 1)^2 pixels
  // around each pixel, scaled back to the same variance, so neighbouring pixels err alike. 0:
  // every pixel independent (before). A real Kinect v1 computes each disparity by matching a
  // window of pixels, so its errors are correlated: on PCL's five-people frame the rms height
  // difference of floor pixels next to each other is 0.40-0.50 of that of pixels 12 apart,
  // where independent errors give 1, and 0.9 with a radius of 4 gives 0.57-0.60
  // (docs/BENCHMARKS.md, "High and steep mounts, and a real Kinect's errors against the
  // simulator's").
  double correlated_share = 0.0;
  int correlation_radius_px = 4;

  // Names the offending field when a value is negative, non-finite or inconsistent.
  Status Validate() const;
};

// Turns ideal depth into a Kinect v1 reading. The random draws are a pure function of
// (seed, pixel index), so a seed reproduces a frame exactly, in any rendering order.
class KinectNoiseModel final {
 public:
  // Disparity conversion (raw is the sensor's 11-bit value, 2047 = no reading).
  static constexpr double kRawScale = -0.0030711016;
  static constexpr double kRawOffset = 3.3309495161;
  static constexpr int kMaxValidRaw = 1084;  // the largest raw value with a positive depth.

  // Fails (kInvalidArgument) when the options do not validate.
  static Result<KinectNoiseModel> Create(const KinectNoiseOptions& options);

  const KinectNoiseOptions& options() const { return options_; }

  // The random numbers of one pixel: ray jitter in pixels and a standard normal for the
  // axial error. All zero when noise is disabled.
  struct PixelDraw {
    double du_px = 0.0;
    double dv_px = 0.0;
    double axial_normal = 0.0;
  };
  PixelDraw Draw(std::uint64_t seed, std::uint64_t pixel_index) const;

  // The draws of a width x height image, row by row: Draw's for each pixel when
  // correlated_share is 0, else mixed with correlated fields: sqrt(1 - share) Draw's +
  // sqrt(share) field, a field being the window mean of other independent normals per pixel
  // (windows cut by the image's border average fewer pixels), scaled back to the draw's
  // variance; the ray jitter and the axial error alike. A pure function of (seed, options,
  // size). All zero when noise is disabled.
  std::vector<PixelDraw> Draws(std::uint64_t seed, int width, int height) const;

  // The reading in millimetres (0 = none) for a surface at ideal depth z_m (along the optical
  // axis) seen at `incidence_rad` from its normal: adds axial_normal * sigma(z), quantises to
  // the disparity grid, then drops readings outside the range or at grazing incidence.
  std::uint16_t Measure(double z_m, double incidence_rad, double axial_normal) const;

  // sigma_z in metres at depth z_m.
  double AxialSigma(double z_m) const { return options_.axial_sigma_per_m * z_m * z_m; }

  // Nearest raw disparity of a depth, clamped to [0, kMaxValidRaw]; z_m must be positive.
  static int RawFromDepth(double z_m);
  // Depth in metres of a raw disparity in [0, kMaxValidRaw]; 0 for any other value.
  static double DepthFromRaw(int raw);

 private:
  explicit KinectNoiseModel(const KinectNoiseOptions& options) : options_(options) {}

  KinectNoiseOptions options_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SIM_KINECT_NOISE_MODEL_H_
