// How a depth sensor's errors are laid out across the image, measured on the floor of organised
// clouds: fits the floor, takes the pixels within 5 cm of it as floor, and per band of depth
// prints the rms of their heights above the fitted plane and the structure function D(d), the
// rms of the height difference of two floor pixels d apart in a row. Errors drawn independently
// per pixel give the same D at every d (sqrt(2) times their sigma); errors that neighbouring
// pixels share give a small D(1) that grows with d until the pixels no longer share them.
// Compares a real recording with the simulator (`hpose simulate`, its cloud.pcd), e.g.:
//   depth_noise_bench ../shared/data/kinect/five_people.pcd sim/cloud.pcd
#include <cmath>
#include <cstdio>
#include <iterator>
#include <string>
#include <vector>

#include "core/depth/floor_fitter.h"
#include "core/io/cloud_io.h"

namespace hpose {
namespace {

constexpr int kOffsets[] = {1, 2, 3, 4, 6, 8, 12};
constexpr double kFloorBandM = 0.05;
constexpr double kDepthStepM = 0.5;
constexpr int kMinPairs = 200;

int Run(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help") {
    std::fprintf(argc < 2 ? stderr : stdout,
                 "usage: depth_noise_bench CLOUD.pcd|CLOUD.ply...\n"
                 "Organised clouds (sensor frame) with the floor in view: per 0.5 m of depth, the\n"
                 "floor pixels' rms height above the fitted floor and D(d), the rms height\n"
                 "difference of floor pixels d apart in a row (mm).\n");
    return argc < 2 ? 2 : 0;
  }
  std::printf("| cloud | depth (m) | floor pixels | rms height (mm) |");
  for (const int d : kOffsets) std::printf(" D(%d) |", d);
  std::printf(" D(1) / D(12) |\n|---|---|---|---|");
  for (size_t k = 0; k < std::size(kOffsets); ++k) std::printf("---|");
  std::printf("---|\n");
  for (int a = 1; a < argc; ++a) {
    const std::string path = argv[a];
    Result<PointCloud> cloud = ReadCloud(path);
    if (!cloud.ok()) {
      std::fprintf(stderr, "depth_noise_bench: %s\n", cloud.error().message.c_str());
      return 1;
    }
    if (!cloud->organised()) {
      std::fprintf(stderr, "depth_noise_bench: %s is not organised (no pixel neighbours)\n",
                   path.c_str());
      return 1;
    }
    Result<FloorEstimate> floor = FitFloor(*cloud);
    if (!floor.ok()) {
      std::fprintf(stderr, "depth_noise_bench: %s: %s\n", path.c_str(),
                   floor.error().message.c_str());
      return 1;
    }
    const int w = cloud->width, h = cloud->height;
    const size_t n = cloud->points.size();
    // Height above the fitted floor of each floor pixel (NaN elsewhere), and its depth.
    std::vector<double> height(n, std::nan("")), depth(n, std::nan(""));
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3f& p = cloud->points[i];
      if (!p.allFinite()) continue;
      const double z = (floor->ground_from_sensor * p.cast<double>()).z();
      if (std::abs(z) >= kFloorBandM) continue;
      height[i] = z;
      depth[i] = p.z();
    }
    for (double lo = 0.5; lo < 5.0; lo += kDepthStepM) {
      double sum2 = 0.0;
      int count = 0;
      double d_rms[std::size(kOffsets)] = {};
      bool enough = true;
      for (size_t k = 0; k < std::size(kOffsets); ++k) {
        double s = 0.0;
        int pairs = 0;
        for (int v = 0; v < h; ++v) {
          for (int u = 0; u + kOffsets[k] < w; ++u) {
            const size_t i = static_cast<size_t>(v) * w + u;
            if (!(depth[i] >= lo && depth[i] < lo + kDepthStepM)) continue;
            const double other = height[i + kOffsets[k]];
            if (std::isnan(other)) continue;
            s += (height[i] - other) * (height[i] - other);
            ++pairs;
          }
        }
        enough = enough && pairs >= kMinPairs;
        d_rms[k] = pairs > 0 ? 1e3 * std::sqrt(s / pairs) : 0.0;
      }
      for (size_t i = 0; i < n; ++i) {
        if (!(depth[i] >= lo && depth[i] < lo + kDepthStepM)) continue;
        sum2 += height[i] * height[i];
        ++count;
      }
      if (!enough) continue;
      std::printf("| %s | %.1f-%.1f | %d | %.1f |", path.c_str(), lo, lo + kDepthStepM, count,
                  1e3 * std::sqrt(sum2 / count));
      for (const double d : d_rms) std::printf(" %.1f |", d);
      std::printf(" %.2f |\n", d_rms[0] / d_rms[std::size(kOffsets) - 1]);
    }
  }
  return 0;
}

}  // namespace
}  // namespace hpose

int main(int argc, char** argv) { return hpose::Run(argc, argv); }
