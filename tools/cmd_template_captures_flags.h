#ifndef HPOSE_TOOLS_CMD_TEMPLATE_CAPTURES_FLAGS_H_
#define HPOSE_TOOLS_CMD_TEMPLATE_CAPTURES_FLAGS_H_

#include <string>

#include "tools/flag_parser.h"

namespace hpose::tools {

// The flags of `hpose template from-captures`, holding their defaults until parsed.
struct TemplateFromCapturesFlags {
  std::string out, name, variant, intrinsics, headings_text, angles_text, origin_name = "centroid";
  std::string report_path, picture_path;
  double step_deg = 30.0, resolution = 0.016, table_height = 0.0, front_yaw_deg = 0.0;
  double max_rms_mm = 6.0, min_inliers = 0.6, axis_search = 0.3, heading_search_deg = 17.0;
  int front_view = 0;
  bool turntable = false, drop_bad = false;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_TEMPLATE_CAPTURES_FLAGS_H_
