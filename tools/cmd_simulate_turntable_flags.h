#ifndef HPOSE_TOOLS_CMD_SIMULATE_TURNTABLE_FLAGS_H_
#define HPOSE_TOOLS_CMD_SIMULATE_TURNTABLE_FLAGS_H_

#include <string>

#include "core/sim/turntable_captures.h"
#include "tools/flag_parser.h"

namespace hpose::tools {

// The flags of `hpose simulate turntable`, holding their defaults until parsed.
struct TurntableFlags {
  std::string out_dir, pose_name = "standing", offset = "0.035,-0.025";
  TurntableSpec spec;
  double axis_x = spec.axis_ground.x(), axis_y = spec.axis_ground.y();
  double step_deg = 30.0, start_deg = 0.0, yaw_deg = 0.0, error_deg = 0.0;
  double pitch_deg = 0.0, roll_deg = 0.0;
  int seed = 1, width = 640, height = 480;
  bool no_noise = false;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_SIMULATE_TURNTABLE_FLAGS_H_
