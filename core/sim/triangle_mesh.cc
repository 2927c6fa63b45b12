#include "core/sim/triangle_mesh.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <tuple>
#include <unordered_set>

#include "core/common/pose2d.h"

namespace hpose {
namespace {

// Adds a ring-by-ring surface of revolution around the local z axis: `rings` holds (radius, z)
// pairs from bottom to top; a zero radius is a pole. The result is closed when the first and
// last rings are poles (or caps are added by the caller).
void AddRevolution(const std::vector<Eigen::Vector2d>& rings, int segments, TriangleMesh* mesh) {
  std::vector<int> first_index;
  for (const Eigen::Vector2d& rz : rings) {
    first_index.push_back(static_cast<int>(mesh->vertices.size()));
    const int count = rz.x() > 0.0 ? segments : 1;
    for (int s = 0; s < count; ++s) {
      const double a = 2.0 * kPi * s / segments;
      mesh->vertices.emplace_back(static_cast<float>(rz.x() * std::cos(a)),
                                  static_cast<float>(rz.x() * std::sin(a)),
                                  static_cast<float>(rz.y()));
    }
  }
  for (size_t r = 0; r + 1 < rings.size(); ++r) {
    const bool pole_a = !(rings[r].x() > 0.0);
    const bool pole_b = !(rings[r + 1].x() > 0.0);
    const int a0 = first_index[r];
    const int b0 = first_index[r + 1];
    for (int s = 0; s < segments; ++s) {
      const int s1 = (s + 1) % segments;
      if (pole_a && pole_b) continue;
      if (pole_a) {
        mesh->triangles.emplace_back(a0, b0 + s1, b0 + s);
      } else if (pole_b) {
        mesh->triangles.emplace_back(a0 + s, a0 + s1, b0);
      } else {
        mesh->triangles.emplace_back(a0 + s, a0 + s1, b0 + s1);
        mesh->triangles.emplace_back(a0 + s, b0 + s1, b0 + s);
      }
    }
  }
}

TriangleMesh TessellateBox(const Eigen::Vector3d& h) {
  TriangleMesh mesh;
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.emplace_back(static_cast<float>((i & 1) ? h.x() : -h.x()),
                               static_cast<float>((i & 2) ? h.y() : -h.y()),
                               static_cast<float>((i & 4) ? h.z() : -h.z()));
  }
  const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const auto& f : faces) {
    mesh.triangles.emplace_back(f[0], f[1], f[2]);
    mesh.triangles.emplace_back(f[0], f[2], f[3]);
  }
  return mesh;
}

// Half-space separating-axis test of a triangle (relative to the box centre) against a box of
// half extent `h`: true when they overlap with a strictly positive depth.
bool TriangleOverlapsBox(const Eigen::Vector3d& v0, const Eigen::Vector3d& v1,
                         const Eigen::Vector3d& v2, double h) {
  const Eigen::Vector3d e[3] = {v1 - v0, v2 - v1, v0 - v2};
  // The nine edge x box-axis axes.
  for (int i = 0; i < 3; ++i) {
    for (int a = 0; a < 3; ++a) {
      const Eigen::Vector3d axis = Eigen::Vector3d::Unit(a).cross(e[i]);
      const double p0 = axis.dot(v0), p1 = axis.dot(v1), p2 = axis.dot(v2);
      const double r = h * axis.cwiseAbs().sum();
      if (std::min({p0, p1, p2}) >= r || std::max({p0, p1, p2}) <= -r) return false;
    }
  }
  // The box's own axes.
  for (int a = 0; a < 3; ++a) {
    if (std::min({v0[a], v1[a], v2[a]}) >= h || std::max({v0[a], v1[a], v2[a]}) <= -h) return false;
  }
  // The triangle's plane.
  const Eigen::Vector3d n = e[0].cross(e[1]);
  const double d = n.dot(v0);
  const double r = h * n.cwiseAbs().sum();
  return std::abs(d) < r || n.squaredNorm() == 0.0;
}

std::int64_t CellKey(std::int64_t x, std::int64_t y, std::int64_t z) {
  constexpr std::int64_t kBias = 1 << 20;
  return ((z + kBias) << 42) | ((y + kBias) << 21) | (x + kBias);
}

// The steps of SampleMeshSurface's lattice along a triangle's edges: its longest edge in steps
// of at most `spacing_m`, at least one.
double LatticeSteps(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                    double spacing_m) {
  const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
  return std::max(1.0, std::ceil(longest / spacing_m));
}

// The samples SampleMeshSurface takes of `mesh` at `spacing_m`, counted without taking them.
double SampleCount(const TriangleMesh& mesh, double spacing_m) {
  double count = 0.0;
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    const double n =
        LatticeSteps(mesh.vertices[tri[0]].cast<double>(), mesh.vertices[tri[1]].cast<double>(),
                     mesh.vertices[tri[2]].cast<double>(), spacing_m);
    count += 0.5 * (n + 1.0) * (n + 2.0);
  }
  return count;
}

}  // namespace

void TriangleMesh::Append(const TriangleMesh& other, const Eigen::Isometry3d& this_from_other) {
  const int offset = static_cast<int>(vertices.size());
  const Eigen::Isometry3f t = this_from_other.cast<float>();
  for (const Eigen::Vector3f& v : other.vertices) vertices.push_back(t * v);
  for (const Eigen::Vector3i& tri : other.triangles)
    triangles.push_back(tri + Eigen::Vector3i::Constant(offset));
}

void TriangleMesh::Transform(const Eigen::Isometry3d& new_from_this) {
  const Eigen::Isometry3f t = new_from_this.cast<float>();
  for (Eigen::Vector3f& v : vertices) v = t * v;
}

Eigen::AlignedBox3d TriangleMesh::Bounds() const {
  Eigen::AlignedBox3d box;
  box.setEmpty();
  for (const Eigen::Vector3i& tri : triangles) {
    for (int k = 0; k < 3; ++k) box.extend(vertices[tri[k]].cast<double>());
  }
  return box;
}

bool TriangleMesh::IsValid() const {
  for (const Eigen::Vector3f& v : vertices) {
    if (!v.allFinite()) return false;
  }
  const int n = static_cast<int>(vertices.size());
  for (const Eigen::Vector3i& tri : triangles) {
    if (tri.minCoeff() < 0 || tri.maxCoeff() >= n) return false;
  }
  return true;
}

TriangleMesh TessellatePrimitive(const Primitive& p, double max_edge_m) {
  assert(max_edge_m > 0.0);
  TriangleMesh local;
  const Eigen::Vector3d& h = p.half_size;
  const double r = h.x();
  const int segments =
      std::max(12, static_cast<int>(std::ceil(2.0 * kPi * std::max(r, 1e-6) / max_edge_m)));
  // Rings of a hemisphere of radius r centred at z = zc, from the equator towards the pole on
  // side `sign` (the equator itself excluded).
  auto hemisphere = [&](double zc, int sign) {
    std::vector<Eigen::Vector2d> rings;
    const int steps = std::max(3, segments / 4);
    for (int i = 1; i <= steps; ++i) {
      const double a = 0.5 * kPi * i / steps;
      rings.emplace_back(i == steps ? 0.0 : r * std::cos(a), zc + sign * r * std::sin(a));
    }
    return rings;
  };
  switch (p.shape) {
    case PrimitiveShape::kBox:
      local = TessellateBox(h);
      break;
    case PrimitiveShape::kSphere:
    case PrimitiveShape::kCapsule: {
      const double half = p.shape == PrimitiveShape::kSphere ? 0.0 : h.z();
      std::vector<Eigen::Vector2d> bottom = hemisphere(-half, -1);
      std::vector<Eigen::Vector2d> rings(bottom.rbegin(), bottom.rend());
      rings.emplace_back(r, -half);
      if (half > 0.0) rings.emplace_back(r, half);
      for (const Eigen::Vector2d& ring : hemisphere(half, 1)) rings.push_back(ring);
      AddRevolution(rings, segments, &local);
      break;
    }
    case PrimitiveShape::kCylinder:
      AddRevolution({{0.0, -h.z()}, {r, -h.z()}, {r, h.z()}, {0.0, h.z()}}, segments, &local);
      break;
  }
  local.Transform(p.parent_from_local);
  return local;
}

Status CheckMeshForTemplate(const TriangleMesh& mesh, const std::string& name,
                            double resolution_m) {
  if (!mesh.IsValid()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "template '" + name + "': the body's mesh has non-finite vertices or " +
                         "triangles that name missing vertices");
  }
  if (!(resolution_m > 0.0)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "template '" + name + "': the voxel size must be positive");
  }
  if (mesh.triangles.empty()) return Status::Ok();  // MakeTemplateFromPoints names it.
  const Eigen::AlignedBox3d bounds = mesh.Bounds();
  const Eigen::Vector3d size = bounds.sizes();
  if (size.maxCoeff() > kMaxTemplateBodyM) {
    std::ostringstream msg;
    msg.precision(3);
    msg << "template '" << name << "': the body spans " << size.x() << " x " << size.y() << " x "
        << size.z() << " m, more than the " << kMaxTemplateBodyM
        << " m a template may span; are its meshes in millimetres (a mesh scale of 0.001 "
        << "converts them) or is a shape far from the others?";
    return MakeError(ErrorCode::kInvalidArgument, msg.str());
  }
  const double offset =
      std::max(bounds.min().cwiseAbs().maxCoeff(), bounds.max().cwiseAbs().maxCoeff());
  if (offset > kMaxTemplateOffsetM) {
    std::ostringstream msg;
    msg.precision(3);
    msg << "template '" << name << "': the body lies " << offset
        << " m from the origin of its frame, more than the " << kMaxTemplateOffsetM
        << " m a template may (its coordinates would lose the precision of a voxel); is a joint "
        << "or shape origin in other units, or far from the others?";
    return MakeError(ErrorCode::kInvalidArgument, msg.str());
  }
  const double samples = SampleCount(mesh, 0.25 * resolution_m);
  if (samples > kMaxTemplateSurfaceSamples) {
    std::ostringstream msg;
    msg.precision(3);
    msg << "template '" << name << "': its surface would take " << samples
        << " samples on voxels of " << resolution_m * 1000.0 << " mm (at most "
        << kMaxTemplateSurfaceSamples << "); choose larger voxels";
    return MakeError(ErrorCode::kInvalidArgument, msg.str());
  }
  return Status::Ok();
}

std::vector<Eigen::Vector3f> SampleMeshSurface(const TriangleMesh& mesh, double spacing_m) {
  assert(spacing_m > 0.0);
  std::vector<Eigen::Vector3f> points;
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[tri[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[tri[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[tri[2]].cast<double>();
    const int n = static_cast<int>(LatticeSteps(a, b, c, spacing_m));
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) {
        // Non-negative weights: a point never leaves the half-spaces its vertices share
        // (a sole on z = 0 stays on z >= 0).
        const Eigen::Vector3d p = a * (static_cast<double>(n - i - j) / n) +
                                  b * (static_cast<double>(i) / n) +
                                  c * (static_cast<double>(j) / n);
        points.push_back(p.cast<float>());
      }
    }
  }
  return points;
}

Result<VoxelTemplate> MakeMeshTemplate(const TriangleMesh& mesh, const std::string& name,
                                       double resolution_m, const std::string& variant,
                                       const std::string& source, const TriangleMesh* free_limbs) {
  if (Status s = CheckMeshForTemplate(mesh, name, resolution_m); !s.ok()) return s.error();
  Result<VoxelTemplate> tpl = MakeTemplateFromPoints(VoxelizeMeshSurface(mesh, resolution_m), name,
                                                     resolution_m, variant, source);
  if (!tpl.ok()) return tpl;
  tpl->surface =
      ReduceSurfacePoints(SampleMeshSurface(mesh, 0.25 * resolution_m), tpl->SurfaceCellM());
  if (free_limbs != nullptr && !free_limbs->empty()) {
    tpl->free_limb = MarkSurfaceCells(
        tpl->surface, SampleMeshSurface(*free_limbs, 0.25 * resolution_m), tpl->SurfaceCellM());
  }
  return tpl;
}

std::vector<Eigen::Vector3f> VoxelizeMeshSurface(const TriangleMesh& mesh, double resolution_m) {
  assert(resolution_m > 0.0);
  const double inv = 1.0 / resolution_m;
  std::unordered_set<std::int64_t> seen;
  std::vector<Eigen::Vector3i> cells;
  auto add = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    if (seen.insert(CellKey(x, y, z)).second)
      cells.emplace_back(static_cast<int>(x), static_cast<int>(y), static_cast<int>(z));
  };
  const double h = 0.5 * resolution_m;
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    const Eigen::Vector3d v[3] = {mesh.vertices[tri[0]].cast<double>(),
                                  mesh.vertices[tri[1]].cast<double>(),
                                  mesh.vertices[tri[2]].cast<double>()};
    // Cells holding a vertex (floor convention: a surface on a cell face belongs to the cell
    // above it), then every cell of the triangle's bounds whose interior the triangle crosses.
    for (const Eigen::Vector3d& p : v) {
      add(static_cast<std::int64_t>(std::floor(p.x() * inv)),
          static_cast<std::int64_t>(std::floor(p.y() * inv)),
          static_cast<std::int64_t>(std::floor(p.z() * inv)));
    }
    const Eigen::Vector3d lo = v[0].cwiseMin(v[1]).cwiseMin(v[2]) * inv;
    const Eigen::Vector3d hi = v[0].cwiseMax(v[1]).cwiseMax(v[2]) * inv;
    for (auto z = static_cast<std::int64_t>(std::floor(lo.z()));
         z <= static_cast<std::int64_t>(std::floor(hi.z())); ++z) {
      for (auto y = static_cast<std::int64_t>(std::floor(lo.y()));
           y <= static_cast<std::int64_t>(std::floor(hi.y())); ++y) {
        for (auto x = static_cast<std::int64_t>(std::floor(lo.x()));
             x <= static_cast<std::int64_t>(std::floor(hi.x())); ++x) {
          const Eigen::Vector3d centre = (Eigen::Vector3d(x, y, z).array() + 0.5) * resolution_m;
          if (TriangleOverlapsBox(v[0] - centre, v[1] - centre, v[2] - centre, h)) add(x, y, z);
        }
      }
    }
  }
  // Surfaces lying in a cell face (e.g. a sole on the floor) cross no interior: their lattice
  // samples put them in the cell above, like MakeTemplateFromPoints would.
  for (const Eigen::Vector3f& p : SampleMeshSurface(mesh, 0.25 * resolution_m)) {
    add(static_cast<std::int64_t>(std::floor(p.x() * inv)),
        static_cast<std::int64_t>(std::floor(p.y() * inv)),
        static_cast<std::int64_t>(std::floor(p.z() * inv)));
  }
  std::sort(cells.begin(), cells.end(), [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
    return std::tie(a.z(), a.y(), a.x()) < std::tie(b.z(), b.y(), b.x());
  });
  std::vector<Eigen::Vector3f> centres;
  centres.reserve(cells.size());
  for (const Eigen::Vector3i& c : cells)
    centres.push_back(((c.cast<double>().array() + 0.5) * resolution_m).matrix().cast<float>());
  return centres;
}

}  // namespace hpose
