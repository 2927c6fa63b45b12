#ifndef HPOSE_TOOLS_CMD_RECORD_FLAGS_H_
#define HPOSE_TOOLS_CMD_RECORD_FLAGS_H_

#include <string>

#include "tools/flag_parser.h"

namespace hpose::tools {

// The flags of `hpose record`, holding their defaults until parsed.
struct RecordFlags {
  std::string device = "openni2://", out;
  int frames = 0;
  double duration_s = 0.0, timeout_s = 5.0;
  bool quiet = false;
  bool list_devices = false;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_RECORD_FLAGS_H_
