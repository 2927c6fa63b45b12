#ifndef HPOSE_CORE_SIM_SCENE_H_
#define HPOSE_CORE_SIM_SCENE_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/common/pose2d.h"
#include "core/common/status.h"
#include "core/sim/humanoid_model.h"
#include "core/sim/mesh_bvh.h"
#include "core/sim/primitive.h"

namespace hpose {

// Where AddRandomClutter may put objects, in the ground frame (sensor above the origin, looking
// along +x).
struct ClutterOptions {
  double min_distance_m = 0.9;  // horizontal distance from the sensor.
  double max_distance_m = 3.5;
  double half_fov_rad = 0.45;          // bearing limit either side of +x (Kinect v1: 28.5 degrees).
  double clearance_m = 0.08;           // minimum gap between footprints of any two objects.
  bool keep_humanoids_visible = true;  // nothing between the sensor and a humanoid.
  int max_attempts_per_object = 2000;
};

// A humanoid standing in the scene: its posed model and its pose in the ground frame.
struct PlacedHumanoid {
  HumanoidModel model;
  Pose2D pose;         // robot (template) frame in the ground frame.
  std::string preset;  // joint preset name, empty when posed otherwise.
};

// A robot given as a triangle mesh in its template frame (e.g. posed from a URDF), standing
// in the scene at `pose`.
struct PlacedMeshRobot {
  std::shared_ptr<const MeshBvh> body;  // never null once added.
  Pose2D pose;                          // robot (template) frame in the ground frame.
  std::string name;                     // e.g. the robot's or the joint set's name.
};

// What the simulator renders: the floor (plane z = 0 of the ground frame), humanoids and
// clutter, all in the ground frame (metres).
class Scene final {
 public:
  Scene() = default;

  bool has_floor() const { return has_floor_; }
  void set_floor(bool has_floor) { has_floor_ = has_floor; }

  // Adds a humanoid; the first one added is the scene's main humanoid. Fails
  // (kInvalidArgument) on a non-finite pose.
  Status AddHumanoid(const HumanoidModel& model, const Pose2D& pose,
                     const std::string& preset = "");
  // Adds a mesh robot (its mesh in the template frame, feet on z = 0). Fails
  // (kInvalidArgument) on a null body or a non-finite pose.
  Status AddMeshRobot(std::shared_ptr<const MeshBvh> body, const Pose2D& pose,
                      const std::string& name = "");
  // Adds one clutter object given in the ground frame. Fails (kInvalidArgument) on a
  // non-finite pose or a size that is not positive and finite (at most 10 m).
  Status AddClutter(const Primitive& primitive_ground);
  // Adds `count` objects standing on the floor: the first is a ball, the others boxes and
  // upright cylinders of random size and yaw, drawn from `seed` (the same seed gives the same
  // objects). They never overlap a humanoid, a mesh robot or each other. Fails with
  // kInvalidArgument (count outside [0, 100], bad options) or kFailedPrecondition when there is no
  // room left, naming how many could be placed (the scene then holds those).
  Status AddRandomClutter(int count, std::uint64_t seed, const ClutterOptions& options = {});

  const std::vector<PlacedHumanoid>& humanoids() const { return humanoids_; }
  const std::vector<PlacedMeshRobot>& mesh_robots() const { return mesh_robots_; }
  const std::vector<Primitive>& clutter() const { return clutter_; }

  // Every solid object made of primitives as a list in the ground frame: one entry per
  // humanoid (in order), then one per clutter primitive. Mesh robots are not included.
  std::vector<std::vector<Primitive>> ObjectsInGround() const;

 private:
  bool has_floor_ = true;
  std::vector<PlacedHumanoid> humanoids_;
  std::vector<PlacedMeshRobot> mesh_robots_;
  std::vector<Primitive> clutter_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SIM_SCENE_H_
