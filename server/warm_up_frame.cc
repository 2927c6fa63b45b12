#include "server/warm_up_frame.h"

#include <spdlog/spdlog.h>

#include "core/common/pose2d.h"
#include "core/sim/frame_simulator.h"

namespace hpose::server {

Intrinsics WarmUpIntrinsics() { return Intrinsics::KinectV1(640, 480); }

namespace {

std::shared_ptr<const SimulatedFrame> Render() {
  FrameSpec spec;
  spec.humanoid_pose = Pose2D{1.5, 0.1, DegToRad(30.0)};
  spec.sensor_height_m = 0.9;
  spec.sensor_pitch_rad = DegToRad(25.0);
  spec.clutter = 3;
  spec.seed = 1;
  spec.intrinsics = WarmUpIntrinsics();
  Result<SimulatedFrame> frame = SimulateFrame(spec);
  if (!frame.ok()) {
    spdlog::warn("no warm-up frame ({}): the first estimates will be slower",
                 frame.error().ToString());
    return nullptr;
  }
  return std::make_shared<const SimulatedFrame>(std::move(*frame));
}

}  // namespace

std::shared_ptr<const SimulatedFrame> WarmUpFrame() {
  static const std::shared_ptr<const SimulatedFrame> frame = Render();
  return frame;
}

}  // namespace hpose::server
