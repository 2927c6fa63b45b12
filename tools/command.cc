#include "tools/command.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>

#include "core/common/vector_level.h"
#include "tools/exit_codes.h"

namespace hpose::tools {
namespace {

// Results written to standard output and lost (a full disk, a closed pipe, /dev/full) must
// not be reported as success: flush it and check for any write error.
int CheckStdoutWritten(const std::string& prog, int code) {
  std::cout.flush();
  errno = 0;
  const bool failed = !std::cout || std::fflush(stdout) != 0 || std::ferror(stdout) != 0;
  if (!failed) return code;
  const int err = errno;
  std::cerr << prog << ": cannot write the output to standard output"
            << (err != 0 ? std::string(": ") + std::strerror(err) : std::string()) << "\n";
  return kExitError;
}

}  // namespace

int RunCommand(const Command& c, int argc, char** argv) {
  std::string prog = std::string("hpose ") + c.name;
  // A cap on core's vector paths that names no level is refused before any work.
  const Status vector_level = CheckVectorLevelVariable();
  if (!vector_level.ok()) return ReportError(c.name, vector_level.error());
  argv[1] = prog.data();
  return CheckStdoutWritten(prog, c.run(argc - 1, argv + 1));
}

}  // namespace hpose::tools
