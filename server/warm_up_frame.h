#ifndef HPOSE_SERVER_WARM_UP_FRAME_H_
#define HPOSE_SERVER_WARM_UP_FRAME_H_

#include <memory>

#include "core/depth/intrinsics.h"

namespace hpose {
struct SimulatedFrame;
}

namespace hpose::server {

// The synthetic frame the daemon's estimators estimate once before their first real one
// (SourceConfig::warm_up, GrpcConfig::warm_up), so that the buffers a frame needs grow there: a
// Kinect v1 view (WarmUpIntrinsics) from 0.9 m, 25 degrees down, of the parametric humanoid
// 1.5 m ahead among clutter, where the floor fills most of the image and every stage of an
// estimate runs. Rendered on the first call and kept for the process (the stream's and the
// calls' warm-ups share it); null, with a warning logged, if it cannot be rendered.
std::shared_ptr<const SimulatedFrame> WarmUpFrame();
Intrinsics WarmUpIntrinsics();

}  // namespace hpose::server

#endif  // HPOSE_SERVER_WARM_UP_FRAME_H_
