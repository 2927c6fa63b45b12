#include "tools/exit_codes.h"

#include <iostream>

namespace hpose::tools {

int ReportError(const std::string& command, const Error& error) {
  std::cerr << "hpose " << command << ": " << error.message << "\n";
  switch (error.code) {
    case ErrorCode::kFailedPrecondition:
      return kExitNoFloor;
    case ErrorCode::kUnavailable:
      return kExitUnavailable;
    default:
      return kExitError;
  }
}

}  // namespace hpose::tools
