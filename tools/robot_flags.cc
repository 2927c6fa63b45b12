#include "tools/robot_flags.h"

#include <cstdlib>
#include <iostream>
#include <sstream>

namespace hpose::tools {

Result<UrdfRobot> RobotFlags::Load(const std::string& urdf_path, const std::string& command) const {
  UrdfLoadOptions options;
  if (geometry == "visual") {
    options.geometry = UrdfGeometryKind::kVisual;
  } else if (geometry == "collision") {
    options.geometry = UrdfGeometryKind::kCollision;
  } else {
    return MakeError(ErrorCode::kInvalidArgument,
                     "--geometry must be visual or collision, got '" + geometry + "'");
  }
  options.package_paths = package_paths;
  if (const char* ros = std::getenv("ROS_PACKAGE_PATH"); ros != nullptr) {
    std::istringstream in(ros);
    for (std::string dir; std::getline(in, dir, ':');) {
      if (!dir.empty()) options.package_paths.push_back(dir);
    }
  }
  options.allow_missing = allow_missing;
  Result<UrdfRobot> robot = UrdfRobot::Load(urdf_path, options);
  if (!robot.ok()) return robot;
  for (const SkippedMesh& s : robot->skipped()) {
    std::cerr << "hpose " << command << ": warning: link '" << s.link << "': skipped mesh "
              << (s.path.empty() ? s.uri : s.path) << ": " << s.reason << "\n";
  }
  return robot;
}

Result<std::vector<NamedJointSet>> RobotFlags::JointSets(const std::string& default_name) const {
  JointValues overrides;
  for (const std::string& a : joint_assignments) {
    if (Status s = ParseJointAssignment(a, &overrides); !s.ok()) return s.error();
  }
  std::vector<std::string> wanted_sets = joint_sets;
  if (!joint_set.empty()) wanted_sets.push_back(joint_set);
  std::vector<NamedJointSet> sets;
  if (joints_file.empty()) {
    if (!wanted_sets.empty()) {
      return MakeError(ErrorCode::kInvalidArgument, "--joint-set needs --joints FILE.yaml");
    }
    sets.push_back({default_name, overrides});
    return sets;
  }
  Result<std::vector<NamedJointSet>> all = LoadJointSetsFile(joints_file);
  if (!all.ok()) return all.error();
  for (const std::string& wanted : wanted_sets) {
    bool found = false;
    for (const NamedJointSet& s : *all) found = found || s.name == wanted;
    if (!found) {
      std::string known;
      for (const NamedJointSet& s : *all) known += (known.empty() ? "" : ", ") + s.name;
      return MakeError(ErrorCode::kInvalidArgument,
                       joints_file + " has no joint set '" + wanted + "' (it has: " + known + ")");
    }
  }
  for (const NamedJointSet& s : *all) {
    bool selected = wanted_sets.empty();
    for (const std::string& wanted : wanted_sets) selected = selected || s.name == wanted;
    if (!selected) continue;
    NamedJointSet set = s;
    for (const auto& [name, value] : overrides) set.joints[name] = value;
    sets.push_back(std::move(set));
  }
  return sets;
}

Result<std::shared_ptr<const MeshBvh>> LoadPosedRobotMesh(const RobotFlags& flags,
                                                          const std::string& urdf_path,
                                                          const std::string& command,
                                                          std::string* set_name) {
  Result<UrdfRobot> robot = flags.Load(urdf_path, command);
  if (!robot.ok()) return robot.error();
  Result<std::vector<NamedJointSet>> sets = flags.JointSets("default");
  if (!sets.ok()) return sets.error();
  const NamedJointSet& set = sets->front();
  Result<PosedRobot> posed = robot->Pose(set.joints, flags.reference_link);
  if (!posed.ok()) return posed.error();
  for (const std::string& note : posed->notes)
    std::cerr << "hpose " << command << ": note: " << note << "\n";
  if (set_name != nullptr) *set_name = robot->name() + "/" + set.name;
  return MeshBvh::Build(std::move(posed->mesh));
}

}  // namespace hpose::tools
