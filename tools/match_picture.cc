#include "tools/match_picture.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

#include <opencv2/imgproc.hpp>

#include "tools/fixed_text.h"
#include "tools/picture_png.h"

namespace hpose::tools {
namespace {

constexpr int kPanel = 640;

// Maps ground-frame metres (a, b) to pixels of a square panel showing [a0, a0+span] x
// [b0, b0+span]; `a` grows upwards, `b` grows to the left (so +y is left, as seen from above
// with +x up).
struct View {
  double a0, b0, span;
  int x0;  // panel's left edge in the image.
  cv::Point Px(double a, double b) const {
    const double s = kPanel / span;
    return cv::Point(x0 + static_cast<int>(kPanel - (b - b0) * s),
                     static_cast<int>(kPanel - (a - a0) * s));
  }
};

cv::Scalar HeightColour(double z) {
  const double t = std::clamp(z / 1.0, 0.0, 1.0);
  return cv::Scalar(90 + 120 * (1 - t), 90 + 120 * t, 90);  // BGR: blue-ish low, green high.
}

std::vector<Eigen::Vector3f> PlacedVoxels(const VoxelTemplate& t, const Pose2D& pose) {
  const Eigen::Isometry3d g = pose.ToIsometry();
  std::vector<Eigen::Vector3f> out;
  out.reserve(t.voxels.size());
  for (const Eigen::Vector3f& v : t.voxels) out.push_back((g * v.cast<double>()).cast<float>());
  return out;
}

}  // namespace

Status WriteMatchPicture(const Estimate& estimate, const std::vector<VoxelTemplate>& templates,
                         const PointCloud& cloud_sensor, const std::string& path) {
  cv::Mat img(kPanel, 2 * kPanel, CV_8UC3, cv::Scalar(30, 30, 30));
  std::vector<Eigen::Vector3f> ground;
  ground.reserve(cloud_sensor.size() / 2);
  const Eigen::Isometry3f gs = estimate.floor.ground_from_sensor.cast<float>();
  for (const Eigen::Vector3f& p : cloud_sensor.points) {
    if (!p.allFinite()) continue;
    const Eigen::Vector3f g = gs * p;
    if (g.z() > 0.02f && g.z() < 2.5f) ground.push_back(g);
  }

  cv::Mat left = img(cv::Rect(0, 0, kPanel, kPanel));  // clips the overview to its panel.
  // Overview: from the sensor to the farthest cluster (at least 2 m), centred on y = 0.
  double far = 2.0;
  for (const ClusterSummary& c : estimate.clusters) far = std::max(far, c.max.x() + 0.3);
  far = std::min(far, 6.0);
  const View over{-0.2, -(far + 0.2) / 2, far + 0.2, 0};
  for (double r = 1.0; r < far + 0.2; r += 1.0) {
    cv::circle(left, over.Px(0, 0), static_cast<int>(r * kPanel / over.span),
               cv::Scalar(55, 55, 55), 1, cv::LINE_AA);
    cv::putText(left, FormatNumber("%.0f m", r), over.Px(r, 0) + cv::Point(3, -3),
                cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(110, 110, 110), 1, cv::LINE_AA);
  }
  for (const Eigen::Vector3f& g : ground) {
    const cv::Point p = over.Px(g.x(), g.y());
    if (p.x >= 0 && p.x < kPanel && p.y >= 0 && p.y < kPanel) {
      left.at<cv::Vec3b>(p) = cv::Vec3b(cv::saturate_cast<uchar>(HeightColour(g.z())[0]),
                                        cv::saturate_cast<uchar>(HeightColour(g.z())[1]),
                                        cv::saturate_cast<uchar>(HeightColour(g.z())[2]));
    }
  }
  cv::drawMarker(left, over.Px(0, 0), cv::Scalar(255, 255, 255), cv::MARKER_TRIANGLE_UP, 14, 2);
  cv::putText(left, "sensor", over.Px(0, 0) + cv::Point(10, -4), cv::FONT_HERSHEY_SIMPLEX, 0.45,
              cv::Scalar(230, 230, 230), 1, cv::LINE_AA);
  for (const ClusterSummary& c : estimate.clusters) {
    cv::rectangle(left, over.Px(c.min.x(), c.min.y()), over.Px(c.max.x(), c.max.y()),
                  c.searched ? cv::Scalar(200, 200, 200) : cv::Scalar(90, 90, 90), 1);
    cv::putText(left, std::to_string(c.index), over.Px(c.max.x(), c.max.y()) + cv::Point(2, -2),
                cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(200, 200, 200), 1, cv::LINE_AA);
  }
  const std::vector<Detection> humans = estimate.Humanoids();
  auto find_template = [&](const std::string& name) -> const VoxelTemplate* {
    for (const VoxelTemplate& t : templates) {
      if (t.name == name) return &t;
    }
    return nullptr;
  };
  for (const Detection& d : humans) {
    const VoxelTemplate* t = find_template(d.best.template_name);
    if (t == nullptr) continue;
    for (const Eigen::Vector3f& v : PlacedVoxels(*t, d.best.pose)) {
      cv::circle(left, over.Px(v.x(), v.y()), 1, cv::Scalar(60, 60, 230), -1);
    }
    const Pose2D& p = d.best.pose;
    cv::arrowedLine(left, over.Px(p.x, p.y),
                    over.Px(p.x + 0.35 * std::cos(p.theta), p.y + 0.35 * std::sin(p.theta)),
                    cv::Scalar(80, 80, 255), 2, cv::LINE_AA, 0, 0.25);
  }
  cv::putText(left, "top view (ground frame, x up, y left)", cv::Point(10, 20),
              cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(230, 230, 230), 1, cv::LINE_AA);

  // Close-ups of the best humanoid (or a note that there is none).
  const int x1 = kPanel;
  cv::line(img, cv::Point(x1, 0), cv::Point(x1, kPanel), cv::Scalar(90, 90, 90), 1);
  if (humans.empty()) {
    cv::putText(img, "no humanoid above the score threshold", cv::Point(x1 + 20, kPanel / 2),
                cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(120, 120, 255), 1, cv::LINE_AA);
  } else {
    const Detection& d = humans.front();
    const VoxelTemplate* t = find_template(d.best.template_name);
    const ClusterSummary* cluster = nullptr;
    for (const ClusterSummary& c : estimate.clusters) {
      if (c.index == d.best.cluster_index) cluster = &c;
    }
    const double res = t != nullptr ? t->resolution_m : 0.016;
    using Cell = std::tuple<int, int, int>;
    std::set<Cell> cluster_cells, template_cells;
    if (cluster != nullptr) {
      for (const Eigen::Vector3f& g : ground) {
        if ((g.array() >= cluster->min.array() - 0.01f).all() &&
            (g.array() <= cluster->max.array() + 0.01f).all()) {
          cluster_cells.insert({static_cast<int>(std::floor(g.x() / res)),
                                static_cast<int>(std::floor(g.y() / res)),
                                static_cast<int>(std::floor(g.z() / res))});
        }
      }
    }
    if (t != nullptr) {
      for (const Eigen::Vector3f& v : PlacedVoxels(*t, d.best.pose)) {
        template_cells.insert({static_cast<int>(std::floor(v.x() / res)),
                               static_cast<int>(std::floor(v.y() / res)),
                               static_cast<int>(std::floor(v.z() / res))});
      }
    }
    const int half = kPanel / 2;
    const double span = 0.9;  // metres shown in each close-up.
    const double s = half / span;
    // Top close-up in the upper half, side close-up (y horizontal, z up) in the lower half.
    auto draw_cell = [&](const Cell& c, const cv::Scalar& colour, bool top) {
      const double cx = (std::get<0>(c) + 0.5) * res, cy = (std::get<1>(c) + 0.5) * res,
                   cz = (std::get<2>(c) + 0.5) * res;
      cv::Point p;
      if (top) {
        p = cv::Point(x1 + half - static_cast<int>((cy - d.best.pose.y) * s),
                      half / 2 + 20 - static_cast<int>((cx - d.best.pose.x) * s));
      } else {
        p = cv::Point(x1 + half - static_cast<int>((cy - d.best.pose.y) * s),
                      kPanel - 15 - static_cast<int>(cz * s * 0.85));
      }
      const int r = std::max(1, static_cast<int>(res * s * 0.45));
      cv::rectangle(img, p - cv::Point(r, r), p + cv::Point(r, r), colour, -1);
    };
    for (bool top : {true, false}) {
      for (const Cell& c : template_cells) draw_cell(c, cv::Scalar(50, 50, 200), top);
      for (const Cell& c : cluster_cells) {
        draw_cell(c, template_cells.count(c) ? cv::Scalar(220, 60, 220) : cv::Scalar(220, 130, 40),
                  top);
      }
    }
    const Pose2D& p = d.best.pose;
    cv::putText(img,
                d.best.template_name + "  x " + FormatNumber("%.3f", p.x) + " m  y " +
                    FormatNumber("%.3f", p.y) + " m  theta " +
                    FormatNumber("%.1f", RadToDeg(p.theta)) + " deg  score " +
                    FormatNumber("%.1f", d.best.score),
                cv::Point(x1 + 10, 20), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(230, 230, 230), 1,
                cv::LINE_AA);
    cv::putText(img, "close-up from above", cv::Point(x1 + 10, 42), cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(170, 170, 170), 1, cv::LINE_AA);
    cv::putText(img, "seen from the sensor (y-z)", cv::Point(x1 + 10, half + 12),
                cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(170, 170, 170), 1, cv::LINE_AA);
    cv::putText(img, "blue: cluster  red: template  magenta: both", cv::Point(x1 + 10, kPanel - 2),
                cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(200, 200, 200), 1, cv::LINE_AA);
  }
  return WritePicturePng(img, path);
}

}  // namespace hpose::tools
