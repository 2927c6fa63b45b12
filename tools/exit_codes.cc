#include "tools/exit_codes.h"

#include <iostream>

namespace hpose::tools {

int ReportError(const std::string& command, const Error& error) {
  return ReportProgramError("hpose " + command, error);
}

int UsageError(const std::string& command, const std::string& message) {
  std::cerr << "hpose " << command << ": error: " << message << " (see --help)\n";
  return kExitUsage;
}

int ReportProgramError(const std::string& program, const Error& error) {
  std::cerr << program << ": " << error.message << "\n";
  return ExitCodeFor(error);
}

int ExitCodeFor(const Error& error) {
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
