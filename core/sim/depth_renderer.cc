#include "core/sim/depth_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace hpose {
namespace {

struct Sphere {
  Eigen::Vector3d centre;
  double radius = 0.0;
};

struct PreparedPart {
  Primitive primitive;  // in the sensor frame.
  Sphere bound;
};

struct PreparedObject {
  std::vector<PreparedPart> parts;
  Sphere bound;
};

// A mesh robot: rays are cast in its own (template) frame.
struct PreparedMesh {
  const MeshBvh* body = nullptr;
  Eigen::Isometry3d mesh_from_sensor;
  Sphere bound;  // sensor frame.
};

std::vector<PreparedMesh> PrepareMeshes(const Scene& scene,
                                        const Eigen::Isometry3d& sensor_from_ground) {
  std::vector<PreparedMesh> meshes;
  for (const PlacedMeshRobot& m : scene.mesh_robots()) {
    const Eigen::Isometry3d sensor_from_mesh = sensor_from_ground * m.pose.ToIsometry();
    const Eigen::AlignedBox3d& b = m.body->bounds();
    meshes.push_back({m.body.get(),
                      sensor_from_mesh.inverse(),
                      {sensor_from_mesh * b.center(), 0.5 * b.diagonal().norm() + 1e-6}});
  }
  return meshes;
}

// Nearest t >= 0 where a ray from the origin along unit `dir` enters the sphere (0 when it
// starts inside), or +inf when it misses.
double SphereEntry(const Sphere& s, const Eigen::Vector3d& dir) {
  const double b = dir.dot(s.centre);
  const double c = s.centre.squaredNorm() - s.radius * s.radius;
  const double disc = b * b - c;
  if (disc < 0.0) return std::numeric_limits<double>::infinity();
  const double root = std::sqrt(disc);
  if (b + root < 0.0) return std::numeric_limits<double>::infinity();
  return std::max(0.0, b - root);
}

std::vector<PreparedObject> Prepare(const Scene& scene,
                                    const Eigen::Isometry3d& sensor_from_ground) {
  std::vector<PreparedObject> objects;
  for (const std::vector<Primitive>& parts : scene.ObjectsInGround()) {
    PreparedObject obj;
    Eigen::AlignedBox3d box;
    box.setEmpty();
    for (const Primitive& p : parts) {
      PreparedPart part{p.Transformed(sensor_from_ground), {}};
      part.bound = {part.primitive.parent_from_local.translation(),
                    part.primitive.BoundingRadius()};
      box.extend(part.primitive.Bounds());
      obj.parts.push_back(std::move(part));
    }
    if (obj.parts.empty()) continue;
    obj.bound.centre = box.center();
    for (const PreparedPart& part : obj.parts) {
      obj.bound.radius = std::max(
          obj.bound.radius, (part.bound.centre - obj.bound.centre).norm() + part.bound.radius);
    }
    objects.push_back(std::move(obj));
  }
  return objects;
}

}  // namespace

Result<DepthRenderer> DepthRenderer::Create(const Intrinsics& intrinsics,
                                            const FloorEstimate& sensor_mount) {
  if (Status s = intrinsics.Validate(); !s.ok()) return s.error();
  if (!sensor_mount.ground_from_sensor.matrix().allFinite()) {
    return MakeError(ErrorCode::kInvalidArgument, "sensor pose is not finite");
  }
  if (!(sensor_mount.ground_from_sensor.translation().z() > 0.0)) {
    return MakeError(ErrorCode::kInvalidArgument, "sensor must be above the floor (height > 0)");
  }
  return DepthRenderer(intrinsics, sensor_mount);
}

DepthImage DepthRenderer::Render(const Scene& scene, const KinectNoiseModel* noise,
                                 std::uint64_t seed) const {
  const Eigen::Isometry3d sensor_from_ground = sensor_mount_.ground_from_sensor.inverse();
  const std::vector<PreparedObject> objects = Prepare(scene, sensor_from_ground);
  const std::vector<PreparedMesh> meshes = PrepareMeshes(scene, sensor_from_ground);
  // The floor (ground z = 0) in the sensor frame: n . p + d = 0, n pointing up.
  const Eigen::Vector3d floor_n = sensor_from_ground.linear().col(2);
  const double floor_d = sensor_mount_.ground_from_sensor.translation().z();
  const bool floor = scene.has_floor();

  const Intrinsics& k = intrinsics_;
  DepthImage image(k.width, k.height);
  // Spatially correlated errors, when asked for, come from the whole image's fields.
  const std::vector<KinectNoiseModel::PixelDraw> draws =
      noise != nullptr && noise->options().correlated_share > 0.0
          ? noise->Draws(seed, k.width, k.height)
          : std::vector<KinectNoiseModel::PixelDraw>();
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::uint64_t index = static_cast<std::uint64_t>(v) * k.width + u;
      KinectNoiseModel::PixelDraw draw;
      if (!draws.empty()) {
        draw = draws[index];
      } else if (noise != nullptr) {
        draw = noise->Draw(seed, index);
      }
      const Eigen::Vector3d dir =
          Eigen::Vector3d((u + draw.du_px - k.cx) / k.fx, (v + draw.dv_px - k.cy) / k.fy, 1.0)
              .normalized();
      double best_t = std::numeric_limits<double>::infinity();
      Eigen::Vector3d best_normal = Eigen::Vector3d::Zero();
      if (floor) {
        const double nd = floor_n.dot(dir);
        if (nd < 0.0) {
          best_t = -floor_d / nd;
          best_normal = floor_n;
        }
      }
      for (const PreparedObject& obj : objects) {
        if (SphereEntry(obj.bound, dir) >= best_t) continue;
        for (const PreparedPart& part : obj.parts) {
          if (SphereEntry(part.bound, dir) >= best_t) continue;
          const std::optional<RayHit> hit =
              part.primitive.Intersect(Eigen::Vector3d::Zero(), dir, 1e-9, best_t);
          if (hit) {
            best_t = hit->t;
            best_normal = hit->normal;
          }
        }
      }
      for (const PreparedMesh& m : meshes) {
        if (SphereEntry(m.bound, dir) >= best_t) continue;
        const std::optional<RayHit> hit = m.body->Intersect(
            m.mesh_from_sensor.translation(), m.mesh_from_sensor.linear() * dir, 1e-9, best_t);
        if (hit) {
          best_t = hit->t;
          best_normal = m.mesh_from_sensor.linear().transpose() * hit->normal;
        }
      }
      if (!std::isfinite(best_t)) continue;
      const double z = best_t * dir.z();
      if (noise != nullptr) {
        const double incidence = std::acos(std::min(1.0, std::abs(best_normal.dot(dir))));
        image.mm[index] = noise->Measure(z, incidence, draw.axial_normal);
      } else if (z > 0.0 && z < 65.5355) {
        image.mm[index] = static_cast<std::uint16_t>(std::lround(z * 1000.0));
      }
    }
  }
  return image;
}

}  // namespace hpose
