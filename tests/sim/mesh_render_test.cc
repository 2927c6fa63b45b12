// A mesh robot renders like the primitives it was tessellated from.
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "core/sim/depth_renderer.h"
#include "core/sim/frame_simulator.h"
#include "core/sim/humanoid_model.h"
#include "core/sim/mesh_bvh.h"
#include "core/sim/triangle_mesh.h"

namespace hpose {
namespace {

DepthRenderer Renderer() {
  Result<DepthRenderer> r = DepthRenderer::Create(
      Intrinsics::KinectV1(320, 240), FloorEstimate::FromHeightPitchRoll(0.6, 0.2, 0.0));
  EXPECT_TRUE(r.ok());
  return *r;
}

// Renders the humanoid's primitives once as primitives and once as a tessellated mesh robot at
// the same pose; returns the fraction of pixels whose depth differs by more than `tol_mm`.
double MismatchFraction(const HumanoidModel& model, const Pose2D& pose, double max_edge,
                        int tol_mm) {
  TriangleMesh mesh;
  for (const Primitive& p : model.primitives()) mesh.Append(TessellatePrimitive(p, max_edge));
  Result<std::shared_ptr<const MeshBvh>> bvh = MeshBvh::Build(mesh);
  EXPECT_TRUE(bvh.ok());
  Scene prims;
  EXPECT_TRUE(prims.AddHumanoid(model, pose).ok());
  Scene meshes;
  EXPECT_TRUE(meshes.AddMeshRobot(*bvh, pose, "mesh").ok());
  const DepthRenderer renderer = Renderer();
  const DepthImage a = renderer.Render(prims);
  const DepthImage b = renderer.Render(meshes);
  int robot = 0, differ = 0;
  for (size_t i = 0; i < a.mm.size(); ++i) {
    if (a.mm[i] == b.mm[i] && a.mm[i] != 0) {
      // Pixels that show the robot in either image count; floor pixels equal in both are
      // counted below only when they differ.
    }
    const bool on_robot = a.mm[i] != b.mm[i] || a.mm[i] < 2500;
    if (!on_robot) continue;
    ++robot;
    if (std::abs(static_cast<int>(a.mm[i]) - static_cast<int>(b.mm[i])) > tol_mm) ++differ;
  }
  EXPECT_GT(robot, 1000);
  return static_cast<double>(differ) / robot;
}

TEST(MeshRenderTest, TessellatedHumanoidRendersLikeItsPrimitives) {
  Result<HumanoidModel> model = HumanoidModel::FromPreset("right_arm_raised");
  ASSERT_TRUE(model.ok());
  for (const double theta : {0.0, 1.2, -2.5}) {
    const Pose2D pose{1.3, 0.1, theta};
    // Within 3 mm except along silhouettes, where a polygon and a curve part ways.
    EXPECT_LT(MismatchFraction(*model, pose, 0.004, 3), 0.03) << theta;
  }
}

TEST(MeshRenderTest, FrameSpecRendersAMeshRobotInsteadOfThePreset) {
  Result<HumanoidModel> model = HumanoidModel::FromPreset("standing");
  ASSERT_TRUE(model.ok());
  TriangleMesh mesh;
  for (const Primitive& p : model->primitives()) mesh.Append(TessellatePrimitive(p, 0.004));
  FrameSpec spec;
  spec.noise = false;
  spec.humanoid_pose = Pose2D{1.2, 0.0, 0.7};
  Result<SimulatedFrame> prim = SimulateFrame(spec);
  ASSERT_TRUE(prim.ok());
  Result<std::shared_ptr<const MeshBvh>> bvh = MeshBvh::Build(mesh);
  ASSERT_TRUE(bvh.ok());
  spec.robot_mesh = *bvh;
  spec.preset = "no such preset: ignored";
  Result<SimulatedFrame> meshed = SimulateFrame(spec);
  ASSERT_TRUE(meshed.ok()) << meshed.error().message;
  EXPECT_NEAR(meshed->humanoid_height_m, prim->humanoid_height_m, 0.003);
  int differ = 0, robot = 0;
  for (size_t i = 0; i < prim->depth.mm.size(); ++i) {
    const int a = prim->depth.mm[i], b = meshed->depth.mm[i];
    if (a == b && (a == 0 || a > 1500)) continue;
    ++robot;
    if (std::abs(a - b) > 3) ++differ;
  }
  EXPECT_GT(robot, 2000);
  EXPECT_LT(differ, robot / 30);
}

TEST(MeshRenderTest, VariantBodiesDiffer) {
  Result<HumanoidDimensions> nao = HumanoidDimensions::Variant("nao");
  Result<HumanoidDimensions> long_legs = HumanoidDimensions::Variant("long_legs");
  ASSERT_TRUE(nao.ok());
  ASSERT_TRUE(long_legs.ok());
  EXPECT_FALSE(HumanoidDimensions::Variant("giraffe").ok());
  Result<HumanoidModel> a = HumanoidModel::FromPreset("standing", *nao);
  Result<HumanoidModel> b = HumanoidModel::FromPreset("standing", *long_legs);
  ASSERT_TRUE(a.ok());
  ASSERT_TRUE(b.ok()) << b.error().message;
  EXPECT_GT(b->Height(), a->Height() + 0.1);
  EXPECT_GT(b->bounds().sizes().y(), a->bounds().sizes().y() + 0.03);
  bool has_pack = false;
  for (const Primitive& p : b->primitives()) has_pack = has_pack || p.name == "battery_pack";
  EXPECT_FALSE(has_pack);
  FrameSpec spec;
  spec.body = "long_legs";
  Result<SimulatedFrame> frame = SimulateFrame(spec);
  ASSERT_TRUE(frame.ok());
  EXPECT_NEAR(frame->humanoid_height_m, b->Height(), 1e-9);
  spec.body = "giraffe";
  EXPECT_FALSE(SimulateFrame(spec).ok());
}

}  // namespace
}  // namespace hpose
