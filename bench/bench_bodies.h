#ifndef HPOSE_BENCH_BENCH_BODIES_H_
#define HPOSE_BENCH_BENCH_BODIES_H_

// Shared by the accuracy benchmarks: the humanoid bodies frames are rendered of, each with the
// templates of its two shapes made from its own model, as `hpose template generate` /
// `from-urdf` would make them.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/sim/frame_simulator.h"
#include "core/sim/mesh_bvh.h"
#include "core/templates/voxel_template.h"

namespace hpose::bench {

// The two shapes of every body: its templates, meshes and joint sets come in this order.
extern const char* const kShapes[2];

// The two sensor mounts of the accuracy benchmarks: level at 0.34 m (the paper's), and 0.9 m
// high pitched 20 degrees down.
struct Mount {
  const char* name;
  double height_m;
  double pitch_rad;
};
extern const Mount kMounts[2];

// A parametric body (HumanoidDimensions::Variant) or a mesh robot from a URDF.
struct Body {
  std::string name;
  std::string variant;                                 // parametric body; empty for a mesh.
  std::vector<std::shared_ptr<const MeshBvh>> meshes;  // per shape, mesh robots only.
  std::vector<VoxelTemplate> templates;                // per shape.
};

Body ParametricBody(const std::string& variant);

// The Darwin-OP of the shared data at `shared_data_dir` (its missing head mesh skipped, as
// `template from-urdf --allow-missing` does), posed with the joint sets of
// `source_dir`/docs/examples/darwin_op_joints.yaml. An error naming what is missing otherwise.
Result<Body> DarwinBody(const std::string& shared_data_dir, const std::string& source_dir);

// A body by name: darwin_op (DarwinBody) or a parametric variant (nao, long_legs, tall); an
// error naming the body otherwise, or what DarwinBody misses.
Result<Body> BodyByName(const std::string& name, const std::string& shared_data_dir,
                        const std::string& source_dir);

// A template of the parametric humanoid with the proportions `variant` (HumanoidDimensions::
// Variant) in the joint preset `pose` (e.g. arms_swung), at 16 mm, as `hpose template generate
// --body` makes it; an error for an unknown variant or preset.
Result<VoxelTemplate> PoseTemplate(const std::string& variant, const std::string& pose);
// The same for a Body: an error for a mesh robot.
Result<VoxelTemplate> PoseTemplate(const Body& body, const std::string& pose);

// A frame of `body` in its shape `shape` (an index of kShapes) `distance_m` straight ahead of
// mount `mount` (of kMounts), heading `theta_deg`, among `clutter` objects laid out from
// `seed`, with the Kinect v1 noise model.
FrameSpec TrialFrame(const Body& body, int shape, int mount, double distance_m, double theta_deg,
                     int clutter, std::uint64_t seed);

// The names of a comma-separated flag value ("nao,darwin_op").
std::vector<std::string> ParseNames(const std::string& list);

}  // namespace hpose::bench

#endif  // HPOSE_BENCH_BENCH_BODIES_H_
