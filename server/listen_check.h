#ifndef HPOSE_SERVER_LISTEN_CHECK_H_
#define HPOSE_SERVER_LISTEN_CHECK_H_

#include <string>

#include "core/common/status.h"

namespace hpose::server {

// Tries to bind a TCP socket to `listen` ("HOST:PORT", "[V6]:PORT") and releases it at once, so
// that the daemon can say in a sentence why it cannot serve there, before gRPC tries (and logs
// its own diagnostics): the port is already in use, the host is not an address of this machine,
// the host name does not resolve, or the port needs privileges. kUnavailable for those; OK
// otherwise (also for port 0, and when the check itself cannot tell).
Status CheckCanListen(const std::string& listen);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_LISTEN_CHECK_H_
