#include "server/openni2_sensors.h"

#include <OpenNI.h>

namespace hpose::server {

std::string ColourAndInfraredSensors(openni::Device& device) {
  std::string names;
  if (device.hasSensor(openni::SENSOR_COLOR)) names = "colour";
  if (device.hasSensor(openni::SENSOR_IR)) names += names.empty() ? "infrared" : " and infrared";
  return names;
}

std::string NoDepthStreamError(openni::Device& device, const std::string& spec) {
  const std::string names = ColourAndInfraredSensors(device);
  return spec + ": no depth stream (" +
         (names.empty() ? "it has no stream" : "it has " + names + " only") + ")";
}

std::string WithOpenni2Error(const std::string& what) {
  const char* ext = openni::OpenNI::getExtendedError();
  std::string e = ext != nullptr ? ext : "";
  const size_t first = e.find_first_not_of(" \t\r\n");
  const size_t last = e.find_last_not_of(" \t\r\n");
  if (first == std::string::npos) return what;
  return what + ": " + e.substr(first, last - first + 1);
}

}  // namespace hpose::server
