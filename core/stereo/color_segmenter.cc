#include "core/stereo/color_segmenter.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace hpose {
namespace {

constexpr int kBits = 6;
constexpr int kLevels = 1 << kBits;
constexpr int kShift = 8 - kBits;

inline int TableIndex(std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  return ((r >> kShift) << (2 * kBits)) | ((g >> kShift) << kBits) | (b >> kShift);
}

// Coverage-weighted centroid of blob `label` (see ColorSegmenterOptions::subpixel_centroids).
Eigen::Vector2d RefineCentroid(const RgbImage& image, const cv::Mat& classes, const cv::Mat& labels,
                               const cv::Rect& roi, int label, const ColorBlob& blob) {
  const int w = image.width, h = image.height;
  auto in_blob = [&](int x, int y) {
    const int lx = x - roi.x, ly = y - roi.y;
    return lx >= 0 && ly >= 0 && lx < roi.width && ly < roi.height &&
           labels.at<int>(ly, lx) == label;
  };
  auto ring = [&](int x, int y) {  // unclassified pixel touching the blob.
    if (classes.at<std::uint8_t>(y, x) != 0) return false;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (in_blob(x + dx, y + dy)) return true;
    return false;
  };
  const int x0 = std::max(0, blob.min_x - 2), x1 = std::min(w - 1, blob.max_x + 2);
  const int y0 = std::max(0, blob.min_y - 2), y1 = std::min(h - 1, blob.max_y + 2);
  Eigen::Vector3d fg = Eigen::Vector3d::Zero(), bg = Eigen::Vector3d::Zero();
  int nf = 0, nb = 0;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const std::uint8_t* p = image.at(x, y);
      const Eigen::Vector3d c(p[0], p[1], p[2]);
      if (in_blob(x, y)) {
        if (in_blob(x - 1, y) && in_blob(x + 1, y) && in_blob(x, y - 1) && in_blob(x, y + 1)) {
          fg += c;
          ++nf;
        }
      } else if (classes.at<std::uint8_t>(y, x) == 0 && !ring(x, y)) {
        bg += c;
        ++nb;
      }
    }
  }
  if (nf == 0 || nb == 0) return blob.centroid_px;
  fg /= nf;
  bg /= nb;
  const Eigen::Vector3d d = fg - bg;
  const double d2 = d.squaredNorm();
  if (d2 < 400.0) return blob.centroid_px;  // too little contrast to weigh by colour.
  double sw = 0, sx = 0, sy = 0;
  for (int y = std::max(0, y0 + 1); y <= std::min(h - 1, y1 - 1); ++y) {
    for (int x = std::max(0, x0 + 1); x <= std::min(w - 1, x1 - 1); ++x) {
      if (!in_blob(x, y) && !ring(x, y)) continue;
      const std::uint8_t* p = image.at(x, y);
      const double cov = std::clamp((Eigen::Vector3d(p[0], p[1], p[2]) - bg).dot(d) / d2, 0.0, 1.0);
      sw += cov;
      sx += cov * x;
      sy += cov * y;
    }
  }
  if (sw <= 0) return blob.centroid_px;
  return Eigen::Vector2d(sx / sw, sy / sw);
}

}  // namespace

bool HsvRange::Contains(double hue_deg, double sat, double val) const {
  const bool hue_ok = hue_min_deg <= hue_max_deg
                          ? (hue_deg >= hue_min_deg && hue_deg <= hue_max_deg)
                          : (hue_deg >= hue_min_deg || hue_deg <= hue_max_deg);
  return hue_ok && sat >= sat_min && sat <= sat_max && val >= val_min && val <= val_max;
}

Status ValidateHsvRange(const HsvRange& r, const std::string& what) {
  const double values[] = {r.hue_min_deg, r.hue_max_deg, r.sat_min,
                           r.sat_max,     r.val_min,     r.val_max};
  for (double v : values) {
    if (!std::isfinite(v)) {
      return MakeError(ErrorCode::kInvalidArgument,
                       what + ": colour range holds a non-finite bound");
    }
  }
  if (r.hue_min_deg < 0 || r.hue_min_deg > 360 || r.hue_max_deg < 0 || r.hue_max_deg > 360) {
    return MakeError(ErrorCode::kInvalidArgument, what + ": hue bounds must lie in [0, 360] deg");
  }
  if (r.sat_min < 0 || r.sat_max > 1 || r.sat_min > r.sat_max || r.val_min < 0 || r.val_max > 1 ||
      r.val_min > r.val_max) {
    return MakeError(ErrorCode::kInvalidArgument,
                     what + ": saturation and value bounds must satisfy 0 <= min <= max <= 1");
  }
  return Status::Ok();
}

Result<ColorSegmenter> ColorSegmenter::Create(const std::vector<HsvRange>& classes,
                                              const ColorSegmenterOptions& options) {
  if (classes.empty() || classes.size() > 254) {
    return MakeError(ErrorCode::kInvalidArgument, "colour segmenter needs 1 to 254 classes");
  }
  for (size_t i = 0; i < classes.size(); ++i) {
    Status s = ValidateHsvRange(classes[i], "colour class " + std::to_string(i));
    if (!s.ok()) return s.error();
  }
  if (options.min_blob_area_px < 1) {
    return MakeError(ErrorCode::kInvalidArgument, "min_blob_area_px must be at least 1");
  }
  if (options.connectivity != 4 && options.connectivity != 8) {
    return MakeError(ErrorCode::kInvalidArgument, "connectivity must be 4 or 8");
  }
  ColorSegmenter seg;
  seg.options_ = options;
  seg.num_classes_ = static_cast<int>(classes.size());
  // Every quantised colour (bin centre) converted to HSV by OpenCV in one call.
  const int n = kLevels * kLevels * kLevels;
  cv::Mat rgb(1, n, CV_32FC3);
  auto* p = rgb.ptr<cv::Vec3f>(0);
  for (int i = 0; i < n; ++i) {
    const int r = i >> (2 * kBits), g = (i >> kBits) & (kLevels - 1), b = i & (kLevels - 1);
    const float half = static_cast<float>(1 << (kShift - 1));
    p[i] = cv::Vec3f((static_cast<float>(r << kShift) + half) / 255.f,
                     (static_cast<float>(g << kShift) + half) / 255.f,
                     (static_cast<float>(b << kShift) + half) / 255.f);
  }
  cv::Mat hsv;
  cv::cvtColor(rgb, hsv, cv::COLOR_RGB2HSV);  // float: H in degrees, S and V in [0, 1].
  seg.table_.assign(n, 0);
  const auto* h = hsv.ptr<cv::Vec3f>(0);
  for (int i = 0; i < n; ++i) {
    for (size_t c = 0; c < classes.size(); ++c) {
      if (classes[c].Contains(h[i][0], h[i][1], h[i][2])) {
        seg.table_[i] = static_cast<std::uint8_t>(c + 1);
        break;
      }
    }
  }
  return seg;
}

int ColorSegmenter::Classify(std::uint8_t r, std::uint8_t g, std::uint8_t b) const {
  return static_cast<int>(table_[TableIndex(r, g, b)]) - 1;
}

std::vector<std::vector<ColorBlob>> ColorSegmenter::Segment(const RgbImage& image) const {
  assert(image.valid());
  const int w = image.width, h = image.height;
  std::vector<std::vector<ColorBlob>> blobs(num_classes_);
  cv::Mat classes(h, w, CV_8UC1);
  struct Box {
    int min_x = std::numeric_limits<int>::max(), min_y = std::numeric_limits<int>::max();
    int max_x = -1, max_y = -1;
  };
  std::vector<Box> boxes(num_classes_);
  const std::uint8_t* table = table_.data();
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* src = image.at(0, y);
    std::uint8_t* dst = classes.ptr<std::uint8_t>(y);
    for (int x = 0; x < w; ++x, src += 3) {
      const std::uint8_t c = table[TableIndex(src[0], src[1], src[2])];
      dst[x] = c;
      if (c != 0) {
        Box& b = boxes[c - 1];
        if (x < b.min_x) b.min_x = x;
        if (x > b.max_x) b.max_x = x;
        if (y < b.min_y) b.min_y = y;
        b.max_y = y;
      }
    }
  }
  cv::Mat mask, labels, stats, centroids;
  for (int c = 0; c < num_classes_; ++c) {
    const Box& b = boxes[c];
    if (b.max_x < 0) continue;
    const cv::Rect roi(b.min_x, b.min_y, b.max_x - b.min_x + 1, b.max_y - b.min_y + 1);
    cv::compare(classes(roi), cv::Scalar(c + 1), mask, cv::CMP_EQ);
    const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids,
                                                   options_.connectivity, CV_32S);
    for (int i = 1; i < n; ++i) {
      const int area = stats.at<int>(i, cv::CC_STAT_AREA);
      if (area < options_.min_blob_area_px) continue;
      ColorBlob blob;
      blob.area_px = area;
      blob.centroid_px =
          Eigen::Vector2d(centroids.at<double>(i, 0) + roi.x, centroids.at<double>(i, 1) + roi.y);
      blob.min_x = stats.at<int>(i, cv::CC_STAT_LEFT) + roi.x;
      blob.min_y = stats.at<int>(i, cv::CC_STAT_TOP) + roi.y;
      blob.max_x = blob.min_x + stats.at<int>(i, cv::CC_STAT_WIDTH) - 1;
      blob.max_y = blob.min_y + stats.at<int>(i, cv::CC_STAT_HEIGHT) - 1;
      blob.mask_centroid_px = blob.centroid_px;
      if (options_.subpixel_centroids) {
        blob.centroid_px = RefineCentroid(image, classes, labels, roi, i, blob);
      }
      blobs[c].push_back(blob);
    }
    std::sort(blobs[c].begin(), blobs[c].end(),
              [](const ColorBlob& a, const ColorBlob& b) { return a.area_px > b.area_px; });
  }
  return blobs;
}

}  // namespace hpose
