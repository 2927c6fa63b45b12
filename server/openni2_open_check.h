#ifndef HPOSE_SERVER_OPENNI2_OPEN_CHECK_H_
#define HPOSE_SERVER_OPENNI2_OPEN_CHECK_H_

#include <string>

#include "core/common/status.h"

namespace hpose::server {

// Opens the recording `path` with OpenNI2 in a child process first, as far as its first depth
// frame: OpenNI2's file driver trusts the records it parses, and some damaged .oni files make it
// crash (a property name that runs on, seen at the device's open) where no error can be caught.
// A child that crashes, or takes more than `timeout_s`, is the recording's DATA_LOSS error,
// naming the file; a child that opened it, or that OpenNI2 refused cleanly (the caller's own
// open then says why), is OK. The child is this program again (/proc/self/exe), stopped at
// start-up by the environment variable HPOSE_OPENNI2_OPEN_CHECK; where it cannot be started the
// check is skipped (OK).
Status CheckRecordingOpens(const std::string& path, double timeout_s = 20.0);

// The same check for an OpenNI2 device URI (the part after openni2://): OpenNI2 opens a
// recording given as a device too, so a URI that names a file is checked as a recording; any
// other URI (a sensor, or none) is OK without a child.
Status CheckDeviceUriOpens(const std::string& uri);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_OPENNI2_OPEN_CHECK_H_
