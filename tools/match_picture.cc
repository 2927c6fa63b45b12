#include "tools/match_picture.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

#include "core/search/estimator.h"
#include "tools/canvas.h"
#include "tools/estimate_report.h"
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
  Px At(double a, double b) const {
    const double s = kPanel / span;
    return Px(x0 + static_cast<int>(kPanel - (b - b0) * s),
              static_cast<int>(kPanel - (a - a0) * s));
  }
};

Bgr HeightColour(double z) {
  const double t = std::clamp(z / 1.0, 0.0, 1.0);
  return Bgr(90 + 120 * (1 - t), 90 + 120 * t, 90);  // BGR: blue-ish low, green high.
}

// Template-frame points where the candidate placed its template (at its pose, as high as it
// stood).
std::vector<Eigen::Vector3f> Placed(const std::vector<Eigen::Vector3f>& points,
                                    const Candidate& c) {
  Eigen::Isometry3d g = c.pose.ToIsometry();
  g.pretranslate(Eigen::Vector3d(0.0, 0.0, c.height_offset_m));
  std::vector<Eigen::Vector3f> out;
  out.reserve(points.size());
  for (const Eigen::Vector3f& v : points) out.push_back((g * v.cast<double>()).cast<float>());
  return out;
}

std::vector<Eigen::Vector3f> PlacedVoxels(const VoxelTemplate& t, const Candidate& c) {
  return Placed(t.voxels, c);
}

// `text` broken at spaces into lines of at most `width` characters (a longer word stays whole).
std::vector<std::string> WrapWords(const std::string& text, size_t width) {
  std::vector<std::string> lines;
  std::string line;
  size_t at = 0;
  while (at < text.size()) {
    size_t end = text.find(' ', at);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(at, end - at);
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      lines.push_back(line);
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
    at = end + 1;
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

// Metres shown across each close-up: the template whole, its height within the side view's
// half of the panel, never less than half a metre (0.9 m without a template).
double CloseUpSpan(const VoxelTemplate* t) {
  if (t == nullptr || t->voxels.empty()) return 0.9;
  float top = 0.0f, reach = 0.0f;
  for (const Eigen::Vector3f& v : t->voxels) {
    top = std::max(top, v.z());
    reach = std::max(reach, v.head<2>().norm());
  }
  const double height = top + t->resolution_m, width = 2.0 * reach + t->resolution_m;
  return std::max({0.5, 1.05 * height, 1.3 * width});
}

}  // namespace

Status WriteMatchPicture(const Estimate& estimate, const std::vector<VoxelTemplate>& templates,
                         const PointCloud& cloud_sensor, const std::string& path,
                         const EstimatorOptions* options) {
  Result<Canvas> made = Canvas::Create(2 * kPanel, kPanel, Bgr(30, 30, 30));
  if (!made.ok()) return made.error();
  Canvas& img = *made;
  std::vector<Eigen::Vector3f> ground;
  ground.reserve(cloud_sensor.size() / 2);
  const Eigen::Isometry3f gs = estimate.floor.ground_from_sensor.cast<float>();
  for (const Eigen::Vector3f& p : cloud_sensor.points) {
    if (!p.allFinite()) continue;
    const Eigen::Vector3f g = gs * p;
    if (g.z() > 0.02f && g.z() < 2.5f) ground.push_back(g);
  }

  Canvas left = img.Region({0, 0, kPanel, kPanel});  // clips the overview to its panel.
  // Overview: from the sensor to the farthest cluster (at least 2 m), centred on y = 0.
  double far = 2.0;
  for (const ClusterSummary& c : estimate.clusters) far = std::max(far, c.max.x() + 0.3);
  far = std::min(far, 6.0);
  const View over{-0.2, -(far + 0.2) / 2, far + 0.2, 0};
  for (double r = 1.0; r < far + 0.2; r += 1.0) {
    left.Circle(over.At(0, 0), static_cast<int>(r * kPanel / over.span), Bgr(55, 55, 55), 1,
                LineKind::kSmooth);
    left.Text(FormatNumber("%.0f m", r), over.At(r, 0) + Px(3, -3), 0.4, Bgr(110, 110, 110), 1,
              LineKind::kSmooth);
  }
  for (const Eigen::Vector3f& g : ground) {
    const Px p = over.At(g.x(), g.y());
    if (p.x >= 0 && p.x < kPanel && p.y >= 0 && p.y < kPanel) {
      left.SetPixel(p, HeightColour(g.z()));
    }
  }
  left.Marker(over.At(0, 0), Bgr(255, 255, 255), MarkerShape::kTriangleUp, 14, 2);
  left.Text("sensor", over.At(0, 0) + Px(10, -4), 0.45, Bgr(230, 230, 230), 1, LineKind::kSmooth);
  for (const ClusterSummary& c : estimate.clusters) {
    left.Rectangle(over.At(c.min.x(), c.min.y()), over.At(c.max.x(), c.max.y()),
                   c.searched ? Bgr(200, 200, 200) : Bgr(90, 90, 90), 1);
    left.Text(std::to_string(c.index), over.At(c.max.x(), c.max.y()) + Px(2, -2), 0.4,
              Bgr(200, 200, 200), 1, LineKind::kSmooth);
  }
  const HumanoidView humans = estimate.Humanoids();
  auto find_template = [&](const std::string& name) -> const VoxelTemplate* {
    for (const VoxelTemplate& t : templates) {
      if (t.name == name) return &t;
    }
    return nullptr;
  };
  for (const Detection& d : humans) {
    const VoxelTemplate* t = find_template(d.best.template_name);
    if (t == nullptr) continue;
    for (const Eigen::Vector3f& v : PlacedVoxels(*t, d.best)) {
      left.Circle(over.At(v.x(), v.y()), 1, Bgr(60, 60, 230), -1);
    }
    const Pose2D& p = d.best.pose;
    left.ArrowedLine(over.At(p.x, p.y),
                     over.At(p.x + 0.35 * std::cos(p.theta), p.y + 0.35 * std::sin(p.theta)),
                     Bgr(80, 80, 255), 2, LineKind::kSmooth, 0.25);
  }
  // Without a humanoid, the nearest miss (the detection the report names) in grey.
  const Detection* miss =
      humans.empty() && !estimate.detections.empty() ? &estimate.detections.front() : nullptr;
  if (miss != nullptr) {
    if (const VoxelTemplate* t = find_template(miss->best.template_name)) {
      for (const Eigen::Vector3f& v : PlacedVoxels(*t, miss->best)) {
        left.Circle(over.At(v.x(), v.y()), 1, Bgr(150, 150, 150), -1);
      }
    }
    const Pose2D& p = miss->best.pose;
    left.ArrowedLine(over.At(p.x, p.y),
                     over.At(p.x + 0.35 * std::cos(p.theta), p.y + 0.35 * std::sin(p.theta)),
                     Bgr(170, 170, 170), 2, LineKind::kSmooth, 0.25);
  }
  left.Text("top view (ground frame, x up, y left)", Px(10, 20), 0.5, Bgr(230, 230, 230), 1,
            LineKind::kSmooth);

  // Close-ups of the best humanoid, else of the nearest miss with why it was refused, else a
  // note that nothing was searched.
  const int x1 = kPanel;
  img.Line(Px(x1, 0), Px(x1, kPanel), Bgr(90, 90, 90), 1);
  if (humans.empty() && miss == nullptr) {
    int searched = 0;
    for (const ClusterSummary& c : estimate.clusters) searched += c.searched;
    const std::string note = estimate.clusters.empty()
                                 ? "no humanoid: nothing stands on the floor"
                                 : "no humanoid: " + std::to_string(estimate.clusters.size()) +
                                       (estimate.clusters.size() == 1 ? " cluster" : " clusters") +
                                       " on the floor, none of a template's size";
    img.Text(searched == 0 ? note : "no humanoid", Px(x1 + 20, kPanel / 2), 0.6, Bgr(120, 120, 255),
             1, LineKind::kSmooth);
  } else {
    const Detection& d = miss != nullptr ? *miss : humans.front();
    const VoxelTemplate* t = find_template(d.best.template_name);
    const ClusterSummary* cluster = nullptr;
    for (const ClusterSummary& c : estimate.clusters) {
      if (c.index == d.best.cluster_index) cluster = &c;
    }
    const double res = t != nullptr ? t->resolution_m : 0.016;
    using Cell = std::tuple<int, int, int>;
    std::set<Cell> cluster_cells, template_cells, limb_cells;
    const auto cell_of = [res](const Eigen::Vector3f& v) {
      return Cell{static_cast<int>(std::floor(v.x() / res)),
                  static_cast<int>(std::floor(v.y() / res)),
                  static_cast<int>(std::floor(v.z() / res))};
    };
    if (cluster != nullptr) {
      for (const Eigen::Vector3f& g : ground) {
        if ((g.array() >= cluster->min.array() - 0.01f).all() &&
            (g.array() <= cluster->max.array() + 0.01f).all()) {
          cluster_cells.insert(cell_of(g));
        }
      }
    }
    if (t != nullptr) {
      for (const Eigen::Vector3f& v : PlacedVoxels(*t, d.best)) template_cells.insert(cell_of(v));
      // Free limbs the pose was fitted without (the robot holds them otherwise): their voxels.
      if (d.best.free_limbs_left_out) {
        for (const Eigen::Vector3f& v : Placed(t->FreeLimbPoints(), d.best)) {
          if (template_cells.count(cell_of(v))) limb_cells.insert(cell_of(v));
        }
      }
    }
    const int half = kPanel / 2;
    const double span = CloseUpSpan(t);  // metres shown in each close-up.
    const double s = half / span;
    // Top close-up in the upper half, side close-up (y horizontal, z up) in the lower half.
    auto draw_cell = [&](const Cell& c, const Bgr& colour, bool top) {
      const double cx = (std::get<0>(c) + 0.5) * res, cy = (std::get<1>(c) + 0.5) * res,
                   cz = (std::get<2>(c) + 0.5) * res;
      Px p;
      if (top) {
        p = Px(x1 + half - static_cast<int>((cy - d.best.pose.y) * s),
               half / 2 + 20 - static_cast<int>((cx - d.best.pose.x) * s));
      } else {
        p = Px(x1 + half - static_cast<int>((cy - d.best.pose.y) * s),
               kPanel - 15 - static_cast<int>(cz * s * 0.85));
      }
      const int r = std::max(1, static_cast<int>(res * s * 0.45));
      img.Rectangle(p - Px(r, r), p + Px(r, r), colour, -1);
    };
    for (bool top : {true, false}) {
      for (const Cell& c : template_cells) {
        draw_cell(c, limb_cells.count(c) ? Bgr(40, 140, 255) : Bgr(50, 50, 200), top);
      }
      for (const Cell& c : cluster_cells) {
        draw_cell(c, template_cells.count(c) ? Bgr(220, 60, 220) : Bgr(220, 130, 40), top);
      }
    }
    const Pose2D& p = d.best.pose;
    const Bgr heading_colour = miss != nullptr ? Bgr(120, 120, 255) : Bgr(230, 230, 230);
    img.Text(d.best.template_name + "  x " + FormatNumber("%.3f", p.x) + " m  y " +
                 FormatNumber("%.3f", p.y) + " m  theta " +
                 FormatNumber("%.1f", RadToDeg(p.theta)) + " deg  score " +
                 FormatNumber("%.1f", d.best.score),
             Px(x1 + 10, 20), 0.5, heading_colour, 1, LineKind::kSmooth);
    int row = 42;
    if (miss != nullptr) {
      for (const std::string& line : WrapWords(
               "the nearest miss, not a humanoid: " + NearestMissReason(*miss, options), 72)) {
        img.Text(line, Px(x1 + 10, row), 0.45, Bgr(120, 120, 255), 1, LineKind::kSmooth);
        row += 18;
      }
    }
    const std::string in_view = PartlyInViewNote(d.best);
    if (!in_view.empty()) {
      for (const std::string& line :
           WrapWords(in_view + ", the rest beyond the image's edges", 72)) {
        img.Text(line, Px(x1 + 10, row), 0.45, Bgr(90, 200, 230), 1, LineKind::kSmooth);
        row += 18;
      }
    }
    if (!limb_cells.empty()) {
      img.Text("orange: the free limbs, held otherwise: the pose was fitted without them",
               Px(x1 + 10, row), 0.45, Bgr(40, 140, 255), 1, LineKind::kSmooth);
      row += 18;
    }
    img.Text("close-up from above", Px(x1 + 10, row), 0.45, Bgr(170, 170, 170), 1,
             LineKind::kSmooth);
    img.Text("seen from the sensor (y-z)", Px(x1 + 10, half + 12), 0.45, Bgr(170, 170, 170), 1,
             LineKind::kSmooth);
    img.Text("blue: cluster  red: template  magenta: both", Px(x1 + 10, kPanel - 2), 0.45,
             Bgr(200, 200, 200), 1, LineKind::kSmooth);
  }
  return WritePicturePng(img, path);
}

}  // namespace hpose::tools
