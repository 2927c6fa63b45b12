#include "core/sim/scene.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace hpose {
namespace {

bool IsFinite(const Eigen::Isometry3d& t) { return t.matrix().allFinite(); }

// Radius of a vertical cylinder around the primitive's centre that holds its footprint.
double FootprintRadius(const Primitive& p) {
  const Eigen::AlignedBox3d b = p.Bounds();
  const Eigen::Vector2d c = p.parent_from_local.translation().head<2>();
  return std::max((b.min().head<2>() - c).norm(), (b.max().head<2>() - c).norm());
}

// Radius of a vertical cylinder around the template origin that holds the body.
double FootprintRadius(const Eigen::AlignedBox3d& b) {
  double r = 0.0;
  for (const double x : {b.min().x(), b.max().x()}) {
    for (const double y : {b.min().y(), b.max().y()}) r = std::max(r, std::hypot(x, y));
  }
  return r;
}

// Distance from point p to the segment a-b in the plane.
double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double s = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + s * ab)).norm();
}

// Uniform in [lo, hi) from 53 random bits: the same on every platform, unlike
// std::uniform_real_distribution.
double Uniform(std::mt19937_64* rng, double lo, double hi) {
  const double u = static_cast<double>((*rng)() >> 11) * (1.0 / 9007199254740992.0);
  return lo + (hi - lo) * u;
}

struct Disc {
  Eigen::Vector2d centre;
  double radius;
};

}  // namespace

Status Scene::AddHumanoid(const HumanoidModel& model, const Pose2D& pose,
                          const std::string& preset) {
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    return MakeError(ErrorCode::kInvalidArgument, "humanoid pose must be finite");
  }
  Pose2D p = pose;
  p.theta = NormalizeAngle(p.theta);
  humanoids_.push_back(PlacedHumanoid{model, p, preset});
  return Status::Ok();
}

Status Scene::AddMeshRobot(std::shared_ptr<const MeshBvh> body, const Pose2D& pose,
                           const std::string& name) {
  if (body == nullptr) return MakeError(ErrorCode::kInvalidArgument, "mesh robot has no body");
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    return MakeError(ErrorCode::kInvalidArgument, "mesh robot pose must be finite");
  }
  Pose2D p = pose;
  p.theta = NormalizeAngle(p.theta);
  mesh_robots_.push_back(PlacedMeshRobot{std::move(body), p, name});
  return Status::Ok();
}

Status Scene::AddClutter(const Primitive& primitive_ground) {
  if (!IsFinite(primitive_ground.parent_from_local)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "clutter '" + primitive_ground.name + "' has a non-finite pose");
  }
  const Eigen::Vector3d& h = primitive_ground.half_size;
  if (!h.allFinite() || h.minCoeff() <= 0.0 || h.maxCoeff() > 5.0) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "clutter '" + primitive_ground.name + "' must have sizes in (0, 10] m");
  }
  clutter_.push_back(primitive_ground);
  return Status::Ok();
}

Status Scene::AddRandomClutter(int count, std::uint64_t seed, const ClutterOptions& options) {
  if (count < 0 || count > 100) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "clutter count must be in [0, 100], got " + std::to_string(count));
  }
  if (!(options.min_distance_m > 0.0) || !(options.max_distance_m > options.min_distance_m) ||
      !std::isfinite(options.max_distance_m) || !(options.half_fov_rad > 0.0) ||
      !(options.half_fov_rad < kPi) || !(options.clearance_m >= 0.0) ||
      options.max_attempts_per_object < 1) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "clutter options: need 0 < min_distance < max_distance, 0 < half_fov < pi, "
                     "clearance >= 0 and at least one attempt");
  }
  std::vector<Disc> taken;
  std::vector<Disc> humanoid_discs;
  for (const PlacedHumanoid& h : humanoids_) {
    humanoid_discs.push_back(
        {Eigen::Vector2d(h.pose.x, h.pose.y), FootprintRadius(h.model.bounds())});
    taken.push_back(humanoid_discs.back());
  }
  for (const PlacedMeshRobot& m : mesh_robots_) {
    humanoid_discs.push_back(
        {Eigen::Vector2d(m.pose.x, m.pose.y), FootprintRadius(m.body->bounds())});
    taken.push_back(humanoid_discs.back());
  }
  for (const Primitive& c : clutter_) {
    taken.push_back({c.parent_from_local.translation().head<2>(), FootprintRadius(c)});
  }

  std::mt19937_64 rng(seed);
  for (int i = 0; i < count; ++i) {
    bool placed = false;
    for (int attempt = 0; attempt < options.max_attempts_per_object && !placed; ++attempt) {
      // Shape and size first, then a place on the floor.
      Primitive p;
      const double yaw = Uniform(&rng, -kPi, kPi);
      Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
      pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      const double kind = Uniform(&rng, 0.0, 1.0);
      if (i == 0) {
        const double r = Uniform(&rng, 0.05, 0.11);
        p = Primitive::Sphere("ball", r, Eigen::Vector3d(0.0, 0.0, r));
      } else if (kind < 0.5) {
        const Eigen::Vector3d size(Uniform(&rng, 0.08, 0.35), Uniform(&rng, 0.08, 0.35),
                                   Uniform(&rng, 0.08, 0.50));
        pose.translation().z() = 0.5 * size.z();
        p = Primitive::Box("box_" + std::to_string(i), size, pose);
      } else {
        const double r = Uniform(&rng, 0.04, 0.15);
        const double height = Uniform(&rng, 0.10, 0.60);
        pose.translation().z() = 0.5 * height;
        p = Primitive::Cylinder("cylinder_" + std::to_string(i), r, height, pose);
      }
      const double distance = Uniform(&rng, options.min_distance_m, options.max_distance_m);
      const double bearing = Uniform(&rng, -options.half_fov_rad, options.half_fov_rad);
      const Eigen::Vector2d centre(distance * std::cos(bearing), distance * std::sin(bearing));
      p.parent_from_local.translation().head<2>() = centre;
      const double radius = FootprintRadius(p);

      bool ok = true;
      for (const Disc& d : taken) {
        if ((d.centre - centre).norm() < d.radius + radius + options.clearance_m) ok = false;
      }
      if (options.keep_humanoids_visible) {
        for (const Disc& d : humanoid_discs) {
          if (DistanceToSegment(centre, Eigen::Vector2d::Zero(), d.centre) <
              d.radius + radius + options.clearance_m) {
            ok = false;
          }
        }
      }
      if (!ok) continue;
      clutter_.push_back(p);
      taken.push_back({centre, radius});
      placed = true;
    }
    if (!placed) {
      return MakeError(ErrorCode::kFailedPrecondition,
                       "no room for clutter: placed " + std::to_string(i) + " of " +
                           std::to_string(count) + " objects without overlaps");
    }
  }
  return Status::Ok();
}

std::vector<std::vector<Primitive>> Scene::ObjectsInGround() const {
  std::vector<std::vector<Primitive>> objects;
  for (const PlacedHumanoid& h : humanoids_) {
    const Eigen::Isometry3d ground_from_robot = h.pose.ToIsometry();
    std::vector<Primitive> parts;
    for (const Primitive& p : h.model.primitives())
      parts.push_back(p.Transformed(ground_from_robot));
    objects.push_back(std::move(parts));
  }
  for (const Primitive& c : clutter_) objects.push_back({c});
  return objects;
}

}  // namespace hpose
