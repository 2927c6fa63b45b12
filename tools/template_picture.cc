#include "tools/template_picture.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/common/pose2d.h"
#include "core/depth/intrinsics.h"
#include "core/templates/template_shape.h"
#include "tools/canvas.h"
#include "tools/fixed_text.h"
#include "tools/picture_png.h"

namespace hpose::tools {
namespace {

constexpr int kPanelW = 320;
constexpr int kPanelH = 420;
constexpr int kTitleH = 40;

const Bgr kRed(60, 60, 230), kGreen(60, 200, 60), kBlue(230, 140, 40);
const Bgr kText(230, 230, 230);

// Grey level for a depth in [lo, hi] voxels: nearer is brighter.
Bgr Shade(int d, int lo, int hi) {
  const double t = hi > lo ? static_cast<double>(d - lo) / (hi - lo) : 1.0;
  const double g = 70 + 170 * t;
  return Bgr(g * 0.85, g * 0.95, g);
}

void Arrow(Canvas* img, Px from, Px to, const Bgr& colour, const std::string& label) {
  img->ArrowedLine(from, to, colour, 2, LineKind::kSmooth, 0.2);
  img->Text(label, to + Px(4, -4), 0.5, colour, 1, LineKind::kSmooth);
}

// An axis pointing at the viewer (circle with a dot) or away (circle with a cross).
void AxisOutOfPlane(Canvas* img, Px at, const Bgr& colour, bool towards, const std::string& label) {
  img->Circle(at, 7, colour, 2, LineKind::kSmooth);
  if (towards) {
    img->Circle(at, 2, colour, kFilled, LineKind::kSmooth);
  } else {
    img->Line(at + Px(-4, -4), at + Px(4, 4), colour, 2, LineKind::kSmooth);
    img->Line(at + Px(-4, 4), at + Px(4, -4), colour, 2, LineKind::kSmooth);
  }
  img->Text(label, at + Px(9, 16), 0.5, colour, 1, LineKind::kSmooth);
}

struct AxisDraw {
  // Image direction of +x, +y, +z in a view ((0,0): out of the plane) and, for those, whether
  // they point at the viewer.
  Px dir[3];
  bool towards[3];
};

// Draws an orthographic view into the panel at x0 with `px` pixels per voxel.
void DrawView(Canvas* img, int x0, const TemplateView& view, int px, const std::string& title,
              const AxisDraw& axes) {
  img->Text(title, Px(x0 + 10, 26), 0.6, kText, 1, LineKind::kSmooth);
  int lo = 0, hi = 0;
  bool first = true;
  for (const int d : view.depth) {
    if (d == TemplateView::kEmpty) continue;
    lo = first ? d : std::min(lo, d);
    hi = first ? d : std::max(hi, d);
    first = false;
  }
  // Cell (u, v) spans [u, u + 1) x [v, v + 1) voxels; the template origin is the corner
  // (0, 0), drawn at (cx, base_y).
  const int cx = x0 + kPanelW / 2;
  const int base_y = kPanelH - 40 + view.v_min * px;
  for (int v = view.v_min; v < view.v_min + view.rows; ++v) {
    for (int u = -view.half_width; u < view.half_width; ++u) {
      const int d = view.at(u, v);
      if (d == TemplateView::kEmpty) continue;
      Bgr shade = Shade(d, lo, hi);
      if (view.free_limb[(v - view.v_min) * view.columns() + (u + view.half_width)]) {
        shade = Bgr(shade.b * 0.35, shade.g * 0.7, shade.r);  // free limbs in orange.
      }
      img->Rectangle(PxBox{cx + u * px, base_y - (v + 1) * px, px, px}, shade, kFilled);
    }
  }
  const Px origin(cx, base_y);
  const int len = std::max(30, static_cast<int>(0.1 / view.resolution_m * px));
  const char* names[3] = {"x", "y", "z"};
  const Bgr colours[3] = {kRed, kGreen, kBlue};
  for (int a = 0; a < 3; ++a) {
    if (axes.dir[a] == Px(0, 0)) {
      AxisOutOfPlane(img, origin, colours[a], axes.towards[a], names[a]);
    } else {
      Arrow(img, origin, origin + axes.dir[a] * len, colours[a], names[a]);
    }
  }
  img->Circle(origin, 3, kText, kFilled, LineKind::kSmooth);
  // Scale bar: 0.1 m.
  const int bar = static_cast<int>(std::lround(0.1 / view.resolution_m * px));
  const Px b0(x0 + 12, kPanelH - 12);
  img->Line(b0, b0 + Px(bar, 0), kText, 2);
  img->Text("0.1 m", b0 + Px(bar + 6, 4), 0.4, kText, 1, LineKind::kSmooth);
}

// The voxels as a level Kinect v1 sees them: each voxel a square splat, nearest drawn last.
void DrawKinectView(Canvas* img, int x0, const VoxelTemplate& tpl,
                    const TemplatePictureOptions& o) {
  const Intrinsics k = Intrinsics::KinectV1(640, 480);
  const Pose2D pose{o.sensor_distance_m, 0.0, DegToRad(o.heading_deg)};
  const Eigen::Isometry3d ground_from_robot = pose.ToIsometry();
  // Sensor frame: x right, y down, z forward; ground: x forward, y left, z up.
  auto to_sensor = [&](const Eigen::Vector3d& g) {
    return Eigen::Vector3d(-g.y(), o.sensor_height_m - g.z(), g.x());
  };
  struct Splat {
    double z;
    Eigen::Vector2d px;
    double half;
    double height;
  };
  std::vector<Splat> splats;
  for (const Eigen::Vector3f& v : tpl.voxels) {
    const Eigen::Vector3d s = to_sensor(ground_from_robot * v.cast<double>());
    if (s.z() <= 0.1) continue;
    splats.push_back({s.z(),
                      Eigen::Vector2d(k.fx * s.x() / s.z() + k.cx, k.fy * s.y() / s.z() + k.cy),
                      0.5 * tpl.resolution_m * k.fx / s.z(), v.z()});
  }
  if (splats.empty()) return;
  std::sort(splats.begin(), splats.end(), [](const Splat& a, const Splat& b) { return a.z > b.z; });
  // Crop around the robot and its axes, then fit the panel.
  double u0 = 1e9, u1 = -1e9, v0 = 1e9, v1 = -1e9;
  for (const Splat& s : splats) {
    u0 = std::min(u0, s.px.x() - s.half);
    u1 = std::max(u1, s.px.x() + s.half);
    v0 = std::min(v0, s.px.y() - s.half);
    v1 = std::max(v1, s.px.y() + s.half);
  }
  const double zmin = splats.back().z, zmax = splats.front().z;
  const double margin = 0.25 * std::max(u1 - u0, v1 - v0);
  u0 -= margin;
  u1 += margin;
  v0 -= margin;
  v1 += margin;
  const double scale = std::min((kPanelW - 20) / (u1 - u0), (kPanelH - kTitleH - 40) / (v1 - v0));
  auto panel = [&](const Eigen::Vector2d& p) {
    return Px(x0 + 10 + static_cast<int>((p.x() - u0) * scale),
              kTitleH + 10 + static_cast<int>((p.y() - v0) * scale));
  };
  for (const Splat& s : splats) {
    const double t = zmax > zmin ? (zmax - s.z) / (zmax - zmin) : 1.0;
    const double g = 80 + 160 * t;
    const Px a = panel(s.px - Eigen::Vector2d(s.half, s.half));
    const Px b = panel(s.px + Eigen::Vector2d(s.half, s.half));
    img->Rectangle(PxBox::Spanning(a, b + Px(1, 1)), Bgr(g * 0.85, g * 0.95, g), kFilled);
  }
  auto project = [&](const Eigen::Vector3d& robot_point) {
    const Eigen::Vector3d s = to_sensor(ground_from_robot * robot_point);
    return panel(Eigen::Vector2d(k.fx * s.x() / s.z() + k.cx, k.fy * s.y() / s.z() + k.cy));
  };
  const Px origin = project(Eigen::Vector3d::Zero());
  const char* names[3] = {"x", "y", "z"};
  const Bgr colours[3] = {kRed, kGreen, kBlue};
  for (int a = 0; a < 3; ++a) {
    Arrow(img, origin, project(0.12 * Eigen::Vector3d::Unit(a)), colours[a], names[a]);
  }
  img->Circle(origin, 3, kText, kFilled, LineKind::kSmooth);
  img->Text("Kinect at " + FormatNumber("%.1f", o.sensor_distance_m) + " m, " +
                FormatNumber("%.2f", o.sensor_height_m) + " m high",
            Px(x0 + 10, 26), 0.5, kText, 1, LineKind::kSmooth);
  img->Text("robot heading " + FormatNumber("%.0f", o.heading_deg) + " deg",
            Px(x0 + 10, kPanelH - 12), 0.45, kText, 1, LineKind::kSmooth);
}

}  // namespace

Status WriteTemplatePicture(const VoxelTemplate& tpl, const std::string& path,
                            const TemplatePictureOptions& options) {
  if (tpl.voxels.empty()) return MakeError(ErrorCode::kInvalidArgument, "template is empty");
  const bool limbs =
      std::find(tpl.free_limb.begin(), tpl.free_limb.end(), 1) != tpl.free_limb.end();
  Result<Canvas> made = Canvas::Create(4 * kPanelW, kPanelH + (limbs ? 50 : 30), Bgr(30, 30, 30));
  if (!made.ok()) return made.error();
  Canvas& img = *made;
  const TemplateView front = ViewTemplate(tpl, TemplateSide::kFront);
  const TemplateView side = ViewTemplate(tpl, TemplateSide::kLeft);
  const TemplateView top = ViewTemplate(tpl, TemplateSide::kTop);
  // One scale for the three orthographic views.
  const int px =
      std::max(1, std::min({(kPanelW - 20) / front.columns(), (kPanelH - kTitleH - 50) / front.rows,
                            (kPanelH - kTitleH - 50) / top.rows}));
  // Front: viewer at +x; image right = +y, up = +z, x towards the viewer.
  DrawView(&img, 0, front, px, "front (from +x)",
           {{{0, 0}, {1, 0}, {0, -1}}, {true, false, false}});
  // Left side: viewer at +y; image right = -x, up = +z, y towards the viewer.
  DrawView(&img, kPanelW, side, px, "side (from +y, its left)",
           {{{-1, 0}, {0, 0}, {0, -1}}, {false, true, false}});
  // Top: image up = +x, right = -y, z towards the viewer.
  DrawView(&img, 2 * kPanelW, top, px, "top (from +z)",
           {{{0, -1}, {-1, 0}, {0, 0}}, {false, false, true}});
  DrawKinectView(&img, 3 * kPanelW, tpl, options);
  for (int p = 1; p < 4; ++p) {
    img.Line(Px(p * kPanelW, 0), Px(p * kPanelW, kPanelH), Bgr(70, 70, 70));
  }
  const TemplateShape shape = DescribeTemplate(tpl);
  const std::string footer =
      "'" + tpl.name + "': " + std::to_string(shape.voxels) + " voxels of " +
      FormatNumber("%.0f", tpl.resolution_m * 1000) + " mm, height " +
      FormatNumber("%.0f", shape.height_m * 1000) + " mm, x " +
      FormatNumber("%.0f", shape.width_x_m * 1000) + " mm, y " +
      FormatNumber("%.0f", shape.width_y_m * 1000) + " mm; front/back differ " +
      FormatNumber("%.0f", 100 * shape.front_back_difference) + "%, left/right sides " +
      FormatNumber("%.0f", 100 * shape.left_right_difference) + "%, mirror " +
      FormatNumber("%.0f", 100 * shape.mirror_difference) + "%";
  img.Text(footer, Px(10, kPanelH + 20), 0.5, kText, 1, LineKind::kSmooth);
  if (limbs) {
    img.Text(
        "orange: free limbs (arms, head), fitted without them where the robot holds them "
        "otherwise",
        Px(10, kPanelH + 40), 0.5, Bgr(60, 150, 240), 1, LineKind::kSmooth);
  }
  return WritePicturePng(img, path, 9);
}

}  // namespace hpose::tools
