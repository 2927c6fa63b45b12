#ifndef HPOSE_SERVER_OPENNI2_SENSORS_H_
#define HPOSE_SERVER_OPENNI2_SENSORS_H_

#include <string>

namespace openni {
class Device;
}  // namespace openni

namespace hpose::server {

// The names of an open device's colour and infrared sensors: "colour and infrared", "colour",
// "infrared", or "" for neither.
std::string ColourAndInfraredSensors(openni::Device& device);

// For an open OpenNI2 device or recording without a depth sensor, the error that says so and
// what it has instead: "SPEC: no depth stream (it has colour and infrared only)", "... (it has
// no stream)". `spec` names the device as the user gave it.
std::string NoDepthStreamError(openni::Device& device, const std::string& spec);

// `what`, then ": " and OpenNI2's last error message (its own whitespace trimmed) if it has one.
std::string WithOpenni2Error(const std::string& what);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_OPENNI2_SENSORS_H_
