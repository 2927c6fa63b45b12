#include <iostream>

#include "tools/command.h"
#include "tools/exit_codes.h"

namespace hpose::tools {

int RunSimulate(int argc, char** argv) {
  (void)argc;
  std::cerr << argv[0] << ": not built yet\n";
  return kExitError;
}

}  // namespace hpose::tools
