#ifndef HPOSE_TOOLS_CMD_CALIBRATE_FLAGS_H_
#define HPOSE_TOOLS_CMD_CALIBRATE_FLAGS_H_

#include <string>
#include <vector>

#include "core/stereo/stereo_calibrator.h"
#include "core/stereo/world_from_ground_fit.h"
#include "tools/command.h"
#include "tools/flag_parser.h"

namespace hpose::tools {

// The flags of `hpose calibrate stereo`, holding their defaults until parsed.
struct CalibrateStereoFlags {
  std::vector<std::string> lefts, rights;
  std::string dir, out;
  ChessboardOptions board;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

// The flags of `hpose calibrate world-from-ground`, holding their defaults until parsed.
struct WorldFromGroundFlags {
  std::string pairs_path, recording, config_path, pairs_out, stereo_options, stereo_calibration;
  // A recording's depth frames (any recording hposed's source.path takes) and stereo sequence
  // directory; how far apart in time a depth pose and a stereo pose may pair, and the stereo
  // clock's offset.
  std::string depth, stereo;
  double max_dt_s = 0.05, stereo_time_offset_s = 0.0;
  std::vector<std::string> templates;
  WorldFromGroundOptions options;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

// What `hpose calibrate TARGET` runs for each target: its work in the command's program, the
// check of its flags in the `hpose` front end.
struct CalibrateSubcommands {
  CommandFn stereo, world_from_ground;
};

// `hpose calibrate`: runs the target argv[1] names, as the program "hpose calibrate TARGET"
// (argv from there on), or prints the usage.
int RunCalibrateSubcommand(const CalibrateSubcommands& subs, int argc, char** argv);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_CALIBRATE_FLAGS_H_
