#ifndef HPOSE_TESTS_SEARCH_FAR_NAO_SCENE_H_
#define HPOSE_TESTS_SEARCH_FAR_NAO_SCENE_H_

#include "core/sim/frame_simulator.h"

namespace hpose::testing {

// A Nao 3.3 m from a sensor 0.9 m high looking 20 degrees down, among 3 clutter objects: the
// depth noise spreads its surfaces over more voxels than the template covers, and it scores
// below 50.
inline FrameSpec FarNaoSpec() {
  FrameSpec spec;
  spec.preset = "standing";
  spec.humanoid_pose = Pose2D{3.3, 0.2, DegToRad(120.0)};
  spec.sensor_height_m = 0.9;
  spec.sensor_pitch_rad = DegToRad(20.0);
  spec.clutter = 3;
  spec.seed = 3;
  return spec;
}

}  // namespace hpose::testing

#endif  // HPOSE_TESTS_SEARCH_FAR_NAO_SCENE_H_
