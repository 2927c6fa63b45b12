#ifndef HPOSE_CORE_SIM_MESH_BVH_H_
#define HPOSE_CORE_SIM_MESH_BVH_H_

#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/status.h"
#include "core/sim/primitive.h"
#include "core/sim/triangle_mesh.h"

namespace hpose {

// A triangle mesh with a bounding-volume hierarchy for ray casting (axis-aligned boxes split
// at the median of the longest axis, a few triangles per leaf). Immutable once built, so one
// instance can be shared by many scenes and threads.
class MeshBvh final {
 public:
  // Builds the hierarchy. Fails (kInvalidArgument) on an empty mesh, a non-finite vertex or an
  // index out of range.
  static Result<std::shared_ptr<const MeshBvh>> Build(TriangleMesh mesh);

  const TriangleMesh& mesh() const { return mesh_; }
  // Bounds of the whole mesh (its own frame).
  const Eigen::AlignedBox3d& bounds() const { return bounds_; }

  // Nearest triangle hit by origin + t * direction (mesh frame, direction unit length) with t
  // in (t_min, t_max), or nullopt. The normal faces the ray's origin (meshes need no
  // consistent winding).
  std::optional<RayHit> Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                  double t_min, double t_max) const;

 private:
  struct Node {
    Eigen::AlignedBox3f box;
    int first = 0;  // leaf: first triangle in order_; inner: index of the right child.
    int count = 0;  // leaf: number of triangles; 0 for an inner node (left child = this + 1).
  };

  explicit MeshBvh(TriangleMesh mesh) : mesh_(std::move(mesh)) {}
  int BuildNode(int begin, int end, const std::vector<Eigen::Vector3f>& centroids);

  TriangleMesh mesh_;
  Eigen::AlignedBox3d bounds_;
  std::vector<int> order_;  // triangle indices, grouped by leaf.
  std::vector<Node> nodes_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SIM_MESH_BVH_H_
