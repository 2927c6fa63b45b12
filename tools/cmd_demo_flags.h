#ifndef HPOSE_TOOLS_CMD_DEMO_FLAGS_H_
#define HPOSE_TOOLS_CMD_DEMO_FLAGS_H_

#include <string>

#include "core/sim/frame_simulator.h"
#include "tools/flag_parser.h"
#include "tools/robot_flags.h"

namespace hpose::tools {

// The flags of `hpose demo`, holding their defaults until parsed.
struct DemoFlags {
  DemoFlags();
  FrameSpec spec;
  double theta_deg = 0.0;
  int seed = 0;
  std::string picture = "hpose-demo.png";
  std::string robot_urdf;
  RobotFlags robot_flags;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_DEMO_FLAGS_H_
