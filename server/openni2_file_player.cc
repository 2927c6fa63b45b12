#include "server/openni2_file_player.h"

#include <OpenNI.h>

namespace hpose::server {
namespace {

// As long as OpenNI2's own close waits for its player thread.
constexpr int kPlayerStartTimeoutMs = 3000;

// Starts `stream` (nothing to do when it runs already) and waits for a frame from it.
void AwaitFrame(openni::VideoStream& stream) {
  if (stream.start() != openni::STATUS_OK) return;
  openni::VideoStream* streams[] = {&stream};
  int ready = -1;
  openni::OpenNI::waitForAnyStream(streams, 1, &ready, kPlayerStartTimeoutMs);
}

}  // namespace

void LetTheFilePlayerStart(openni::Device& device, openni::VideoStream* stream) {
  if (!device.isValid() || !device.isFile()) return;
  if (stream != nullptr && stream->isValid()) {
    AwaitFrame(*stream);
    return;
  }
  for (const openni::SensorType type :
       {openni::SENSOR_DEPTH, openni::SENSOR_COLOR, openni::SENSOR_IR}) {
    openni::VideoStream other;
    if (!device.hasSensor(type) || other.create(device, type) != openni::STATUS_OK) continue;
    AwaitFrame(other);
    other.stop();
    other.destroy();
    return;
  }
}

}  // namespace hpose::server
