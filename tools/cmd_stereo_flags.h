#ifndef HPOSE_TOOLS_CMD_STEREO_FLAGS_H_
#define HPOSE_TOOLS_CMD_STEREO_FLAGS_H_

#include <string>
#include <vector>

#include "core/stereo/paired_sim_recording.h"
#include "core/stereo/stereo_sim_sequence.h"
#include "tools/flag_parser.h"

namespace hpose::tools {

// The flags of `hpose estimate-stereo`, holding their defaults until parsed.
struct EstimateStereoFlags {
  std::vector<std::string> calibration_paths;
  std::string left, right, sequence, options_path, method, calib_unit = "m";
  double fps = 15.0;
  bool json = false;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

// The flags of `hpose simulate-stereo` (and `hpose simulate stereo`), holding their defaults until
// parsed.
struct SimulateStereoFlags {
  StereoSimSequenceSpec spec;
  std::string out, scenario = "rolling", rig = "paper";
  bool no_distractors = false, no_sway = false, hard = false;
  int seed = 1;
  PairedDepthSensorSpec depth;
  std::string depth_sensor, depth_size;
  double depth_pitch_deg = 0.0;
  double noise = spec.noise.pixel_noise_sigma;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_STEREO_FLAGS_H_
