#ifndef HPOSE_TOOLS_EXIT_CODES_H_
#define HPOSE_TOOLS_EXIT_CODES_H_

#include <string>

#include "core/common/status.h"

namespace hpose::tools {

// Exit statuses shared by every hpose command (documented in `hpose --help`).
enum ExitCode : int {
  kExitOk = 0,
  kExitError = 1,        // bad input or a failure; the message says what.
  kExitUsage = 2,        // wrong flags.
  kExitNoHumanoid = 3,   // the frame was processed but no cluster passed the threshold.
  kExitNoFloor = 4,      // no floor plane could be found.
  kExitUnavailable = 5,  // a server or device could not be reached.
};

// Prints "hpose <command>: <message>" to stderr and returns the exit code that fits the error.
int ReportError(const std::string& command, const Error& error);

// Prints "hpose <command>: error: <message> (see --help)" to stderr and returns kExitUsage, for
// flags that parse but do not make sense together or are out of range.
int UsageError(const std::string& command, const std::string& message);

// The same for a program of its own: "<program>: <message>" (e.g. "hposed: ...").
int ReportProgramError(const std::string& program, const Error& error);

// The exit code that fits an error: kNotFound / kInvalidArgument / kDataLoss / kInternal ->
// kExitError, kFailedPrecondition -> kExitNoFloor, kUnavailable -> kExitUnavailable.
int ExitCodeFor(const Error& error);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_EXIT_CODES_H_
