#include "core/sim/frame_simulator.h"

#include "core/sim/depth_renderer.h"
#include "core/sim/humanoid_model.h"
#include "core/sim/kinect_noise_model.h"
#include "core/sim/scene.h"

namespace hpose {

Result<SimulatedFrame> SimulateFrame(const FrameSpec& spec) {
  Result<HumanoidModel> model = HumanoidModel::FromPreset(spec.preset);
  if (!model.ok()) return model.error();
  Scene scene;
  Status st = scene.AddHumanoid(*model, spec.humanoid_pose, spec.preset);
  if (!st.ok()) return st.error();
  if (spec.clutter > 0) {
    st = scene.AddRandomClutter(spec.clutter, spec.seed);
    if (!st.ok()) return st.error();
  }
  const FloorEstimate mount = FloorEstimate::FromHeightPitchRoll(
      spec.sensor_height_m, spec.sensor_pitch_rad, spec.sensor_roll_rad);
  Result<DepthRenderer> renderer = DepthRenderer::Create(spec.intrinsics, mount);
  if (!renderer.ok()) return renderer.error();
  SimulatedFrame frame;
  frame.sensor_mount = mount;
  frame.humanoid_height_m = model->Height();
  if (spec.noise) {
    Result<KinectNoiseModel> noise = KinectNoiseModel::Create(KinectNoiseOptions{});
    if (!noise.ok()) return noise.error();
    frame.depth = renderer->Render(scene, &*noise, spec.seed);
  } else {
    frame.depth = renderer->Render(scene);
  }
  return frame;
}

}  // namespace hpose
