#include "bench/bench_bodies.h"

#include <algorithm>
#include <sstream>

#include "core/robot/joint_sets.h"
#include "core/robot/urdf_robot.h"
#include "core/sim/humanoid_model.h"
#include "core/sim/humanoid_template.h"
#include "core/sim/triangle_mesh.h"

namespace hpose::bench {

const char* const kShapes[2] = {"standing", "right_arm_raised"};
const Mount kMounts[2] = {{"level 0.34 m", 0.34, 0.0},
                          {"pitched 0.9 m, 20° down", 0.9, 20.0 * kPi / 180.0}};

FrameSpec TrialFrame(const Body& body, int shape, int mount, double distance_m, double theta_deg,
                     int clutter, std::uint64_t seed) {
  FrameSpec spec;
  spec.preset = kShapes[shape];
  if (body.meshes.empty()) {
    spec.body = body.variant;
  } else {
    spec.robot_mesh = body.meshes[shape];
  }
  spec.humanoid_pose = Pose2D{distance_m, 0.0, NormalizeAngle(theta_deg * kPi / 180.0)};
  spec.sensor_height_m = kMounts[mount].height_m;
  spec.sensor_pitch_rad = kMounts[mount].pitch_rad;
  spec.clutter = clutter;
  spec.seed = seed;
  return spec;
}

Body ParametricBody(const std::string& variant) {
  Body b;
  b.name = variant;
  b.variant = variant;
  for (const char* shape : kShapes) b.templates.push_back(PoseTemplate(b, shape).value());
  return b;
}

Result<Body> DarwinBody(const std::string& shared_data_dir, const std::string& source_dir) {
  UrdfLoadOptions load;
  load.allow_missing = true;
  Result<UrdfRobot> robot =
      UrdfRobot::Load(shared_data_dir + "/darwin_op/robots/robotis_op.urdf", load);
  if (!robot.ok()) return robot.error();
  Result<std::vector<NamedJointSet>> sets =
      LoadJointSetsFile(source_dir + "/docs/examples/darwin_op_joints.yaml");
  if (!sets.ok()) return sets.error();
  Body b;
  b.name = "darwin_op";
  for (const char* shape : kShapes) {
    auto set = std::find_if(sets->begin(), sets->end(),
                            [&](const NamedJointSet& n) { return n.name == shape; });
    if (set == sets->end()) {
      return MakeError(ErrorCode::kNotFound, std::string("no joint set '") + shape + "'");
    }
    Result<PosedRobot> posed = robot->Pose(set->joints);
    if (!posed.ok()) return posed.error();
    Result<std::shared_ptr<const MeshBvh>> bvh = MeshBvh::Build(posed->mesh);
    if (!bvh.ok()) return bvh.error();
    b.meshes.push_back(*bvh);
    Result<VoxelTemplate> tpl =
        MakeMeshTemplate(posed->mesh, shape, 0.016, shape, "bench darwin_op");
    if (!tpl.ok()) return tpl.error();
    b.templates.push_back(*tpl);
  }
  return b;
}

Result<Body> BodyByName(const std::string& name, const std::string& shared_data_dir,
                        const std::string& source_dir) {
  if (name == "darwin_op") return DarwinBody(shared_data_dir, source_dir);
  if (!HumanoidDimensions::Variant(name).ok()) {
    return MakeError(ErrorCode::kNotFound, "unknown body '" + name + "'");
  }
  return ParametricBody(name);
}

Result<VoxelTemplate> PoseTemplate(const std::string& variant, const std::string& pose) {
  Result<HumanoidDimensions> dims = HumanoidDimensions::Variant(variant);
  if (!dims.ok()) return dims.error();
  Result<HumanoidModel> model = HumanoidModel::FromPreset(pose, *dims);
  if (!model.ok()) return model.error();
  return MakeHumanoidTemplate(*model, pose, 0.016, pose, "bench " + variant);
}

Result<VoxelTemplate> PoseTemplate(const Body& body, const std::string& pose) {
  if (body.variant.empty()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     body.name + " is a mesh robot: no joint preset '" + pose + "' to make");
  }
  return PoseTemplate(body.variant, pose);
}

std::vector<std::string> ParseNames(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, ',');) out.push_back(item);
  return out;
}

}  // namespace hpose::bench
