#ifndef HPOSE_TOOLS_CMD_TEMPLATE_URDF_FLAGS_H_
#define HPOSE_TOOLS_CMD_TEMPLATE_URDF_FLAGS_H_

#include <string>

#include "tools/flag_parser.h"
#include "tools/robot_flags.h"

namespace hpose::tools {

// The flags of `hpose template from-urdf`, holding their defaults until parsed.
struct TemplateFromUrdfFlags {
  std::string out, name;
  double resolution = 0.016;
  bool list_joints = false;
  RobotFlags robot_flags;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_TEMPLATE_URDF_FLAGS_H_
