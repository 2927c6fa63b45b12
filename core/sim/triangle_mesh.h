#ifndef HPOSE_CORE_SIM_TRIANGLE_MESH_H_
#define HPOSE_CORE_SIM_TRIANGLE_MESH_H_

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/status.h"
#include "core/sim/primitive.h"
#include "core/templates/voxel_template.h"

namespace hpose {

// A plain triangle soup with shared vertices (metres, in whatever frame its owner states).
// Triangles index `vertices`; the winding is not relied upon.
struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;

  bool empty() const { return triangles.empty(); }
  // Appends `other` mapped by this_from_other.
  void Append(const TriangleMesh& other,
              const Eigen::Isometry3d& this_from_other = Eigen::Isometry3d::Identity());
  // Maps every vertex by new_from_this.
  void Transform(const Eigen::Isometry3d& new_from_this);
  // Axis-aligned bounds of the vertices used by triangles (empty box for an empty mesh).
  Eigen::AlignedBox3d Bounds() const;
  // True when every vertex is finite and every index is within range.
  bool IsValid() const;
};

// A closed triangle surface approximating a primitive (in the primitive's parent frame): boxes
// exactly, spheres, cylinders and capsules as inscribed polyhedra whose edges are at most
// about `max_edge_m` long (at least 12 segments around). max_edge_m must be positive (asserts).
TriangleMesh TessellatePrimitive(const Primitive& primitive, double max_edge_m);

// Deterministic points on every triangle: a barycentric lattice fine enough that no two
// neighbouring lattice points are more than `spacing_m` apart, vertices included, so even tiny
// or thin triangles are sampled. spacing_m must be positive (asserts).
std::vector<Eigen::Vector3f> SampleMeshSurface(const TriangleMesh& mesh, double spacing_m);

// Exact surface voxelisation: the centres of every cubic cell of edge `resolution_m`
// (cell = floor(p / resolution), as MakeTemplateFromPoints) whose interior a triangle meets
// (separating-axis test), so no cell touched by the surface is missed, however small or thin
// the triangles. Surfaces lying exactly on a cell face count for one side only. Unique and
// sorted (by z, then y, then x). resolution_m must be positive (asserts).
std::vector<Eigen::Vector3f> VoxelizeMeshSurface(const TriangleMesh& mesh, double resolution_m);

// The largest body a mesh template may span along any axis, and the most surface samples
// (SampleMeshSurface at a quarter voxel) it may take: a humanoid is a few metres at most, and a
// mesh far larger is one in other units (millimetres) or a misplaced shape.
inline constexpr double kMaxTemplateBodyM = 5.0;
// ... and how far from the origin of its frame it may lie: vertices are single precision, which
// beyond a kilometre keeps less than a tenth of a millimetre and far away none of a voxel.
inline constexpr double kMaxTemplateOffsetM = 1000.0;
inline constexpr double kMaxTemplateSurfaceSamples = 20e6;

// Ok when MakeMeshTemplate can voxelise `mesh` at `resolution_m`: finite vertices, triangles
// that name existing vertices, a body within kMaxTemplateBodyM, within kMaxTemplateOffsetM of
// its frame's origin, and a surface within
// kMaxTemplateSurfaceSamples; otherwise an error naming what is wrong.
Status CheckMeshForTemplate(const TriangleMesh& mesh, const std::string& name, double resolution_m);

// A template of a mesh body (in the template frame): the voxels of VoxelizeMeshSurface and the
// surface kept from samples a quarter voxel apart (VoxelTemplate::surface), so the search and the
// refinement see the mesh's sub-voxel shape. Fails as CheckMeshForTemplate and
// MakeTemplateFromPoints do. With `free_limbs` (the part of `mesh` on limbs that do not reach
// the floor, e.g. PosedRobot::free_limbs) the surface points on them are marked
// (VoxelTemplate::free_limb).
Result<VoxelTemplate> MakeMeshTemplate(const TriangleMesh& mesh, const std::string& name,
                                       double resolution_m, const std::string& variant = "",
                                       const std::string& source = "",
                                       const TriangleMesh* free_limbs = nullptr);

}  // namespace hpose

#endif  // HPOSE_CORE_SIM_TRIANGLE_MESH_H_
