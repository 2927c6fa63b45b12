#include "core/sim/frame_simulator.h"

#include "core/sim/depth_renderer.h"
#include "core/sim/humanoid_model.h"
#include "core/sim/kinect_noise_model.h"
#include "core/sim/scene.h"

namespace hpose {

Result<SimulatedFrame> SimulateFrame(const FrameSpec& spec) {
  Scene scene;
  double height_m = 0.0;
  if (spec.robot_mesh != nullptr) {
    if (Status st = scene.AddMeshRobot(spec.robot_mesh, spec.humanoid_pose); !st.ok()) {
      return st.error();
    }
    height_m = spec.robot_mesh->bounds().max().z();
  } else {
    Result<HumanoidDimensions> body = HumanoidDimensions::Variant(spec.body);
    if (!body.ok()) return body.error();
    Result<HumanoidModel> model = HumanoidModel::FromPreset(spec.preset, *body);
    if (!model.ok()) return model.error();
    if (Status st = scene.AddHumanoid(*model, spec.humanoid_pose, spec.preset); !st.ok()) {
      return st.error();
    }
    height_m = model->Height();
  }
  if (spec.clutter > 0) {
    if (Status st = scene.AddRandomClutter(spec.clutter, spec.seed); !st.ok()) return st.error();
  }
  const FloorEstimate mount = FloorEstimate::FromHeightPitchRoll(
      spec.sensor_height_m, spec.sensor_pitch_rad, spec.sensor_roll_rad);
  Result<DepthRenderer> renderer = DepthRenderer::Create(spec.intrinsics, mount);
  if (!renderer.ok()) return renderer.error();
  SimulatedFrame frame;
  frame.sensor_mount = mount;
  frame.humanoid_height_m = height_m;
  if (spec.noise) {
    KinectNoiseOptions noise_options;
    noise_options.correlated_share = spec.noise_correlated_share;
    Result<KinectNoiseModel> noise = KinectNoiseModel::Create(noise_options);
    if (!noise.ok()) return noise.error();
    frame.depth = renderer->Render(scene, &*noise, spec.seed);
  } else {
    frame.depth = renderer->Render(scene);
  }
  return frame;
}

}  // namespace hpose
