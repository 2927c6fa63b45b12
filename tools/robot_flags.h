#ifndef HPOSE_TOOLS_ROBOT_FLAGS_H_
#define HPOSE_TOOLS_ROBOT_FLAGS_H_

#include <memory>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/robot/joint_sets.h"
#include "core/robot/urdf_robot.h"
#include "core/sim/mesh_bvh.h"
#include "tools/flag_parser.h"

namespace hpose::tools {

// The flags every command that takes a URDF robot shares (template from-urdf, simulate,
// demo): which geometry, where packages are, the joint positions and the reference link.
struct RobotFlags {
  std::string geometry = "visual";
  std::vector<std::string> package_paths;
  std::vector<std::string> joint_assignments;  // NAME=VALUE
  std::string joints_file;
  std::vector<std::string> joint_sets;  // names selected from joints_file
  std::string joint_set;                // the one selected, for commands that take one
  std::string reference_link;
  bool allow_missing = false;

  // Adds --geometry, --package-path, --joint, --joints, --joint-set, --reference-link and
  // --allow-missing. `one_set`: --joint-set selects exactly one set (simulate, demo).
  void Register(FlagParser* flags, bool one_set);

  // Loads the robot (package paths from the flags, then ROS_PACKAGE_PATH) and prints a
  // warning to stderr for each mesh skipped by --allow-missing.
  Result<UrdfRobot> Load(const std::string& urdf_path, const std::string& command) const;

  // The joint sets to pose: those of --joints (all, or those picked by --joint-set), each with
  // the --joint values on top; without --joints a single set named `default_name` holding the
  // --joint values. kInvalidArgument on a bad value or an unknown --joint-set.
  Result<std::vector<NamedJointSet>> JointSets(const std::string& default_name) const;
};

// Loads a URDF robot and poses it with exactly one joint set (the flags', see above), for
// simulation: returns the mesh in the template frame ready to render, and prints skipped
// meshes and notes to stderr. `set_name` receives the name of the set used.
Result<std::shared_ptr<const MeshBvh>> LoadPosedRobotMesh(const RobotFlags& flags,
                                                          const std::string& urdf_path,
                                                          const std::string& command,
                                                          std::string* set_name);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_ROBOT_FLAGS_H_
