#ifndef HPOSE_CORE_SIM_PRIMITIVE_H_
#define HPOSE_CORE_SIM_PRIMITIVE_H_

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace hpose {

enum class PrimitiveShape { kBox, kSphere, kCylinder, kCapsule };

// Stable lowercase name: "box", "sphere", "cylinder", "capsule".
const char* PrimitiveShapeName(PrimitiveShape shape);
// Inverse of PrimitiveShapeName; nullopt for an unknown name.
std::optional<PrimitiveShape> PrimitiveShapeFromName(const std::string& name);

// Where a ray meets a primitive: distance along the (unit) ray in metres and the outward unit
// surface normal, both in the frame the ray was given in.
struct RayHit {
  double t = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

// A solid shape placed in a parent frame (metres). The shape is centred on the origin of its
// local frame; cylinders and capsules run along the local z axis.
struct Primitive {
  PrimitiveShape shape = PrimitiveShape::kSphere;
  // kBox: half extents (x, y, z). kSphere: (r, r, r). kCylinder: (r, r, half height).
  // kCapsule: (r, r, half length of the axis segment, the hemispherical caps excluded).
  Eigen::Vector3d half_size = Eigen::Vector3d::Zero();
  Eigen::Isometry3d parent_from_local = Eigen::Isometry3d::Identity();
  std::string name;  // e.g. "head", "left_upper_arm", "box_2".

  // A box of full edge lengths `size_m` (x, y, z of its local frame).
  static Primitive Box(std::string name, const Eigen::Vector3d& size_m,
                       const Eigen::Isometry3d& parent_from_local);
  static Primitive Sphere(std::string name, double radius_m, const Eigen::Vector3d& centre);
  // A cylinder of the given radius and full height along its local z axis.
  static Primitive Cylinder(std::string name, double radius_m, double height_m,
                            const Eigen::Isometry3d& parent_from_local);
  // A capsule around the segment a-b (parent frame). a != b is not required: a zero-length
  // capsule is a sphere.
  static Primitive Capsule(std::string name, double radius_m, const Eigen::Vector3d& a,
                           const Eigen::Vector3d& b);

  // The same primitive expressed in another frame: new_from_parent * parent_from_local.
  Primitive Transformed(const Eigen::Isometry3d& new_from_parent) const;

  // Radius of a sphere around parent_from_local.translation() that holds the whole shape.
  double BoundingRadius() const;
  // Exact axis-aligned bounds in the parent frame.
  Eigen::AlignedBox3d Bounds() const;
  // True when `p_parent` lies inside the solid shrunk by `margin_m` (a positive margin keeps
  // points near the surface outside).
  bool Contains(const Eigen::Vector3d& p_parent, double margin_m = 0.0) const;

  // First intersection of the ray origin + t * direction (parent frame, direction unit length)
  // with t in (t_min, t_max), or nullopt. A ray starting inside the solid reports where it
  // leaves it.
  std::optional<RayHit> Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                  double t_min, double t_max) const;

  // Deterministic points on the surface, roughly `spacing_m` apart, in the parent frame.
  // spacing_m must be positive (asserts).
  std::vector<Eigen::Vector3d> SampleSurface(double spacing_m) const;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SIM_PRIMITIVE_H_
