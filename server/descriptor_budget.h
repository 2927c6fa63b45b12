#ifndef HPOSE_SERVER_DESCRIPTOR_BUDGET_H_
#define HPOSE_SERVER_DESCRIPTOR_BUDGET_H_

namespace hpose::server {

// The process's open file descriptors (counted in /proc/self/fd), or -1 when they cannot be
// counted (no descriptor left to open the directory with).
int OpenDescriptors();

// Descriptors the network servers leave to the rest of the daemon: its frame source (an
// OpenNI2 device, the next PNG), logs, template files, child processes. At most 128, and a
// quarter of a smaller limit.
int ReservedDescriptors();

// Whether a connection may be accepted: more than ReservedDescriptors() would stay free under
// the soft RLIMIT_NOFILE. A true answer counts as one descriptor taken (the caller accepts).
// Thread-safe; the count is refreshed every 100 ms and whenever it leaves no room. A server that
// may not accept leaves the connection in the kernel's backlog and asks again a little later; a
// flood of connections then waits there instead of leaving the daemon without descriptors. (Raising
// the soft limit is no way out: OpenNI2's PS1080 driver calls select(), which cannot take
// descriptors past 1 023.)
bool MayAcceptConnection();

}  // namespace hpose::server

#endif  // HPOSE_SERVER_DESCRIPTOR_BUDGET_H_
