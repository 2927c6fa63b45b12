#ifndef HPOSE_TOOLS_CMD_PLOT_FLAGS_H_
#define HPOSE_TOOLS_CMD_PLOT_FLAGS_H_

#include <string>

#include "tools/flag_parser.h"

namespace hpose::tools {

// The flags of `hpose plot`, holding their defaults until parsed.
struct PlotFlags {
  std::string out, title;
  std::string truth_path;  // a simulation's truth.json, drawn beneath the estimates.

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_PLOT_FLAGS_H_
