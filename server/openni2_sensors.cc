#include "server/openni2_sensors.h"

#include <OpenNI.h>

namespace hpose::server {

std::string NoDepthStreamError(openni::Device& device, const std::string& spec) {
  std::string names;
  if (device.hasSensor(openni::SENSOR_COLOR)) names = "colour";
  if (device.hasSensor(openni::SENSOR_IR)) names += names.empty() ? "infrared" : " and infrared";
  return spec + ": no depth stream (" +
         (names.empty() ? "it has no stream" : "it has " + names + " only") + ")";
}

}  // namespace hpose::server
