// RobotFlags::Register, apart from the loading in robot_flags.cc: the `hpose` front end declares
// these flags without linking the URDF and mesh libraries.
#include "tools/robot_flags.h"

namespace hpose::tools {

void RobotFlags::Register(FlagParser* flags, bool one_set) {
  flags->AddString("geometry", &geometry, "which shapes of each link: visual or collision",
                   "visual|collision");
  flags->AddStrings("package-path", &package_paths,
                    "directory holding ROS packages for package://NAME/... mesh names: a "
                    "package itself (its package.xml names it, or its directory is NAME) or a "
                    "tree searched 4 levels deep; ROS_PACKAGE_PATH and the URDF's parent "
                    "directories are searched after",
                    "DIR");
  flags->AddStrings("joint", &joint_assignments,
                    "a joint position, radians (metres for prismatic joints), applied on top "
                    "of --joints",
                    "NAME=VALUE");
  flags->AddString("joints", &joints_file,
                   "YAML file of named joint sets: {SET: {JOINT: position, ...}, ...}",
                   "FILE.yaml");
  if (one_set) {
    flags->AddString("joint-set", &joint_set,
                     "the set of --joints to use [default: the file's first]", "NAME");
  } else {
    flags->AddStrings("joint-set", &joint_sets, "only this set of --joints [default: every set]",
                      "NAME");
  }
  flags->AddString("reference-link", &reference_link,
                   "link whose origin, projected on the floor, is the template origin and whose "
                   "x axis is the robot's forward direction [default: the root link]",
                   "LINK");
  flags->AddBool("allow-missing", &allow_missing,
                 "skip meshes that are missing or unreadable, with a warning for each, instead "
                 "of failing");
}

}  // namespace hpose::tools
