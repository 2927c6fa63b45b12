#ifndef HPOSE_TOOLS_CMD_ESTIMATE_FLAGS_H_
#define HPOSE_TOOLS_CMD_ESTIMATE_FLAGS_H_

#include <string>
#include <vector>

#include "core/common/pose2d.h"
#include "core/search/estimator.h"
#include "tools/flag_parser.h"

namespace hpose::tools {

// The flags of `hpose estimate`, holding their defaults until parsed.
struct EstimateFlags {
  EstimateFlags();
  std::string depth_path, intrinsics_path, cloud_path, picture;
  std::vector<std::string> template_paths;
  bool json = false;
  EstimatorOptions options = DefaultEstimatorOptions();
  std::string search = SearchKindName(options.search);
  std::string score = ScoreKindName(options.score);
  double floor_height = -1.0, floor_pitch_deg = 0.0, floor_roll_deg = 0.0;
  double floor_max_tilt_deg = RadToDeg(options.floor_fit.max_tilt_rad);
  int stride = options.cloud.stride;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_ESTIMATE_FLAGS_H_
