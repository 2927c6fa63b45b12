#ifndef HPOSE_TOOLS_CMD_QUERY_FLAGS_H_
#define HPOSE_TOOLS_CMD_QUERY_FLAGS_H_

#include <string>
#include <vector>

#include "tools/flag_parser.h"

namespace hpose::tools {

// The flags of `hpose query`, holding their defaults until parsed.
struct QueryFlags {
  std::string server = "127.0.0.1:50051", intrinsics, estimator = "all";
  std::vector<std::string> templates;
  std::string tls_ca, tls_cert, tls_key, token_file;
  bool json = false, compare = false;
  int count = 0;
  double timeout_s = 10.0, max_dt_s = 0.05;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_QUERY_FLAGS_H_
