#include "core/templates/template_shape.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <tuple>

namespace hpose {
namespace {

Eigen::Vector3i VoxelIndex(const Eigen::Vector3f& centre, double resolution) {
  return Eigen::Vector3i(static_cast<int>(std::lround(centre.x() / resolution - 0.5)),
                         static_cast<int>(std::lround(centre.y() / resolution - 0.5)),
                         static_cast<int>(std::lround(centre.z() / resolution - 0.5)));
}

}  // namespace

TemplateView ViewTemplate(const VoxelTemplate& tpl, TemplateSide side) {
  TemplateView view;
  view.resolution_m = tpl.resolution_m;
  if (tpl.voxels.empty()) return view;
  int reach = 0, z_lo = 0, z_hi = 0;
  bool first = true;
  for (const Eigen::Vector3f& c : tpl.voxels) {
    const Eigen::Vector3i i = VoxelIndex(c, tpl.resolution_m);
    reach = std::max({reach, i.x() + 1, -i.x(), i.y() + 1, -i.y()});
    z_lo = first ? i.z() : std::min(z_lo, i.z());
    z_hi = first ? i.z() : std::max(z_hi, i.z());
    first = false;
  }
  view.half_width = reach;
  const bool top = side == TemplateSide::kTop;
  view.v_min = top ? -reach : std::min(0, z_lo);
  view.rows = top ? 2 * reach : z_hi - view.v_min + 1;
  view.depth.assign(static_cast<size_t>(view.rows) * view.columns(), TemplateView::kEmpty);
  view.free_limb.assign(view.depth.size(), 0);
  // The voxels that hold a surface point on a free limb.
  std::set<std::tuple<int, int, int>> limb_voxels;
  const double inv = 1.0 / tpl.resolution_m;
  for (const Eigen::Vector3f& p : tpl.FreeLimbPoints()) {
    limb_voxels.emplace(static_cast<int>(std::floor(p.x() * inv)),
                        static_cast<int>(std::floor(p.y() * inv)),
                        static_cast<int>(std::floor(p.z() * inv)));
  }
  for (const Eigen::Vector3f& c : tpl.voxels) {
    const Eigen::Vector3i i = VoxelIndex(c, tpl.resolution_m);
    int u = 0, v = i.z(), d = 0;
    switch (side) {
      case TemplateSide::kFront:
        u = i.y();
        d = i.x();
        break;
      case TemplateSide::kBack:
        u = ~i.y();
        d = ~i.x();
        break;
      case TemplateSide::kLeft:
        u = ~i.x();
        d = i.y();
        break;
      case TemplateSide::kRight:
        u = i.x();
        d = ~i.y();
        break;
      case TemplateSide::kTop:
        u = ~i.y();
        v = i.x();
        d = i.z();
        break;
    }
    const size_t at =
        static_cast<size_t>((v - view.v_min) * view.columns() + (u + view.half_width));
    const bool limb = limb_voxels.count({i.x(), i.y(), i.z()}) > 0;
    if (d > view.depth[at]) {
      view.depth[at] = d;
      view.free_limb[at] = limb;
    } else if (d == view.depth[at] && limb) {
      view.free_limb[at] = 1;
    }
  }
  return view;
}

double ViewDifference(const TemplateView& a, const TemplateView& b) {
  int either = 0, matched = 0;
  const int half = std::max(a.half_width, b.half_width);
  const int v_lo = std::min(a.v_min, b.v_min);
  const int v_hi = std::max(a.v_min + a.rows, b.v_min + b.rows);
  auto get = [](const TemplateView& t, int u, int v) {
    if (u < -t.half_width || u >= t.half_width || v < t.v_min || v >= t.v_min + t.rows) {
      return TemplateView::kEmpty;
    }
    return t.at(u, v);
  };
  for (int v = v_lo; v < v_hi; ++v) {
    for (int u = -half; u < half; ++u) {
      const int da = get(a, u, v), db = get(b, u, v);
      const bool ina = da != TemplateView::kEmpty, inb = db != TemplateView::kEmpty;
      if (!ina && !inb) continue;
      ++either;
      if (ina && inb && std::abs(da - db) <= 1) ++matched;
    }
  }
  return either == 0 ? 0.0 : 1.0 - static_cast<double>(matched) / either;
}

TemplateShape DescribeTemplate(const VoxelTemplate& tpl) {
  TemplateShape s;
  s.voxels = tpl.voxels.size();
  if (tpl.voxels.empty()) return s;
  Eigen::Vector3f lo = tpl.voxels.front(), hi = tpl.voxels.front();
  for (const Eigen::Vector3f& v : tpl.voxels) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const double half = 0.5 * tpl.resolution_m;
  s.min = lo.cast<double>().array() - half;
  s.max = hi.cast<double>().array() + half;
  s.height_m = tpl.Height();
  s.width_x_m = s.max.x() - s.min.x();
  s.width_y_m = s.max.y() - s.min.y();
  const TemplateView front = ViewTemplate(tpl, TemplateSide::kFront);
  s.front_back_difference = ViewDifference(front, ViewTemplate(tpl, TemplateSide::kBack));
  s.left_right_difference = ViewDifference(ViewTemplate(tpl, TemplateSide::kLeft),
                                           ViewTemplate(tpl, TemplateSide::kRight));
  TemplateView mirrored = front;
  for (int v = front.v_min; v < front.v_min + front.rows; ++v) {
    for (int u = -front.half_width; u < front.half_width; ++u) {
      mirrored.depth[(v - front.v_min) * front.columns() + (u + front.half_width)] =
          front.at(~u, v);
    }
  }
  s.mirror_difference = ViewDifference(front, mirrored);
  return s;
}

}  // namespace hpose
