#ifndef HPOSE_TOOLS_CMD_REPLAY_FLAGS_H_
#define HPOSE_TOOLS_CMD_REPLAY_FLAGS_H_

#include <string>
#include <vector>

#include "tools/flag_parser.h"

namespace hpose::tools {

// The flags of `hpose replay`, holding their defaults until parsed.
struct ReplayFlags {
  std::string out_path, format, config_path, intrinsics_path, rate = "fast", initial_pose,
                                                              truth_path;
  std::vector<std::string> templates;
  int max_frames = 0;
  double fps = 30.0;
  bool no_progress = false;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_REPLAY_FLAGS_H_
