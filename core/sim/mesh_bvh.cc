#include "core/sim/mesh_bvh.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hpose {
namespace {

constexpr int kLeafSize = 4;

// Entry and exit distances of a ray through a box (slab test); false when it misses or the
// box lies outside (t_min, t_max).
bool RayBox(const Eigen::AlignedBox3f& box, const Eigen::Vector3d& origin,
            const Eigen::Vector3d& inv_dir, double t_min, double t_max, double* t_enter) {
  double lo = t_min, hi = t_max;
  for (int a = 0; a < 3; ++a) {
    double t0 = (box.min()[a] - origin[a]) * inv_dir[a];
    double t1 = (box.max()[a] - origin[a]) * inv_dir[a];
    if (t0 > t1) std::swap(t0, t1);
    // NaN (0 * inf: the ray lies in a slab face) keeps the current interval.
    if (t0 > lo) lo = t0;
    if (t1 < hi) hi = t1;
    if (lo > hi) return false;
  }
  *t_enter = lo;
  return true;
}

}  // namespace

Result<std::shared_ptr<const MeshBvh>> MeshBvh::Build(TriangleMesh mesh) {
  if (mesh.empty()) return MakeError(ErrorCode::kInvalidArgument, "mesh has no triangles");
  if (!mesh.IsValid()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "mesh has a non-finite vertex or a triangle index out of range");
  }
  std::shared_ptr<MeshBvh> bvh(new MeshBvh(std::move(mesh)));
  const TriangleMesh& m = bvh->mesh_;
  bvh->bounds_ = m.Bounds();
  std::vector<Eigen::Vector3f> centroids;
  centroids.reserve(m.triangles.size());
  for (const Eigen::Vector3i& t : m.triangles) {
    centroids.push_back((m.vertices[t[0]] + m.vertices[t[1]] + m.vertices[t[2]]) / 3.0f);
  }
  bvh->order_.resize(m.triangles.size());
  for (size_t i = 0; i < bvh->order_.size(); ++i) bvh->order_[i] = static_cast<int>(i);
  bvh->nodes_.reserve(2 * m.triangles.size() / kLeafSize + 1);
  bvh->BuildNode(0, static_cast<int>(bvh->order_.size()), centroids);
  return std::shared_ptr<const MeshBvh>(std::move(bvh));
}

int MeshBvh::BuildNode(int begin, int end, const std::vector<Eigen::Vector3f>& centroids) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Eigen::AlignedBox3f box;
  box.setEmpty();
  Eigen::AlignedBox3f centre_box;
  centre_box.setEmpty();
  for (int i = begin; i < end; ++i) {
    const Eigen::Vector3i& t = mesh_.triangles[order_[i]];
    for (int k = 0; k < 3; ++k) box.extend(mesh_.vertices[t[k]]);
    centre_box.extend(centroids[order_[i]]);
  }
  nodes_[index].box = box;
  int axis = 0;
  centre_box.sizes().maxCoeff(&axis);
  if (end - begin <= kLeafSize || centre_box.sizes()[axis] <= 0.0f) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  const int mid = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                   [&](int a, int b) { return centroids[a][axis] < centroids[b][axis]; });
  BuildNode(begin, mid, centroids);
  const int right = BuildNode(mid, end, centroids);
  nodes_[index].first = right;
  nodes_[index].count = 0;
  return index;
}

std::optional<RayHit> MeshBvh::Intersect(const Eigen::Vector3d& origin,
                                         const Eigen::Vector3d& direction, double t_min,
                                         double t_max) const {
  const Eigen::Vector3d inv_dir = direction.cwiseInverse();
  double best_t = t_max;
  int best_triangle = -1;
  int stack[64];
  int top = 0;
  double enter = 0.0;
  if (nodes_.empty() || !RayBox(nodes_[0].box, origin, inv_dir, t_min, best_t, &enter)) {
    return std::nullopt;
  }
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        // Moller-Trumbore.
        const Eigen::Vector3i& t = mesh_.triangles[order_[i]];
        const Eigen::Vector3d a = mesh_.vertices[t[0]].cast<double>();
        const Eigen::Vector3d e1 = mesh_.vertices[t[1]].cast<double>() - a;
        const Eigen::Vector3d e2 = mesh_.vertices[t[2]].cast<double>() - a;
        const Eigen::Vector3d p = direction.cross(e2);
        const double det = e1.dot(p);
        if (std::abs(det) < 1e-18) continue;
        const double inv_det = 1.0 / det;
        const Eigen::Vector3d s = origin - a;
        const double u = s.dot(p) * inv_det;
        if (u < 0.0 || u > 1.0) continue;
        const Eigen::Vector3d q = s.cross(e1);
        const double v = direction.dot(q) * inv_det;
        if (v < 0.0 || u + v > 1.0) continue;
        const double hit_t = e2.dot(q) * inv_det;
        if (hit_t > t_min && hit_t < best_t) {
          best_t = hit_t;
          best_triangle = order_[i];
        }
      }
      continue;
    }
    // Visit the nearer child first: push it last.
    const int left = static_cast<int>(&node - nodes_.data()) + 1;
    const int right = node.first;
    double t_left = 0.0, t_right = 0.0;
    const bool hit_left = RayBox(nodes_[left].box, origin, inv_dir, t_min, best_t, &t_left);
    const bool hit_right = RayBox(nodes_[right].box, origin, inv_dir, t_min, best_t, &t_right);
    if (hit_left && hit_right) {
      if (t_left < t_right) {
        stack[top++] = right;
        stack[top++] = left;
      } else {
        stack[top++] = left;
        stack[top++] = right;
      }
    } else if (hit_left) {
      stack[top++] = left;
    } else if (hit_right) {
      stack[top++] = right;
    }
  }
  if (best_triangle < 0) return std::nullopt;
  const Eigen::Vector3i& t = mesh_.triangles[best_triangle];
  const Eigen::Vector3d a = mesh_.vertices[t[0]].cast<double>();
  Eigen::Vector3d n = (mesh_.vertices[t[1]].cast<double>() - a)
                          .cross(mesh_.vertices[t[2]].cast<double>() - a)
                          .normalized();
  if (n.dot(direction) > 0.0) n = -n;
  return RayHit{best_t, n};
}

}  // namespace hpose
