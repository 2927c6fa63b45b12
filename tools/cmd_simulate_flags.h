#ifndef HPOSE_TOOLS_CMD_SIMULATE_FLAGS_H_
#define HPOSE_TOOLS_CMD_SIMULATE_FLAGS_H_

#include <string>

#include "tools/command.h"
#include "tools/flag_parser.h"
#include "tools/robot_flags.h"

namespace hpose::tools {

// The flags of `hpose simulate` (a scene of a humanoid), holding their defaults until parsed.
struct SimulateFlags {
  std::string out_dir;
  double x = 1.0, y = 0.0, theta_deg = 0.0;
  std::string pose_name = "standing";
  std::string body = "nao", robot_urdf;
  RobotFlags robot_flags;
  double sensor_height = 0.34, pitch_deg = 0.0, roll_deg = 0.0;
  int clutter = 0, seed = 1, width = 640, height = 480, frames = 1;
  bool no_noise = false, no_cloud = false;
  double noise_correlation = 0.0;
  int noise_correlation_px = 4;
  double turn_deg = 0.0, step_m = 0.0;
  std::string second_at, second_pose = "standing";

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

// What `hpose simulate [stereo|turntable]` runs: the scene of a humanoid, or stereo pairs, or
// turntable captures; their work in the command's program, the check of their flags in the
// `hpose` front end.
struct SimulateSubcommands {
  CommandFn scene, stereo, turntable;
};

// `hpose simulate`: `stereo` and `turntable` run as the programs "hpose simulate stereo" and
// "hpose simulate turntable" (argv from argv[1] on), anything else is the scene's flags.
int RunSimulateSubcommand(const SimulateSubcommands& subs, int argc, char** argv);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_SIMULATE_FLAGS_H_
