#include "core/templates/voxel_template.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <tuple>

namespace hpose {
namespace {

bool ValidName(const std::string& name) {
  if (name.empty() || name.size() > 128) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-' || c == '.';
  });
}

using Cell = std::tuple<int, int, int>;

Cell CellAt(const Eigen::Vector3f& p, double inv_edge) {
  return Cell(static_cast<int>(std::floor(inv_edge * static_cast<double>(p.x()))),
              static_cast<int>(std::floor(inv_edge * static_cast<double>(p.y()))),
              static_cast<int>(std::floor(inv_edge * static_cast<double>(p.z()))));
}

// The mean of the points in each cell of edge `edge_m`, in cell order.
std::vector<Eigen::Vector3f> CellCentroids(const std::vector<Eigen::Vector3f>& points,
                                           double edge_m) {
  std::map<Cell, std::pair<Eigen::Vector3d, int>> sums;
  const double inv = 1.0 / edge_m;
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    auto& [sum, n] = sums.try_emplace(CellAt(p, inv), Eigen::Vector3d::Zero(), 0).first->second;
    sum += p.cast<double>();
    ++n;
  }
  std::vector<Eigen::Vector3f> out;
  out.reserve(sums.size());
  for (const auto& [cell, sn] : sums) out.push_back((sn.first / sn.second).cast<float>());
  return out;
}

}  // namespace

std::string VoxelEdgeText(double m) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.1f mm", m * 1000.0);
  return buf;
}

std::vector<Eigen::Vector3f> ReduceSurfacePoints(const std::vector<Eigen::Vector3f>& points,
                                                 double cell_m) {
  return CellCentroids(points, cell_m);
}

std::vector<std::uint8_t> MarkSurfaceCells(const std::vector<Eigen::Vector3f>& surface,
                                           const std::vector<Eigen::Vector3f>& part,
                                           double cell_m) {
  const double inv = 1.0 / cell_m;
  std::set<Cell> cells;
  for (const Eigen::Vector3f& p : part) {
    if (p.allFinite()) cells.insert(CellAt(p, inv));
  }
  std::vector<std::uint8_t> marks(surface.size(), 0);
  for (size_t i = 0; i < surface.size(); ++i) marks[i] = cells.count(CellAt(surface[i], inv)) > 0;
  return marks;
}

std::vector<Eigen::Vector3f> VoxelTemplate::FreeLimbPoints() const {
  std::vector<Eigen::Vector3f> out;
  if (free_limb.size() != surface.size()) return out;
  for (size_t i = 0; i < surface.size(); ++i) {
    if (free_limb[i]) out.push_back(surface[i]);
  }
  return out;
}

std::vector<Eigen::Vector3f> VoxelTemplate::VoxelSurfaceCentroids() const {
  if (surface.empty()) return voxels;
  // Sums per (x, y) column of voxels.
  std::map<std::pair<int, int>, std::pair<Eigen::Vector2d, int>> sums;
  const double inv = 1.0 / resolution_m;
  for (const Eigen::Vector3f& p : surface) {
    const Cell c = CellAt(p, inv);
    auto& [sum, n] = sums.try_emplace({std::get<0>(c), std::get<1>(c)}, Eigen::Vector2d::Zero(), 0)
                         .first->second;
    sum += p.head<2>().cast<double>();
    ++n;
  }
  std::vector<Eigen::Vector3f> out;
  out.reserve(voxels.size());
  for (const Eigen::Vector3f& v : voxels) {
    const Cell c = CellAt(v, inv);
    auto it = sums.find({std::get<0>(c), std::get<1>(c)});
    if (it == sums.end()) {
      out.push_back(v);
      continue;
    }
    const Eigen::Vector2d xy = it->second.first / it->second.second;
    out.emplace_back(static_cast<float>(xy.x()), static_cast<float>(xy.y()), v.z());
  }
  return out;
}

double VoxelTemplate::Height() const {
  double top = 0.0;
  for (const Eigen::Vector3f& v : voxels) top = std::max(top, v.z() + 0.5 * resolution_m);
  return top;
}

Result<VoxelTemplate> MakeTemplateFromPoints(const std::vector<Eigen::Vector3f>& points,
                                             const std::string& name, double resolution_m,
                                             const std::string& variant,
                                             const std::string& source) {
  if (!ValidName(name)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "template name '" + name +
                         "' is empty, too long or has characters other than [A-Za-z0-9_.-]");
  }
  if (!(resolution_m >= 0.001 && resolution_m <= 0.5)) {
    return MakeError(
        ErrorCode::kInvalidArgument,
        "template resolution " + std::to_string(resolution_m) + " m is outside [0.001, 0.5] m");
  }
  const double inv = 1.0 / resolution_m;
  std::vector<std::tuple<int, int, int>> cells;
  cells.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    const double x = std::floor(inv * static_cast<double>(p.x()));
    const double y = std::floor(inv * static_cast<double>(p.y()));
    const double z = std::floor(inv * static_cast<double>(p.z()));
    if (std::abs(x) > 30000 || std::abs(y) > 30000 || std::abs(z) > 30000) {
      return MakeError(ErrorCode::kInvalidArgument,
                       "template point (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) +
                           ", " + std::to_string(p.z()) +
                           ") m is too far from the template origin; is the cloud in metres and "
                           "in the template frame?");
    }
    cells.emplace_back(static_cast<int>(x), static_cast<int>(y), static_cast<int>(z));
  }
  if (cells.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, "template '" + name + "' has no finite points (" +
                                                      std::to_string(points.size()) + " given)");
  }
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());

  VoxelTemplate tpl;
  tpl.name = name;
  tpl.variant = variant.empty() ? name : variant;
  tpl.source = source;
  tpl.resolution_m = resolution_m;
  tpl.voxels.reserve(cells.size());
  for (const auto& [x, y, z] : cells) {
    tpl.voxels.emplace_back(static_cast<float>((x + 0.5) * resolution_m),
                            static_cast<float>((y + 0.5) * resolution_m),
                            static_cast<float>((z + 0.5) * resolution_m));
  }
  tpl.surface = CellCentroids(points, tpl.SurfaceCellM());
  return tpl;
}

Result<VoxelTemplate> VoxeliseAgain(const VoxelTemplate& tpl, double resolution_m) {
  if (!(resolution_m >= tpl.resolution_m - 1e-12)) {
    return MakeError(ErrorCode::kInvalidArgument, "template '" + tpl.name + "' has voxels of " +
                                                      VoxelEdgeText(tpl.resolution_m) +
                                                      " and cannot be voxelised again at a finer " +
                                                      VoxelEdgeText(resolution_m));
  }
  // Made under a placeholder name: the template's own was accepted when it was loaded.
  Result<VoxelTemplate> again =
      MakeTemplateFromPoints(tpl.SurfaceOrVoxels(), "t", resolution_m, tpl.variant, tpl.source);
  if (!again.ok()) return again.error();
  again->name = tpl.name;
  if (!tpl.free_limb.empty() && tpl.free_limb.size() == tpl.surface.size()) {
    again->free_limb =
        MarkSurfaceCells(again->surface, tpl.FreeLimbPoints(), again->SurfaceCellM());
  }
  return again;
}

}  // namespace hpose
